"""A tracker that learns where the person is from the motion-capture truth, instead of taking the
darkest place (issue 52, a try different in kind from wallcli/signal/track.py).

Each sample's 64 places along the view are scored by a conditional logit (one softmax over the
places, trained on the truth's place) on features of the place: the darkness map there (either
sign), at its mirror image across the view's centre and at the place a shade magnified 1.5x about
the centre would be (the side-window and back-window geometries of README.md), the local change
energy, the place's distance from the edges, and each of those multiplied by clip-level cues of
the light that a run-time command has (the mean frame's level profiles and colours). So the model
may learn "in a room lit like this, the person is where the shade's mirror image is". The best
path through the learned log-probabilities (Viterbi at the shipped speed limit) is then read as a
track.

Out of fold twice: by the fixed fold rule (each fold one kind of light, so a light is never seen
in training when it is judged) and by the lighting-balanced split `(number // 5) % 5`. Figures on
the detectable single walkers, on the same samples as the shipped tracker's longest track (paired,
McNemar), and over every sample the walker moves.

    python research/track/learned.py [--lam 1.0]
"""
from __future__ import annotations

import argparse
import re
import sys
from pathlib import Path

import numpy as np
from scipy.optimize import minimize

sys.path.insert(0, str(Path(__file__).resolve().parent))
sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "recordings"))
from common import mcnemar  # noqa: E402
from data import clips  # noqa: E402
from wallcli.signal.track import MAX_SPEED, _smooth, darkness, track_rows, viterbi  # noqa: E402
from wallcli.train.recordings import FPS  # noqa: E402

B = 64


def resample_bins(a: np.ndarray) -> np.ndarray:
    if a.shape[1] == B:
        return a
    src = (np.arange(a.shape[1]) + 0.5) / a.shape[1]
    dst = (np.arange(B) + 0.5) / B
    return np.stack([np.interp(dst, src, row) for row in a])


def clip_cues(c) -> np.ndarray:
    """What the mean frame says about the light: the level profiles' slope and curvature along the
    width and the height, their contrast, and the colour balance."""
    out = []
    for plot in (c.h, c.v):
        m = plot.mean(axis=0)  # (bins, 3)
        lum = m.mean(axis=1)
        u = np.linspace(-1, 1, len(lum))
        lvl = lum / max(lum.mean(), 1e-9)
        p = np.polyfit(u, lvl, 2)
        out += [p[1], p[0], lvl.std()]
    col = c.h.mean(axis=(0, 1))
    col = col / max(col.sum(), 1e-9)
    out += [col[0] - col[2], col[1] - (col[0] + col[2]) / 2]
    return np.array(out)


def place_features(c):
    """(T, B, F0) features of every place and sample."""
    D = resample_bins(darkness(c.h, FPS))
    E = _smooth(np.abs(np.gradient(D, axis=0)) * FPS, 0.3 * FPS, 0)
    idx = np.arange(B)
    mirror = B - 1 - idx
    mag = np.clip(np.round((B - 1) / 2 + 1.5 * (idx - (B - 1) / 2)), 0, B - 1).astype(int)
    pos = (idx + 0.5) / B
    edge = np.broadcast_to(np.exp(-np.minimum(pos, 1 - pos) / 0.05), D.shape)
    cols = [D, -np.minimum(D, 0), D[:, mirror], -np.minimum(D[:, mirror], 0), D[:, mag], E, E[:, mirror], edge]
    return np.stack(cols, axis=-1).astype(np.float32)


def build(cs):
    rows = []
    for c in cs:
        F0 = place_features(c)
        cue = clip_cues(c)
        rows.append((c, F0, cue))
    cue_all = np.array([r[2] for r in rows])
    return rows, cue_all


def design(F0, cue, mu, sd):
    z = (cue - mu) / sd
    inter = F0[..., :, None] * z[None, None, None, :]
    return np.concatenate([F0, inter.reshape(*F0.shape[:2], -1)], axis=-1)


def fit(X, y, lam):
    n, b, f = X.shape
    sc = np.ones(f, np.float32)
    sc = X.reshape(-1, f).std(axis=0) + 1e-6
    Xs = X / sc

    def loss(th):
        s = Xs @ th
        s = s - s.max(axis=1, keepdims=True)
        p = np.exp(s)
        Z = p.sum(axis=1)
        p /= Z[:, None]
        ll = s[np.arange(n), y] - np.log(Z)
        g = np.einsum("nb,nbf->f", p, Xs) - Xs[np.arange(n), y].sum(axis=0)
        return -ll.sum() + lam * th @ th, g + 2 * lam * th

    th = minimize(loss, np.zeros(f), jac=True, method="L-BFGS-B", options={"maxiter": 300}).x
    return th / sc


def label_bins(x):
    return np.clip(np.floor(np.clip(x, 0, 1) * B), 0, B - 1).astype(int)


def one_mover(c):
    """Samples where exactly one person moves, and that person's x."""
    if c.x.shape[0] == 0:
        return None, None
    mv = c.moving
    one = mv.sum(axis=0) == 1
    k = np.argmax(mv, axis=0)
    x = c.x[k, np.arange(c.x.shape[1])]
    ok = one & np.isfinite(x) & (x >= 0) & (x <= 1)  # beyond the view every place is as wrong
    return ok, x


