"""Trust from recordings: decided/undetermined thresholds fitted on out-of-sample clip answers.

For a model that never trained on the recordings (the shipped ones), every clip's answer is out of
sample; the thresholds are still judged out of fold: each fold's decisions come from thresholds
fitted on the other folds' answers (wallcli/cli/_train_clips.judge_out_of_fold).
"""
import sys, json
import numpy as np
sys.path.insert(0, __import__('os').path.dirname(__file__))
from common import *
from wallcli.cli._train_clips import judge_out_of_fold
from wallcli.infer.twostage import load_classifier
from wallcli.train.folds import clip_probabilities, clip_signal_db, format_table

level = float(sys.argv[1]) if len(sys.argv) > 1 else 0.97
recs = recordings()
for task in ("count", "activity"):
    model = load_classifier(task)
    sel = [r for r in recs if scored(r, task)]
    answers = {r.name: {"probs": list(clip_probabilities(model, r)), "signal_db": clip_signal_db(model, r)} for r in sel}
    cls = COUNT_CLASSES if task == "count" else ACT_CLASSES
    table, block = judge_out_of_fold(sel, answers, task, cls, level, K)
    print(task, "level", level)
    print("\n".join(format_table(table, task)))
    print(json.dumps(block["thresholds"]))
