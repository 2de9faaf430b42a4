"""The activity net with waving/jumping re-split (wallcli.infer.split), out of fold, package code only."""
import sys, json
import numpy as np
sys.path.insert(0, __import__('os').path.dirname(__file__))
from common import *
from wallcli.infer.split import Split, fit
from wallcli.signal.features import window_features

recs = recordings()
folds = np.array([fold_of(r.name, K) for r in recs])
base = json.load(open(ROOT / "runs" / "baseline_probs.json"))
F = []
for r in recs:
    ix = r.eval_index(64)
    F.append(window_features(r.horizontal[ix], r.vertical[ix], r.h_offset[ix], r.v_offset[ix]).mean(0))
F = np.array(F)
pair = ["waving", "jumping"]
sel = np.array([r.activity in pair and bool(r.detectable) and r.persons <= 1 for r in recs])
y = np.array([1.0 if r.activity == "jumping" else 0.0 for r in recs])
for l2 in [float(a) for a in (sys.argv[1:] or ["1"])]:
    newr, oldr = {}, {}
    for f in range(K):
        blk = fit(F[sel & (folds != f)], y[sel & (folds != f)], l2=l2)
        blk["pair"] = pair
        sp = Split(blk, ACT_CLASSES)
        for j in np.flatnonzero(folds == f):
            r = recs[j]
            if not scored(r, "activity"):
                continue
            p = np.array(base[r.name]["activity"])
            newr[j] = ACT_CLASSES[int(sp.apply(p, F[j])[0].argmax())] == r.activity
            oldr[j] = ACT_CLASSES[int(p.argmax())] == r.activity
    js = sorted(newr)
    sub = [recs[j] for j in js]
    det = [j for j in js if recs[j].detectable]
    print("l2", l2, table(sub, [newr[j] for j in js], "activity"), "+%d -%d p=%.3f" % mcnemar([oldr[j] for j in det], [newr[j] for j in det]))