def figures(xe, xt):
    r = float(np.corrcoef(xe, xt)[0, 1]) if len(xe) > 2 and np.std(xe) > 0 and np.std(xt) > 0 else 0.0
    return r, float(np.median(np.abs(xe - xt)))


def balanced_fold(name: str) -> int:
    return (int(re.search(r"\d+", name).group()) // 5) % 5


def run(rows, cue_all, fold_fn, lam, shipped, walkers_only=False):
    names = [r[0].name for r in rows]
    folds = np.array([fold_fn(n) for n in names])
    res = {}
    for k in range(5):
        tr = [i for i in range(len(rows)) if folds[i] != k and rows[i][0].detectable]
        mu, sd = cue_all[tr].mean(axis=0), cue_all[tr].std(axis=0) + 1e-9
        Xs, ys = [], []
        for i in tr:
            c, F0, cue = rows[i]
            ok, x = one_mover(c)
            if ok is None or (walkers_only and "walking" not in c.activities):
                continue
            sel = np.flatnonzero(ok)[::3]
            if len(sel) == 0:
                continue
            Xs.append(design(F0[sel], cue, mu, sd))
            ys.append(label_bins(x[sel]))
        th = fit(np.concatenate(Xs), np.concatenate(ys), lam)
        for i in range(len(rows)):
            c, F0, cue = rows[i]
            if folds[i] != k or not (c.people == 1 and c.activity == "walking" and c.detectable):
                continue
            S = design(F0, cue, mu, sd) @ th
            S = S - S.max(axis=1, keepdims=True)
            logp = S - np.log(np.exp(S).sum(axis=1, keepdims=True))
            path = viterbi(logp, MAX_SPEED * B / FPS)
            xe = (path + 0.5) / B
            t_sh, _ = shipped[c.name]
            tt = np.arange(len(xe)) / FPS
            same = np.interp(t_sh, tt, xe) if len(t_sh) else np.zeros(0)
            xt_same = np.interp(t_sh, tt, c.x[0]) if len(t_sh) else np.zeros(0)
            mv = c.moving[0] & np.isfinite(c.x[0])
            res[c.name] = {"same": figures(same, xt_same) if len(t_sh) else (0.0, 1.0),
                           "all": figures(xe[mv], c.x[0][mv])}
    return res


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--lam", type=float, default=1.0)
    ap.add_argument("--walkers-only", action="store_true", help="train on walking people only")
    ap.add_argument("--no-cues", action="store_true", help="no clip-level light cues (place features only)")
    a = ap.parse_args()
    cs = clips()
    rows, cue_all = build(cs)
    if a.no_cues:
        rows = [(c, F0, cue[:0]) for c, F0, cue in rows]
        cue_all = cue_all[:, :0]
    shipped = {}
    walkers = [c for c in cs if c.people == 1 and c.activity == "walking" and c.detectable]
    base = {}
    for c in walkers:
        tracks = track_rows(c.h, np.arange(c.h.shape[0]) / FPS, FPS)
        if tracks:
            tr = max(tracks, key=lambda t: t.duration)
            t = np.asarray(tr.t)
            shipped[c.name] = (t, np.asarray(tr.x))
            base[c.name] = figures(np.asarray(tr.x), np.interp(t, np.arange(c.x.shape[1]) / FPS, c.x[0]))
        else:
            shipped[c.name] = (np.zeros(0), np.zeros(0))
            base[c.name] = (0.0, 1.0)
    names = sorted(base)
    b_r = np.array([base[n][0] >= 0.8 for n in names])
    b_e = np.array([base[n][1] <= 0.25 for n in names])
    print(f"walkers {len(names)}; shipped tracker: r>=0.8 {b_r.sum()}, err<=0.25 {b_e.sum()}")
    for label, fn in (("fixed folds", lambda n: int(re.search(r"\d+", n).group()) % 5), ("balanced folds", balanced_fold)):
        res = run(rows, cue_all, fn, a.lam, shipped, a.walkers_only)
        for part in ("same", "all"):
            r_ok = np.array([res[n][part][0] >= 0.8 for n in names])
            e_ok = np.array([res[n][part][1] <= 0.25 for n in names])
            line = f"{label:15s} {part:4s}: r>=0.8 {r_ok.sum():2d}/{len(names)}, err<=0.25 {e_ok.sum():2d}/{len(names)}"
            if part == "same":
                p1, m1, pr = mcnemar(b_r, r_ok)
                p2, m2, pe = mcnemar(b_e, e_ok)
                line += f"  (vs shipped: r +{p1} -{m1} p={pr:.2f}; err +{p2} -{m2} p={pe:.2f})"
            print(line)
        for n in names:
            print(f"    {n:24s} shipped r={base[n][0]:+.2f} e={base[n][1]:.2f} | learned r={res[n]['same'][0]:+.2f} "
                  f"e={res[n]['same'][1]:.2f} | all r={res[n]['all'][0]:+.2f} e={res[n]['all'][1]:.2f}")


if __name__ == "__main__":
    main()
