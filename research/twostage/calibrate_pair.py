"""Fit when the two-stage count's answer is decided, on the validation set, and store it in the count card.

    python research/twostage/calibrate_pair.py ../shared/transfer models/count.onnx [--activity models/activity.onnx]
        [--level 0.95] [--min-support 12] [--write]

Issue 35 made the transfer set the validation set: thresholds may be fitted there (never a
gradient step). Each clip is answered exactly as `wallcli count` answers it (the two-stage pair,
the light corrections and the view check on), then :func:`wallcli.infer.confidence.fit` gives,
per band of the measured signal (under 0 dB, 0-10 dB, 10 dB and over) and per answer, the lowest
clip probability whose answers are right at least ``level`` of the time with 90 % confidence
(one-sided Wilson bound) on at least ``min_support`` clips. Under 0 dB nothing is decided (a
person under the noise and an empty room give the same plot).

Because the figures of the decided answers on the very clips the thresholds were fitted on flatter
them, the script also reports a two-fold estimate: thresholds fitted on one half of the clips
(alternate clips), the decided answers counted on the other half, both ways.
"""
from __future__ import annotations

import argparse
import json
import multiprocessing as mp
from pathlib import Path

import numpy as np

EDGES = [0.0, 10.0]
_W = {}


def _init(count, activity):
    import os

    os.environ.setdefault("OMP_NUM_THREADS", "1")
    from wallcli.infer.twostage import load_count

    _W["m"] = load_count(count, activity_path=activity, threads=1)


def _one(path):
    from wallcli.infer.classify import classify_video

    r, _ = classify_video(_W["m"], str(path), stride=int(_W["m"].card["stride"]), threads=1)
    return r["probabilities"], r["signal_db"], r["view"]["usable"]


def answers(folder, count, activity, jobs=2):
    from wallcli.evaluate.labels import read_labels

    labels = read_labels(folder)
    clips = labels.clips
    with mp.get_context("spawn").Pool(jobs, initializer=_init, initargs=(count, activity)) as pool:
        got = pool.map(_one, [str(c.path) for c in clips])
    probs = np.array([g[0] for g in got])
    sig = np.array([g[1] for g in got])
    truth = np.array([c.people for c in clips])
    det = np.array([bool(c.detectable) for c in clips])
    return clips, probs, sig, truth, det


def fit_block(probs, truth, sig, level, min_support):
    from wallcli.infer.confidence import fit

    block = fit(probs, truth, sig, [0, 1, 2], level=level, edges=EDGES, min_support=min_support)
    block["thresholds"][0] = [None, None, None]  # under 0 dB: never decided
    return block


def decided(block, probs, sig, truth):
    from wallcli.infer.confidence import judge

    ok = np.array([judge(block, p, s, [0, 1, 2])[0] for p, s in zip(probs, sig)])
    right = probs.argmax(1) == truth
    return int(ok.sum()), int((ok & right).sum())


def main(argv=None) -> int:
    ap = argparse.ArgumentParser()
    ap.add_argument("folder")
    ap.add_argument("count")
    ap.add_argument("--activity", default=None)
    ap.add_argument("--level", type=float, default=0.95)
    ap.add_argument("--min-support", type=int, default=12)
    ap.add_argument("--write", action="store_true", help="store the block in the count card")
    a = ap.parse_args(argv)
    clips, probs, sig, truth, det = answers(a.folder, a.count, a.activity)
    block = fit_block(probs, truth, sig, a.level, a.min_support)
    n, k = decided(block, probs, sig, truth)
    print("thresholds (rows: <0, 0-10, >=10 dB measured signal; columns 0, 1, 2 people):", block["thresholds"])
    print(f"in-sample: decided {n} of {len(clips)} clips, {k} right")
    half = np.arange(len(clips)) % 2
    cv_n = cv_k = 0
    for h in (0, 1):
        fitted = fit_block(probs[half == h], truth[half == h], sig[half == h], a.level, max(6, a.min_support // 2))
        nn, kk = decided(fitted, probs[half != h], sig[half != h], truth[half != h])
        cv_n += nn
        cv_k += kk
    print(f"two-fold (fit on half, count on the other): decided {cv_n} of {len(clips)}, {cv_k} right")
    if a.write:
        from wallcli.infer.card import read_card, write_card
        from wallcli.infer.model import load_model
        from wallcli.infer.twostage import RULE

        act = load_model("activity", a.activity)
        card = read_card(Path(a.count))
        block["fitted_on"] = (f"the transfer set (the validation set since 2026-11-26; {len(clips)} clips, never trained on), "
                              "clip answers of the two-stage pair with the light corrections and the view check on")
        block["two_fold"] = {"decided": cv_n, "right": cv_k, "clips": len(clips),
                             "how": "thresholds fitted on alternate clips, decided answers counted on the others, both ways"}
        block["in_sample"] = {"decided": n, "right": k}
        # the rest of the block (prior_two_vs_one, simulator figures) is kept
        card["two_stage"] = dict(card.get("two_stage") or {}, rule=RULE, activity_model=act.info(), confidence=block)
        write_card(Path(a.count).with_suffix(".json"), card)
        print(f"wrote two_stage block into the card of {a.count}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
