"""The shipped activity model's confusion on simulated one-person windows of each dataset given
(windows whose mover is at least -20 dB), to see whether a change to the simulator makes its
windows fool the model the way the transfer renderer's clips do (waving read as jumping or none).

  python research/features/shipped_on.py data/wide41 data/act44
"""
import json
import sys
from pathlib import Path

import numpy as np

from wallcli.infer.model import Model
from wallcli.io.arrays import load_npz

ACTS = ["none", "walking", "crouching", "waving", "jumping"]
model = Model.load("models/activity.onnx", task="activity")
for root in map(Path, sys.argv[1:]):
    man = json.loads((root / "dataset.json").read_text())
    conf = np.zeros((5, 5), int)
    for s in man["shards"]:
        if not (root / s["file"]).is_file():
            continue
        a, _ = load_npz(root / s["file"], kind="wallcli.dataset-shard")
        act = a["activity"] if man["task"] == "count" else a["label"]
        keep = (a["people"] <= 1) & ((a["snr_db"] >= -20) | (act == 0))
        if not keep.any():
            continue
        inp = {"horizontal": model.normalize(a["horizontal"][keep], a["h_offset"][keep]),
               "vertical": model.normalize(a["vertical"][keep], a["v_offset"][keep])}
        pred = model.predict({n: inp[n] for n in model.input_names}).argmax(1)
        for t_, p_ in zip(act[keep], pred):
            conf[t_, p_] += 1
    print(f"{root}: rows truth, columns answer ({', '.join(ACTS)}); right {np.trace(conf)}/{conf.sum()}")
    for i, row in enumerate(conf):
        print(f"  {ACTS[i]:>9}", " ".join(f"{v:4d}" for v in row))
