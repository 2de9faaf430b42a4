"""Which features move between the simulator and the transfer renderer, class by class.

For every feature: the transfer clips' median (over their windows, then over clips of the
class) placed in the simulator's distribution of the same class (its percentile). A feature
whose transfer median sits at the 5th or 95th simulator percentile is one the simulator does
not produce for that class. Understanding only: nothing is fitted to the transfer clips.

  python research/features/shift.py runs/feat_wide41.npz
"""
import csv
import sys
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))
from experiment import ACTS, transfer_features  # noqa: E402
from feats import names  # noqa: E402

sim = np.load(sys.argv[1])
clips = transfer_features(Path("data/tp"), Path("../shared/transfer/labels.csv"))
nm = names()
groups = {"empty (0)": (lambda p, a: p == 0), "walking": (lambda p, a: (p == 1) & (a == 1)),
          "crouching": (lambda p, a: (p == 1) & (a == 2)), "waving": (lambda p, a: (p == 1) & (a == 3)),
          "jumping": (lambda p, a: (p == 1) & (a == 4)), "two": (lambda p, a: p == 2)}
keep = (sim["snr"] >= -20) | (sim["people"] == 0)
for g, f in groups.items():
    m = f(sim["people"], sim["activity"]) & keep
    if not m.any():
        continue
    tx = []
    for r, x in clips:
        p, a = int(r["people"]), r["activity"]
        ai = ACTS.index(a) if a in ACTS else -1
        if f(np.array(p), np.array(ai)):
            tx.append(np.median(x, axis=0))
    tx = np.median(np.array(tx), axis=0)
    pct = [(sim["x"][m, j] < tx[j]).mean() * 100 for j in range(len(nm))]
    far = [(nm[j], round(pct[j]), round(float(tx[j]), 2), round(float(np.median(sim["x"][m, j])), 2))
           for j in np.argsort(np.abs(np.array(pct) - 50))[::-1][:8]]
    print(f"{g} ({m.sum()} sim windows): most shifted (feature, transfer percentile in sim, transfer median, sim median)")
    for t in far:
        print("   ", t)
