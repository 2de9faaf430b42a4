import sys, json
import numpy as np
sys.path.insert(0, __import__('os').path.dirname(__file__))
from common import *
recs = recordings()
base = json.load(open(ROOT / "runs" / "baseline_probs.json"))
for task in ("count", "activity"):
    cls = COUNT_CLASSES if task == "count" else ACT_CLASSES
    for b in ("empty", "<0", "0-10", ">=10"):
        cm = np.zeros((len(cls), len(cls)), int)
        for r in recs:
            if band(r) == b and scored(r, task):
                cm[cls.index(truth(r, task)), int(np.argmax(base[r.name][task]))] += 1
        print(task, b, cm.tolist())
