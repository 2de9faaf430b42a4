"""The waving/jumping split fitted on recordings + simulated scenes (each set weighted equally), judged
out of fold on the recordings and on a held-out simulated set (per window, as the card's validation).

    python research/recordings/split_mix.py FIT_DATASET HELDOUT_DATASET [sim_weight ...]
"""
import sys, json
from pathlib import Path
import numpy as np
sys.path.insert(0, __import__('os').path.dirname(__file__))
from common import *
from wallcli.infer.model import load_model
from wallcli.infer.split import Split
from wallcli.io.arrays import load_npz
from wallcli.signal.features import window_features
from wallcli.train.folds import _split_data, simulated_split_data
from wallcli.infer.split import fit

fit_dir, held = Path(sys.argv[1]), Path(sys.argv[2])
ratios = [float(a) for a in sys.argv[3:]] or [1.0]
pair = ["waving", "jumping"]
recs = recordings()
folds = np.array([fold_of(r.name, K) for r in recs])
base = json.load(open(ROOT / "runs" / "baseline_probs.json"))
Xs, ys = simulated_split_data([fit_dir], pair)
model = load_model("activity")
H = {"label": [], "p": [], "f": [], "vis": []}
for f in sorted(held.glob("shard-*.npz")):
    a, _ = load_npz(f)
    H["p"].append(model.classify({"horizontal": a["horizontal"], "vertical": a["vertical"]},
                                 {"horizontal": a["h_offset"], "vertical": a["v_offset"]}))
    H["f"].append(window_features(a["horizontal"], a["vertical"], a["h_offset"], a["v_offset"]))
    H["label"].append(a["label"]); H["vis"].append(a["snr_db_weakest"])
P, F, Y, V = (np.concatenate(H[k]) for k in ("p", "f", "label", "vis"))
vis = np.isnan(V) | (V >= -10)


def block(X, y, Xs_, ys_, ratio):
    w = np.concatenate([np.ones(len(y)), np.full(len(ys_), ratio * len(y) / len(ys_))])
    b = fit(np.concatenate([X, Xs_]), np.concatenate([y, ys_]), weights=w)
    b["pair"] = pair
    return Split(b, ACT_CLASSES)


for ratio in ratios:
    newr, oldr = {}, {}
    for f in range(K):
        X, y = _split_data([r for r in recs if fold_of(r.name, K) != f], pair)
        sp = block(X, y, Xs, ys, ratio)
        for j in np.flatnonzero(folds == f):
            r = recs[j]
            if not scored(r, "activity"):
                continue
            ix = r.eval_index(64)
            feat = window_features(r.horizontal[ix], r.vertical[ix], r.h_offset[ix], r.v_offset[ix]).mean(0)
            p = np.array(base[r.name]["activity"])
            newr[j] = ACT_CLASSES[int(sp.apply(p, feat)[0].argmax())] == r.activity
            oldr[j] = ACT_CLASSES[int(p.argmax())] == r.activity
    js = sorted(newr)
    det = [j for j in js if recs[j].detectable]
    X, y = _split_data(recs, pair)
    sp = block(X, y, Xs, ys, ratio)
    q = sp.apply(P, F).argmax(1)
    n0, n1 = (P.argmax(1)[vis] == Y[vis]).mean(), (q[vis] == Y[vis]).mean()
    a0, a1 = (P.argmax(1) == Y).mean(), (q == Y).mean()
    print(f"sim weight {ratio}: recordings {table([recs[j] for j in js], [newr[j] for j in js], 'activity')} "
          f"+%d -%d p=%.3f" % mcnemar([oldr[j] for j in det], [newr[j] for j in det]),
          f"| held-out sim visible {n0:.1%} -> {n1:.1%}, all {a0:.1%} -> {a1:.1%}", flush=True)
