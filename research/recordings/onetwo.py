"""Count: one against two people re-split by a logistic on the plots' features (out of fold)."""
import sys, json
import numpy as np
sys.path.insert(0, __import__('os').path.dirname(__file__))
from common import *
import wavejump as wj

recs, X, folds = wj.recs, wj.X, wj.folds
base = json.load(open(ROOT / "runs" / "baseline_probs.json"))
sel = np.array([r.people in (1, 2) and bool(r.detectable) for r in recs])
y = np.array([1 if r.people == 2 else 0 for r in recs])
for name, cols in (("feat14", slice(5, 19)), ("all", slice(0, 19))):
    q = wj.oof_second(X[:, cols], y, sel, folds, balance=True)
    for mode in ("replace", "product"):
        newr, oldr = [], []
        for j, r in enumerate(recs):
            p = np.array(base[r.name]["count"])
            old = int(p.argmax())
            s = p[1] + p[2]
            if mode == "replace":
                p[1], p[2] = s * (1 - q[j]), s * q[j]
            else:
                a, b = p[1] * (1 - q[j]), p[2] * q[j]
                p[1], p[2] = s * a / (a + b), s * b / (a + b)
            newr.append(int(p.argmax()) == r.people); oldr.append(old == r.people)
        det = [i for i, r in enumerate(recs) if r.detectable]
        print(name, mode, table(recs, newr, "count"), "+%d -%d p=%.3f" % mcnemar([oldr[i] for i in det], [newr[i] for i in det]))
