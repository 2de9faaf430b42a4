"""The shipped models' answers on the recordings, from the cached windows (stride 64)."""
import json, sys
import numpy as np
sys.path.insert(0, __import__('os').path.dirname(__file__))
from common import *
from wallcli.infer.model import load_model
from wallcli.infer.twostage import combine

recs = recordings()
cm, am = load_model("count"), load_model("activity")
odds = cm.card["two_stage"]["prior_two_vs_one"]
out = {}
for r in recs:
    ix = r.eval_index(64)
    w = {"horizontal": r.horizontal[ix], "vertical": r.vertical[ix]}
    o = {"horizontal": r.h_offset[ix], "vertical": r.v_offset[ix]}
    pc = cm.classify({"horizontal": w["horizontal"]}, {"horizontal": o["horizontal"]}).mean(0)
    pa = am.classify(w, o).mean(0)
    p2 = combine(pc[None], pa[None], odds)[0]
    out[r.name] = {"count": p2.tolist(), "count_net": pc.tolist(), "activity": pa.tolist()}
json.dump(out, open(ROOT / "runs" / "baseline_probs.json", "w"))
for task in ("count", "activity"):
    cls = COUNT_CLASSES if task == "count" else ACT_CLASSES
    right = [cls[int(np.argmax(out[r.name][task]))] == truth(r, task) for r in recs]
    print(task, table(recs, right, task))
