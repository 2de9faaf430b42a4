"""Compare a candidate's out-of-fold answers (whatever folds are done) with the shipped models' on the same clips."""
import sys, json, glob
import numpy as np
sys.path.insert(0, __import__('os').path.dirname(__file__))
from common import *
work, task = sys.argv[1], sys.argv[2]
recs = {r.name: r for r in recordings()}
base = json.load(open(ROOT / "runs" / "baseline_probs.json"))
ans = {}
for f in sorted(glob.glob(f"{work}/fold-*.answers.json")):
    ans.update(json.load(open(f))["answers"])
cls = COUNT_CLASSES if task == "count" else ACT_CLASSES
names = sorted(ans)
sub = [recs[n] for n in names]
right = [cls[int(np.argmax(ans[n]["probs"]))] == truth(recs[n], task) for n in names]
bright = [cls[int(np.argmax(base[n][task]))] == truth(recs[n], task) for n in names]
print("cand ", table(sub, right, task))
print("base ", table(sub, bright, task))
det = [i for i, r in enumerate(sub) if r.detectable]
print("mcnemar det +%d -%d p=%.3f" % mcnemar([bright[i] for i in det], [right[i] for i in det]))
