"""Approach G: the clip as a whole, not the mean of its windows (count, out of fold).

The shipped count answers a clip with the mean of its windows' probabilities (two stages: the
count net and the activity net's presence evidence, then the count net's one-against-two share at
the card's prior odds). Here each clip becomes one row of features of the DISTRIBUTION of its
windows' outputs (every harvested window, stride 16): per window the presence logit
(log p(somebody) / p(nobody)) and the how-many logit (log p(two) / p(one) given somebody), each
summarised by mean, max, min and the 0.25 / 0.75 / 0.9 quantiles; the share of windows whose
two-stage argmax is each class; the windows' measured signal (window_signal_db of both plots: mean,
std, max - min); the log of the clip's mean two-stage probabilities. Optionally the clip's mean of
the 19 physical features (wallcli/signal/features.py). A multinomial logistic regression (L2 on the
weights, features standardised on the training rows) is fitted per fold on the other 4 folds'
clips, one row per clip, and answers the held-out fold.

Settings (the full sweep is printed, with how many were compared):
  features  shallow (mean + max of both logits, 4), dist (25), dist+phys (44)
  C         0.1, 1, 10 (sklearn's convention: C * sum of log-losses + |W|^2 / 2)
  rows      all clips of the training folds, or only their detectable clips
and one nested choice: inside each outer fold's training folds, each setting is scored by a
leave-one-fold-out over those 4 folds (detectable clips right), the best is refitted on the 4
folds and answers the outer fold (ties: the earlier setting in the sweep's order).

Run: python research/recordings/aggregate.py [--cache DIR] (default $WALLCLI_RECCACHE, else
runs/reccache of this checkout). The windows' outputs are kept in runs/aggregate_windows.npz.
"""
from __future__ import annotations

import argparse
import itertools
import json
import os
import sys
from pathlib import Path

import numpy as np
from scipy.optimize import minimize

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from common import *  # noqa: E402,F403
from common import CACHE, ROOT, TRANSFER, K, band, mcnemar  # noqa: E402
from wallcli.infer.twostage import combine  # noqa: E402
from wallcli.evaluate.score import exact_ci  # noqa: E402
from wallcli.train.recordings import fold_of, load_recordings  # noqa: E402

BANDS = ("empty", "<0", "0-10", ">=10")
QS = (0.25, 0.75, 0.9)
OUT = ROOT / "runs" / "aggregate_windows.npz"


def window_outputs(cache: Path) -> dict:
    """Per window (stride 16): both nets' probabilities, signal_db, the 19 features; per clip:
    the shipped answer (stride 64) and the labels."""
    from wallcli.infer.model import load_model
    from wallcli.signal.features import window_features
    from wallcli.signal.window import window_signal_db

    recs = load_recordings([TRANSFER], cache)
    cm, am = load_model("count"), load_model("activity")
    odds = cm.card["two_stage"]["prior_two_vs_one"]
    pc, pa, db, feat, clip, at64 = [], [], [], [], [], []
    shipped = []
    for j, r in enumerate(recs):
        w = {"horizontal": r.horizontal, "vertical": r.vertical}
        o = {"horizontal": r.h_offset, "vertical": r.v_offset}
        c = cm.classify({"horizontal": w["horizontal"]}, {"horizontal": o["horizontal"]})
        a = am.classify(w, o)
        pc.append(c); pa.append(a)
        db.append(window_signal_db([(r.horizontal, r.h_offset), (r.vertical, r.v_offset)]))
        feat.append(window_features(r.horizontal, r.vertical, r.h_offset, r.v_offset))
        clip.append(np.full(len(c), j))
        m = np.zeros(len(c), bool)
        ix = r.eval_index(64)
        m[ix] = True
        at64.append(m)
        shipped.append(combine(c[ix].mean(0)[None], a[ix].mean(0)[None], odds)[0])
        print(f"\r{j + 1}/{len(recs)}", end="", file=sys.stderr, flush=True)
    print(file=sys.stderr)
    snr = np.array([np.nan if r.snr_db is None else r.snr_db for r in recs])
    out = dict(pc=np.concatenate(pc), pa=np.concatenate(pa), db=np.concatenate(db), feat=np.concatenate(feat),
               clip=np.concatenate(clip), at64=np.concatenate(at64), shipped=np.array(shipped),
               names=np.array([r.name for r in recs]), people=np.array([r.people for r in recs]),
               detectable=np.array([bool(r.detectable) for r in recs]), snr=snr, odds=np.array(odds))
    OUT.parent.mkdir(parents=True, exist_ok=True)
    np.savez(OUT, **out)
    return out


def logit(p):
    p = np.clip(p, 1e-6, 1 - 1e-6)
    return np.log(p) - np.log1p(-p)


