"""Does the track evidence help count tell two people from one? Out of fold on the recordings.

The how-many stage of today's count (the nets' two-stage answer, runs/baseline_probs.json from
research/recordings/baseline.py) against the same answer with its two-versus-one odds re-read by a
logistic regression on the nets' log-odds and the track features (research/track/twofeat.py,
runs/twofeat.json): fitted on four folds' clips with somebody moving, applied to the fifth. Presence
(nobody against somebody) is left as it is. Paired with today's answers: McNemar over the detectable
clips, and the two-person clips from 10 dB up.

    python research/track/count_oof.py [--features W,Sv,...] [--lam 1.0] [--folds fixed|balanced]
"""
from __future__ import annotations

import argparse
import json
import sys
from pathlib import Path

import numpy as np

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE.parent / "recordings"))
from common import ROOT, K, band, mcnemar, recordings, table  # noqa: E402
from wallcli.train.recordings import fold_of  # noqa: E402

DEFAULT = "W,Wdur,n_tracks,n_moving,Sh,Sh_med,Sh_peak,Shm,Shm_med,Shm_peak,Sv,Sv_med,Sv_peak"


def logistic(X, y, lam):
    """L2 logistic regression by Newton's method (numpy only); returns (mu, sd, w)."""
    mu, sd = X.mean(0), X.std(0) + 1e-9
    Z = np.c_[(X - mu) / sd, np.ones(len(X))]
    w = np.zeros(Z.shape[1])
    reg = np.r_[np.full(Z.shape[1] - 1, lam), 0.0]
    for _ in range(50):
        p = 1 / (1 + np.exp(-Z @ w))
        g = Z.T @ (p - y) + reg * w
        H = (Z * (p * (1 - p))[:, None]).T @ Z + np.diag(reg) + 1e-9 * np.eye(len(w))
        step = np.linalg.solve(H, g)
        w -= step
        if np.abs(step).max() < 1e-8:
            break
    return mu, sd, w


def main() -> None:
    ap = argparse.ArgumentParser()
    ap.add_argument("--features", default=DEFAULT)
    ap.add_argument("--lam", type=float, default=1.0)
    ap.add_argument("--folds", choices=("fixed", "balanced"), default="fixed",
                    help="fixed: the clip's number mod 5 (each fold one kind of light); balanced: (number // 5) mod 5")
    a = ap.parse_args()
    names = a.features.split(",")
    path = ROOT / "runs" / "twofeat.json"
    if not path.is_file():  # every recording's features (truth is not needed), once
        sys.path.insert(0, str(HERE))
        from data import full_plot
        from twofeat import features

        path.write_text(json.dumps({r.name: features(full_plot(r.horizontal, r.h_offset, r.starts, r.frames),
                                                     full_plot(r.vertical, r.v_offset, r.starts, r.frames), 30.0)
                                    for r in recordings()}))
    F = json.loads(path.read_text())
    B = json.loads((ROOT / "runs" / "baseline_probs.json").read_text())
    recs = recordings()
    base = np.array([B[r.name]["count"] for r in recs])
    lab0 = base.argmax(1)
    logodds = np.log(base[:, 2] + 1e-9) - np.log(base[:, 1] + 1e-9)
    feats = np.array([[np.log1p(max(F[r.name][n], 0.0)) for n in names] for r in recs])
    X = np.c_[logodds, feats]
    if a.folds == "fixed":
        folds = np.array([fold_of(r.name, K) for r in recs])
    else:
        import re

        folds = np.array([(int(re.findall(r"\d+", r.name)[0]) // 5) % K for r in recs])
    people = np.array([r.people for r in recs])
    new = lab0.copy()
    for k in range(K):
        tr = (folds != k) & (people >= 1)
        mu, sd, w = logistic(X[tr], (people[tr] == 2).astype(float), a.lam)
        te = (folds == k) & (lab0 >= 1)
        z = np.c_[(X[te] - mu) / sd, np.ones(te.sum())] @ w
        new[te] = np.where(z > 0, 2, 1)
    right0 = lab0 == np.array([r.people for r in recs])
    right1 = new == np.array([r.people for r in recs])
    print("today  ", table(recs, right0.tolist(), "count"))
    print("tracks ", table(recs, right1.tolist(), "count"))
    det = np.array([bool(r.detectable) for r in recs])
    g, l, p = mcnemar(right0[det], right1[det])
    print(f"detectable: +{g} -{l}, McNemar p = {p:.3f}")
    two10 = np.array([r.people == 2 and band(r) == ">=10" for r in recs])
    one10 = np.array([r.people == 1 and band(r) == ">=10" for r in recs])
    print(f"two people >=10 dB: {right0[two10].sum()} -> {right1[two10].sum()} of {two10.sum()}; "
          f"one person >=10 dB: {right0[one10].sum()} -> {right1[one10].sum()} of {one10.sum()}")


if __name__ == "__main__":
    main()
