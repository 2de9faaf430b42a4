"""The waving/jumping split on simulated windows: activity's net alone against net + split, paired,
on a fresh simulated validation set (`wallcli simulate --dataset 1024 --task activity --domain shifted
--seed 108 --grid 24x32 -o DIR`, the recipe of the card's validation set, today's simulator)."""
import sys
from pathlib import Path

import numpy as np

from wallcli.infer.model import load_model
from wallcli.infer.split import from_card
from wallcli.io.arrays import load_npz
from wallcli.signal.features import window_features

d = Path(sys.argv[1])
model = load_model("activity")
split = from_card(model.card)
rows = {"label": [], "net": [], "split": [], "vis": []}
for f in sorted(d.glob("shard-*.npz")):
    a, _ = load_npz(f)
    h, v, ho, vo = a["horizontal"], a["vertical"], a["h_offset"], a["v_offset"]
    p = model.classify({"horizontal": h, "vertical": v}, {"horizontal": ho, "vertical": vo})
    q = split.apply(p, window_features(h, v, ho, vo))
    rows["label"] += list(a["label"]); rows["net"] += list(p.argmax(1)); rows["split"] += list(q.argmax(1))
    rows["vis"] += list(a["snr_db_weakest"] if "snr_db_weakest" in a else a["snr_db"])
y, n0, n1, vis = (np.array(rows[k]) for k in ("label", "net", "split", "vis"))
visible = np.isnan(vis) | (vis >= -10)
out = {"set": f"fresh simulated validation set ({d.name}): shifted rooms, 1,024 windows from 256 scenes, "
              "the recipe of the card's validation set with today's simulator",
       "command": "wallcli simulate --dataset 1024 --task activity --domain shifted --seed 108 --grid 24x32 -o DIR"}
for name, m in (("all", np.ones_like(visible)), ("visible", visible)):
    a0, a1 = (n0[m] == y[m]).mean(), (n1[m] == y[m]).mean()
    g, l = int(((n1 == y) & (n0 != y) & m).sum()), int(((n0 == y) & (n1 != y) & m).sum())
    print(f"{name}: {m.sum()} windows, net {a0:.1%}, net + split {a1:.1%} (+{g} -{l})")
    out[name] = {"windows": int(m.sum()), "net_alone": round(float(a0), 4), "with_split": round(float(a1), 4),
                 "gained": g, "lost": l}
out["visible"]["min_snr_db"] = -10
import json
(Path(__file__).resolve().parents[2] / "runs" / "sim_split.json").write_text(json.dumps(out, indent=1))
