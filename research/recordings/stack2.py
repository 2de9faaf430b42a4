import sys; sys.argv=['a','b']
from oof_head import *
for task in ("count","activity"):
    for bal in (False, True):
        run(task, ["feat"], 1e-3, balance=bal)
    run(task, ["feat"], 1e-3, hidden=16, balance=False)
    run(task, ["feat","lpc","lpa"], 1e-3, balance=False)
