import sys; sys.argv=['a','b']
from oof_head import *
for task in ("count","activity"):
    for bal in (False, True):
        run(task, ["lpc","lpa"], 1e-3, balance=bal)
    run(task, ["lpc","lpa","fc"], 1e-2, balance=False)
    run(task, ["fc","fh","fv"], 1e-2, balance=False)
