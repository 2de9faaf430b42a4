"""Trust from recordings: decided/undetermined thresholds fitted on out-of-sample clip answers.

For a model that never trained on the recordings (count 0.4.1 in two stages), every clip's answer
is out of sample; the thresholds are still judged out of fold: each fold's decisions come from
thresholds fitted on the other folds' answers (wallcli/cli/_train_clips.judge_out_of_fold).
Activity 0.4.0's waving/jumping split was fitted on the first 220 clips, so its answers as shipped
are in sample there: the activity rows use the split refitted per fold on the other folds
(split_oof.py's answers, 'activity, split out of fold'); the shipped model's own answers are shown
as well ('activity as shipped', optimistic), and the net alone.

Beyond the rule's verdict it prints, per band of measured signal (the rule's bands, answers other
than nobody) and pooled, the run of right answers from the most confident answer down before the
first error, the best one-sided 95 % Wilson bound of any prefix of at least 10, and the exact bound a
run of n right gives (0.05 ** (1 / n); 97 % needs n >= 99).

Run: python research/recordings/trust.py [LEVEL] (default 0.97).
"""
import sys, json
import numpy as np
sys.path.insert(0, __import__('os').path.dirname(__file__))
from common import *
from wallcli.cli._train_clips import judge_out_of_fold
from wallcli.infer.confidence import NOBODY, band_of, wilson_lower
from wallcli.infer.model import load_model
from wallcli.infer.split import Split, fit as split_fit
from wallcli.infer.twostage import load_classifier
from wallcli.signal.features import window_features
from wallcli.train.folds import Z95_ONE_SIDED, clip_probabilities, clip_signal_db, format_table

level = float(sys.argv[1]) if len(sys.argv) > 1 else 0.97
EDGES = (0.0, 10.0)
recs = recordings()


def runs(sel, answers, cls, task):
    """Per band and pooled: (answers, leading run of right answers, best Wilson bound of a prefix >= 10)."""
    probs = np.array([answers[r.name]["probs"] for r in sel])
    sig = np.array([answers[r.name]["signal_db"] for r in sel])
    lab = np.array([cls.index(truth(r, task)) for r in sel])
    pred, pmax = probs.argmax(1), probs.max(1)
    someone = np.array([cls[k] not in NOBODY for k in pred])
    bands = np.array([band_of(list(EDGES), s) for s in sig])
    names = [r.name for r in sel]
    out = {}
    for name, m in (("< 0 dB", bands == 0), ("0-10 dB", bands == 1), (">= 10 dB", bands == 2), ("pooled", bands >= 0)):
        m = m & someone
        o = np.argsort(-pmax[m], kind="stable")
        ok = (pred[m] == lab[m])[o]
        run = int(np.argmax(~ok)) if (~ok).any() else int(ok.size)
        hits, n = np.cumsum(ok), np.arange(1, ok.size + 1)
        wl = wilson_lower(hits, n, Z95_ONE_SIDED)
        best = float(wl[9:].max()) if ok.size >= 10 else float("nan")
        at = int(np.argmax(wl[9:]) + 10) if ok.size >= 10 else 0
        wrong = [(int(i + 1), names[j], cls[pred[m][o][i]], round(float(pmax[m][o][i]), 3))
                 for i, j in zip(np.flatnonzero(~ok)[:2], np.flatnonzero(m)[o][np.flatnonzero(~ok)[:2]])]
        out[name] = dict(answers=int(ok.size), right=int(ok.sum()), run=run, exact_bound=0.05 ** (1 / run) if run else 0.0,
                         best_wilson=best, best_wilson_at=at, first_errors=wrong)
    return out


base = json.load(open(ROOT / "runs" / "baseline_probs.json"))
folds = np.array([fold_of(r.name, K) for r in recs])
am = load_model("activity")
F = np.stack([window_features(r.horizontal[r.eval_index(64)], r.vertical[r.eval_index(64)],
                              r.h_offset[r.eval_index(64)], r.v_offset[r.eval_index(64)]).mean(0) for r in recs])
pair = ["waving", "jumping"]
sel_split = np.array([r.activity in pair and bool(r.detectable) and r.persons <= 1 for r in recs])
yb = np.array([1.0 if r.activity == "jumping" else 0.0 for r in recs])
oof_act = {}
for f in range(K):
    blk = split_fit(F[sel_split & (folds != f)], yb[sel_split & (folds != f)], l2=1.0)
    blk["pair"] = pair
    sp = Split(blk, ACT_CLASSES)
    for j in np.flatnonzero(folds == f):
        oof_act[recs[j].name] = sp.apply(np.array(base[recs[j].name]["activity"]), F[j])[0]

report = {}
for task, kind in (("count", "shipped"), ("activity", "split out of fold"), ("activity", "as shipped"),
                   ("activity", "net alone")):
    model = load_classifier(task)
    sel = [r for r in recs if scored(r, task)]
    answers = {}
    for r in sel:
        if kind == "split out of fold":
            p = oof_act[r.name]
        elif kind == "net alone":
            p = np.array(base[r.name]["activity"])
        else:
            p = clip_probabilities(model, r)
        answers[r.name] = {"probs": [float(v) for v in p], "signal_db": clip_signal_db(model, r)}
    cls = COUNT_CLASSES if task == "count" else ACT_CLASSES
    tab, block = judge_out_of_fold(sel, answers, task, cls, level, K)
    print(f"\n{task} ({kind}), level {level}, {len(sel)} clips")
    print("\n".join(format_table(tab, task)))
    print("thresholds (every fold):", json.dumps(block["thresholds"]))
    rr = runs(sel, answers, cls, task)
    for b, v in rr.items():
        print(f"  {b:8s}: {v['answers']} answers ({v['right']} right); the most confident {v['run']} right before the "
              f"first error (exact 95 % bound {v['exact_bound']:.3f}); best Wilson bound of a prefix >= 10: "
              f"{v['best_wilson']:.3f} at {v['best_wilson_at']}; first errors (rank, clip, answer, p): {v['first_errors']}")
    report[f"{task} | {kind}"] = {"thresholds": block["thresholds"], "runs": rr}
json.dump(report, open(ROOT / "runs" / "trust.json", "w"), indent=1)
n97 = int(np.ceil(np.log(0.05) / np.log(level)))
print(f"\na run of n right answers gives the exact one-sided 95 % bound 0.05^(1/n); {level:g} needs n >= {n97}")