def clip_features(W: dict) -> dict[str, np.ndarray]:
    """The three feature sets, one row per clip."""
    n = len(W["names"])
    p2 = combine(W["pc"], W["pa"], float(W["odds"]))
    pres = logit(1 - p2[:, 0])  # stage 1: somebody moves
    how = logit(p2[:, 2] / np.maximum(p2[:, 1] + p2[:, 2], 1e-300))  # stage 2: two, given somebody
    arg = p2.argmax(1)
    shallow, dist, phys = [], [], []
    for j in range(n):
        m = W["clip"] == j
        s, h, d = pres[m], how[m], W["db"][m]
        stats = lambda x: [x.mean(), x.max(), x.min(), *np.quantile(x, QS)]  # noqa: E731
        mean_p = p2[m].mean(0)
        shallow.append([s.mean(), s.max(), h.mean(), h.max()])
        dist.append(stats(s) + stats(h) + [np.mean(arg[m] == k) for k in range(3)]
                    + [d.mean(), d.std(), d.max() - d.min()] + list(np.log(np.clip(mean_p, 1e-6, 1))))
        phys.append(W["feat"][m].mean(0))
    dist = np.array(dist)
    return {"shallow": np.array(shallow), "dist": dist, "dist+phys": np.concatenate([dist, np.array(phys)], 1)}


def fit_mlr(X, y, C, k=3):
    """Multinomial logistic regression: C * sum log-loss + |W|^2 / 2 (intercepts free)."""
    mu, sd = X.mean(0), X.std(0)
    sd[sd < 1e-9] = 1.0
    Z = (X - mu) / sd
    n, d = Z.shape
    Y = np.eye(k)[y]

    def f(theta):
        Wt, b = theta[:d * k].reshape(d, k), theta[d * k:]
        L = Z @ Wt + b
        L = L - L.max(1, keepdims=True)
        lse = np.log(np.exp(L).sum(1, keepdims=True))
        P = np.exp(L - lse)
        loss = C * -(Y * (L - lse)).sum() + 0.5 * (Wt ** 2).sum()
        G = C * (P - Y)
        return loss, np.concatenate([(Z.T @ G + Wt).ravel(), G.sum(0)])

    res = minimize(f, np.zeros(d * k + k), jac=True, method="L-BFGS-B", options={"maxiter": 2000})
    Wt, b = res.x[:d * k].reshape(d, k), res.x[d * k:]
    return lambda Xn: ((Xn - mu) / sd) @ Wt + b


SETTINGS = [(fs, C, rows) for fs, C, rows in itertools.product(("shallow", "dist", "dist+phys"), (0.1, 1.0, 10.0),
                                                              ("all", "detectable"))]


def oof(F, y, det, folds, setting, train_folds, test_fold):
    fs, C, rows = setting
    tr = np.isin(folds, train_folds)
    if rows == "detectable":
        tr &= det
    model = fit_mlr(F[fs][tr], y[tr], C)
    te = folds == test_fold
    return np.flatnonzero(te), model(F[fs][te]).argmax(1)


def answers(F, y, det, folds, setting):
    pred = np.zeros(len(y), int)
    for f in range(K):
        ix, p = oof(F, y, det, folds, setting, [g for g in range(K) if g != f], f)
        pred[ix] = p
    return pred


def nested(F, y, det, folds):
    pred, chosen = np.zeros(len(y), int), []
    for f in range(K):
        inner = [g for g in range(K) if g != f]
        scores = []
        for s in SETTINGS:
            right = 0
            for g in inner:
                ix, p = oof(F, y, det, folds, s, [h for h in inner if h != g], g)
                right += int(((p == y[ix]) & det[ix]).sum())
            scores.append(right)
        best = SETTINGS[int(np.argmax(scores))]
        chosen.append(best)
        ix, p = oof(F, y, det, folds, best, inner, f)
        pred[ix] = p
    return pred, chosen


def auc(score, pos):
    """Mann-Whitney AUC (ties half)."""
    s1, s0 = score[pos], score[~pos]
    return float(((s1[:, None] > s0[None]).sum() + 0.5 * (s1[:, None] == s0[None]).sum()) / (len(s1) * len(s0)))


def row(name, pred, y, bands, det, base_right):
    right = pred == y
    cells = [f"{int(right[bands == b].sum())}" for b in BANDS]
    k, n = int(right[det].sum()), int(det.sum())
    lo, hi = exact_ci(k, n)  # Clopper-Pearson since #54.2 (tables written before it show Wilson's)
    g, l, p = mcnemar(base_right[det], right[det])
    return (f"| {name} | " + " | ".join(cells) + f" | {k} ({100 * k / n:.1f} %, {100 * lo:.0f}-{100 * hi:.0f} %) "
            f"| +{g} -{l}, p = {p:.3g} |"), (k, g, l, p, [int(right[bands == b].sum()) for b in BANDS])


