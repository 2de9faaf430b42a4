"""Two people or one: the count net's odds against what the plot's own structure says.

    python research/render/two_vs_one.py --plots plots.npz --train runs/render/train \\
        --eval ../shared/transfer --eval runs/render/val --answers DIR

A second person who moves independently of the first adds a second independent pattern to the
horizontal space-time plot. Each plot (its three colours averaged) is divided by each position's
frame-to-frame noise (a robust spread of its differences), smoothed over 5 samples (the people's
light is slow, the noise is not), and its singular values are read against the median of those
from the ninth on (where noise alone lies): ``s1 .. s3``. A logistic regression on the count net's
log odds of two against one and log s1..s3 is fitted on the rooms of ``--train`` with people in
them, and read on the ``--eval`` folders (rooms it never saw): the AUC of two against one (every
room with people, and two people with the labels' SNR 10 dB or more against every single person),
and the answers if "how many" were this score with the prior odds given (presence as shipped).

``--answers DIR`` holds ``wallcli evaluate FOLDER --task count --json`` of each folder, named
``<folder name>.json`` (the count net's probabilities per clip). The plots are computed once
(``wallcli.api.compute_plot``) and kept in ``--plots``.
"""
from __future__ import annotations

import argparse
import csv
import json
import os
from pathlib import Path

import numpy as np

SMOOTH = 5  # samples


def _plots(path: Path, folders: list[Path]) -> dict[str, dict]:
    """{folder/file: {h (bins, T), people, snr_db, detectable}}, computed where not yet in ``path``."""
    from wallcli.api import compute_plot

    have = dict(np.load(path, allow_pickle=False)) if path.exists() else {}
    meta: dict[str, dict] = {}
    for folder in folders:
        for r in csv.DictReader(open(folder / "labels.csv")):
            key = f"{folder.name}/{r['file']}"
            clip = folder / r["file"]
            if not clip.exists():
                continue
            if key not in have:
                have[key] = np.asarray(compute_plot(clip).horizontal, np.float64).mean(axis=-1)
            meta[key] = {"people": int(r["people"]), "snr_db": float(r["snr_db"]) if r["snr_db"] else None}
    np.savez_compressed(path, **have)
    return {k: dict(m, h=have[k]) for k, m in meta.items()}


def structure(h: np.ndarray) -> np.ndarray:
    """s1..s3 of the whitened, smoothed plot over its noise singular values."""
    d = np.diff(h, axis=1)
    sig = 1.4826 * np.median(np.abs(d - np.median(d, axis=1, keepdims=True)), axis=1) / np.sqrt(2) + 1e-12
    z = h / sig[:, None]
    k = np.ones(SMOOTH) / SMOOTH
    z = np.array([np.convolve(row, k, mode="valid") for row in z])
    z -= z.mean(axis=1, keepdims=True)
    s = np.linalg.svd(z, compute_uv=False)
    return s[:3] / np.median(s[8:])


def auc(pos, neg) -> float:
    pos, neg = np.asarray(pos, float), np.asarray(neg, float)
    if not len(pos) or not len(neg):
        return float("nan")
    return float(((pos[:, None] > neg[None, :]).sum() + 0.5 * (pos[:, None] == neg[None, :]).sum()) / (len(pos) * len(neg)))


def fit(X: np.ndarray, y: np.ndarray, l2: float = 1.0, steps: int = 3000):
    """A ridge logistic regression by gradient descent on standardised inputs; returns the scorer."""
    mu, sd = X.mean(0), X.std(0) + 1e-9
    Z = np.c_[np.ones(len(X)), (X - mu) / sd]
    w = np.zeros(Z.shape[1])
    for _ in range(steps):
        p = 1 / (1 + np.exp(-Z @ w))
        w -= 0.5 * (Z.T @ (p - y) / len(y) + l2 * np.r_[0, w[1:]] / len(y))
    return lambda X: np.c_[np.ones(len(X)), (X - mu) / sd] @ w


def _rows(plots, answers: dict, folder: str):
    out = []
    for key, m in plots.items():
        name, file = key.split("/", 1)
        a = answers.get(file)
        if name != folder or a is None or a.get("error") is not None:
            continue
        p = a["probabilities"]
        odds = float(np.log((p[2] + 1e-6) / (p[1] + 1e-6)))
        out.append((m, a, np.array([odds, *np.log(structure(m["h"]))])))
    return out


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--plots", type=Path, required=True)
    ap.add_argument("--train", type=Path, required=True)
    ap.add_argument("--eval", type=Path, action="append", required=True)
    ap.add_argument("--answers", type=Path, required=True)
    ap.add_argument("--priors", default="0.25,0.5,1")
    a = ap.parse_args()
    os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")
    plots = _plots(a.plots, [a.train, *a.eval])
    answers = {f.name: {r["file"]: r for r in json.load(open(a.answers / f"{f.name}.json"))["rows"]}
               for f in [a.train, *a.eval]}
    train = [r for r in _rows(plots, answers[a.train.name], a.train.name) if r[0]["people"] > 0]
    X = np.array([x for *_, x in train])
    y = np.array([m["people"] == 2 for m, *_ in train])
    scorers = {"net": (fit(X[:, :1], y), [0]), "structure": (fit(X[:, 1:], y), [1, 2, 3]),
               "net + structure": (fit(X, y), [0, 1, 2, 3])}
    shift = float(np.log(y.mean() / (1 - y.mean())))  # the training rooms' own odds of two among movers
    print(f"fitted on {a.train}: {int(y.sum())} rooms with two people, {int((~y).sum())} with one")
    for folder in a.eval:
        rows = _rows(plots, answers[folder.name], folder.name)
        movers = [r for r in rows if r[0]["people"] > 0]
        two = np.array([m["people"] == 2 for m, *_ in movers])
        strong = np.array([m["people"] == 2 and (m["snr_db"] or -99) >= 10 for m, *_ in movers])
        for name, (f, cols) in scorers.items():
            sc = f(np.array([x[cols] for *_, x in movers]))
            print(f"{folder.name:10s} {name:16s} AUC two vs one {auc(sc[two], sc[~two]):.3f} "
                  f"(two people, 10 dB and over, vs one: {auc(sc[strong], sc[~two]):.3f}; {int(two.sum())} and {int((~two).sum())} rooms)")
        f, cols = scorers["net + structure"]
        det = [r for r in rows if r[1].get("detectable", True)]
        for prior in map(float, a.priors.split(",")):
            right = base = twos = twos_base = n_two = 0
            for m, ans, x in det:
                label = ans["label"]
                if label != 0:  # presence as shipped; how many by the score at this prior
                    label = 2 if f(x[cols][None])[0] - shift + np.log(prior) > 0 else 1
                right += label == ans["truth"]
                base += ans["label"] == ans["truth"]
                if ans["truth"] == 2:
                    n_two += 1
                    twos += label == 2
                    twos_base += ans["label"] == 2
            print(f"{folder.name:10s} prior {prior:g}: detectable right {right}/{len(det)} (shipped {base}); "
                  f"two people counted as two {twos}/{n_two} (shipped {twos_base})")


if __name__ == "__main__":
    main()
