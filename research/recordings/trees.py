"""A learner of another kind on the recordings: trees (issue 53, before blocking on the figures).

Every candidate in README.md that learns from the recordings is linear in what it reads (logistic
heads, the waving/jumping split, the windows' distribution) or a fine-tuned net. Here the same
clip-level inputs go to nonparametric, nonlinear learners that can cut the feature space where a
line cannot: gradient-boosted trees (scikit-learn's HistGradientBoostingClassifier, shallow and
strongly regularised for ~180 training rooms) and extremely randomised trees (ExtraTrees, 500
trees, min 5 clips a leaf).

Inputs, one row per clip (research/recordings/curve.py's Data):
  count     G 'dist+phys' (44: the distribution of the windows' presence and how-many logits, the
            windows' measured signal, the mean probabilities, the 19 physical features)
  activity  the activity net's mean log-probabilities (5) and the 19 physical features, on clips
            with at most one person
Fitted on 4 folds' clips (count: every clip; activity: every clip with at most one person), answering
the fifth; fixed folds and lighting-balanced folds. Paired (exact McNemar, detectable clips) with
today's answers: count's shipped two-stage answers; activity's shipped recipe out of fold (F split).
scikit-learn is a research dependency only (pip install scikit-learn); nothing here ships.

    python research/recordings/trees.py
"""
from __future__ import annotations

import sys
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))
from common import mcnemar, recordings  # noqa: E402
from curve import BANDS, FOLD_RULES, K, WINDOWS, Data, f_answers, score, window_outputs, CACHE  # noqa: E402


def learners():
    from sklearn.ensemble import ExtraTreesClassifier, HistGradientBoostingClassifier

    return {
        "boosted trees, depth 2, 100 rounds": lambda: HistGradientBoostingClassifier(
            max_depth=2, learning_rate=0.05, max_iter=100, min_samples_leaf=10, l2_regularization=1.0,
            random_state=0),
        "boosted trees, depth 3, 200 rounds": lambda: HistGradientBoostingClassifier(
            max_depth=3, learning_rate=0.05, max_iter=200, min_samples_leaf=10, l2_regularization=1.0,
            random_state=0),
        "extra trees, 500, leaf 5": lambda: ExtraTreesClassifier(
            n_estimators=500, min_samples_leaf=5, max_features="sqrt", random_state=0, n_jobs=2),
    }


def answers(D, X, y, ok, make):
    pred = np.full(len(y), -1)
    for f in range(K):
        tr = (D.folds != f) & ok
        te = (D.folds == f) & ok
        m = make().fit(X[tr], y[tr])
        pred[te] = m.predict(X[te])
    return pred


def main() -> None:
    W = {k: v for k, v in np.load(WINDOWS).items()} if WINDOWS.is_file() else window_outputs(CACHE)
    recs = recordings()
    for rule in ("fixed", "balanced"):
        D = Data(W, recs, FOLD_RULES[rule])
        train_all = {f: D.folds != f for f in range(K)}
        refs = {"count": D.shipped_count.argmax(1), "activity": f_answers(D, train_all)}
        inputs = {"count": (D.G["dist+phys"], D.people, np.ones(len(D.names), bool)),
                  "activity": (np.concatenate([np.log(np.clip(D.net_act, 1e-6, 1)), D.phys], 1), D.act, D.single)}
        print(f"\n{rule} folds")
        for task in ("count", "activity"):
            X, y, ok = inputs[task]
            k0, n, r0 = score(D, task, refs[task])
            scored = D.det & (True if task == "count" else D.single)
            every = np.ones(len(y), bool) if task == "count" else D.single
            b0 = [int((r0 & every & (D.bands == b)).sum()) for b in BANDS]
            print(f"  {task} today ({'shipped' if task == 'count' else 'shipped recipe, out of fold'}): "
                  f"{k0} of {n}, bands {b0}")
            for name, make in learners().items():
                pred = answers(D, X, y, ok, make)
                k, n, r = score(D, task, pred)
                g, l, p = mcnemar(r0[scored], r[scored])
                b = [int((r & every & (D.bands == bb)).sum()) for bb in BANDS]
                down = [bb for bb, x0, x1 in zip(BANDS, b0, b) if x0 - x1 >= 2]
                print(f"    {name:36s} {k} of {n} ({100 * k / n:.1f} %), +{g} -{l}, p = {p:.2f}; bands {b}; "
                      f"down by >= 2: {down or 'none'}", flush=True)


if __name__ == "__main__":
    main()