def confusion(pred, y, det) -> str:
    lines = ["| truth \\ answer | 0 | 1 | 2 |", "|---|---|---|---|"]
    for t in range(3):
        m = (y == t)
        lines.append(f"| {t} (detectable {int((m & det).sum())}) | "
                     + " | ".join(f"{int(((pred == a) & m).sum())} ({int(((pred == a) & m & det).sum())})"
                                  for a in range(3)) + " |")
    return "\n".join(lines)


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--cache", default=os.environ.get("WALLCLI_RECCACHE", str(CACHE)))
    ap.add_argument("--recompute", action="store_true")
    a = ap.parse_args()
    if OUT.is_file() and not a.recompute:
        W = {k: v for k, v in np.load(OUT).items()}
    else:
        W = window_outputs(Path(a.cache))
    names = list(W["names"])
    y, det = W["people"].astype(int), W["detectable"].astype(bool)
    bands = np.array(["empty" if p == 0 else "<0" if not (s >= 0) else "0-10" if s < 10 else ">=10"
                      for p, s in zip(y, W["snr"])])
    folds = np.array([fold_of(nm, K) for nm in names])
    base = W["shipped"].argmax(1)
    base_right = base == y
    print("clips", len(y), "windows", len(W["clip"]), "detectable", int(det.sum()),
          "by band", {b: int((bands == b).sum()) for b in BANDS})
    F = clip_features(W)
    # does the distribution separate the pairs the mean confuses? (rank AUC on detectable clips, no fit)
    names_d = ["pres mean", "pres max", "pres min", "pres q25", "pres q75", "pres q90",
               "how mean", "how max", "how min", "how q25", "how q75", "how q90"]
    for title, a, b in (("two against one", 1, 2), ("one against nobody", 0, 1)):
        sel = det & np.isin(y, [a, b])
        aucs = [auc(F["dist"][sel, i], y[sel] == b) for i in range(12)]
        print(f"AUC {title} ({int((sel & (y == b)).sum())} vs {int((sel & (y == a)).sum())}):",
              ", ".join(f"{nm} {v:.2f}" for nm, v in zip(names_d, aucs)))
    print("\n| setting | empty (37) | < 0 (41) | 0-10 (67) | >= 10 (75) | detectable of 179 (95 %) | against shipped |")
    print("|---|---|---|---|---|---|---|")
    print(row("shipped (mean of stride-64 windows)", base, y, bands, det, base_right)[0])
    mean16 = combine(np.stack([W["pc"][W["clip"] == j].mean(0) for j in range(len(y))]),
                     np.stack([W["pa"][W["clip"] == j].mean(0) for j in range(len(y))]), float(W["odds"])).argmax(1)
    print(row("mean of every stride-16 window (no fit)", mean16, y, bands, det, base_right)[0])
    results, preds = {}, {}
    for s in SETTINGS:
        pred = answers(F, y, det, folds, s)
        line, res = row(f"{s[0]}, C = {s[1]:g}, rows {s[2]}", pred, y, bands, det, base_right)
        results[s], preds[s] = res, pred
        print(line)
    pred, chosen = nested(F, y, det, folds)
    line, res = row("**nested choice**", pred, y, bands, det, base_right)
    print(line)
    print("\nnested choice per outer fold:", [f"{c[0]} C={c[1]:g} {c[2]}" for c in chosen])
    best = max(SETTINGS, key=lambda s: (results[s][0], -results[s][3]))
    print(f"\n{len(SETTINGS)} settings compared (+ the nested choice). Best of the sweep: {best}")
    print("\nconfusion, shipped (all clips; detectable in brackets):\n" + confusion(base, y, det))
    print("\nconfusion, best of the sweep:\n" + confusion(preds[best], y, det))
    print("\nconfusion, nested choice:\n" + confusion(pred, y, det))
    allres = dict(results); allres[("nested", 0, "")] = res
    ships = []
    for s, (k, g, l, p, bb) in allres.items():
        down = max(0, *[b0 - b1 for b0, b1 in zip([int(base_right[bands == b].sum()) for b in BANDS], bb)])
        if p <= 0.1 and down < 2 and g > l:
            ships.append(s)
    print("\nmeets the shipping rule (p <= 0.1, gains > losses, no band down by 2 or more):", ships or "none")
    json.dump({"settings": {f"{s[0]}|{s[1]}|{s[2]}": v for s, v in allres.items()},
               "chosen": [list(c) for c in chosen]}, open(ROOT / "runs" / "aggregate.json", "w"))


if __name__ == "__main__":
    main()
