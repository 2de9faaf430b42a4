"""A second look at two answers a net confuses: re-split their probability by the plots' physics.

The activity net reads the recordings' waving as jumping (its simulated waving was another motion).
Where its answer is one of the pair, the probability the two hold together is shared again by a
logistic regression on the window's physical features (:mod:`wallcli.signal.features`), fitted
on labelled recordings (``wallcli train activity --clips DIR --split waving,jumping``). Everything
else is left as the net said. The coefficients are the card's ``split`` block; a clip's answer uses
its windows' mean features, as the clip's probabilities are its windows' mean.
"""
from __future__ import annotations

from typing import Any

import numpy as np

from wallcli.errors import WallcliError
from wallcli.signal.features import NAMES

FORMAT = "wallcli.split v1"


class Split:
    def __init__(self, block: dict[str, Any], classes: list[Any]) -> None:
        why = validate(block, classes)
        if why:
            raise WallcliError(f"the model card's split block is unusable: {why}")
        self.pair = list(block["pair"])
        self.i, self.j = classes.index(self.pair[0]), classes.index(self.pair[1])
        self.mean = np.asarray(block["mean"], np.float64)
        self.scale = np.asarray(block["scale"], np.float64)
        self.coef = np.asarray(block["coef"], np.float64)
        self.intercept = float(block["intercept"])

    def second(self, feats: np.ndarray) -> np.ndarray:
        """P(the pair's second answer | one of the pair), per row of features."""
        z = ((np.atleast_2d(feats) - self.mean) / self.scale) @ self.coef + self.intercept
        return 1.0 / (1.0 + np.exp(-np.clip(z, -50, 50)))

    def apply(self, probs: np.ndarray, feats: np.ndarray) -> np.ndarray:
        p = np.array(np.atleast_2d(probs), np.float64)
        q = self.second(feats)
        top = p.argmax(1)
        on = (top == self.i) | (top == self.j)
        m = p[on, self.i] + p[on, self.j]
        p[on, self.i], p[on, self.j] = m * (1 - q[on]), m * q[on]
        return p


def validate(block: Any, classes: list[Any]) -> str | None:
    if not isinstance(block, dict) or block.get("format") != FORMAT:
        return f"not a {FORMAT} block"
    pair = block.get("pair")
    if not isinstance(pair, list) or len(pair) != 2 or any(c not in classes for c in pair) or pair[0] == pair[1]:
        return "pair must name two of the model's classes"
    if block.get("features") != NAMES:
        return "its features are not the ones this wallcli computes"
    for key in ("mean", "scale", "coef"):
        v = block.get(key)
        if (not isinstance(v, list) or len(v) != len(NAMES)
                or not all(isinstance(x, (int, float)) and not isinstance(x, bool) and np.isfinite(x) for x in v)):
            return f"{key} must be {len(NAMES)} finite numbers"
    if any(s <= 0 for s in block["scale"]):
        return "scale must be positive"
    b = block.get("intercept")
    if not isinstance(b, (int, float)) or isinstance(b, bool) or not np.isfinite(b):
        return "intercept must be a finite number"
    return None


def from_card(card: dict[str, Any]) -> Split | None:
    block = card.get("split")
    return None if block is None else Split(block, list(card["classes"]))


def fit(X: np.ndarray, y: np.ndarray, *, l2: float = 1.0, iters: int = 50,
        weights: np.ndarray | None = None) -> dict[str, Any]:
    """Logistic regression (Newton's method, an L2 penalty on the standardised coefficients):
    deterministic, no optimiser to tune. ``y``: 1 for the pair's second answer; ``weights``: each
    row's weight (default 1)."""
    X = np.asarray(X, np.float64)
    y = np.asarray(y, np.float64)
    sw = np.ones(len(y)) if weights is None else np.asarray(weights, np.float64)
    mean = (X * sw[:, None]).sum(0) / sw.sum()
    scale = np.sqrt(((X - mean) ** 2 * sw[:, None]).sum(0) / sw.sum())
    scale = np.where(scale > 1e-12, scale, 1.0)
    Z = np.concatenate([(X - mean) / scale, np.ones((len(X), 1))], 1)
    w = np.zeros(Z.shape[1])
    pen = np.full(Z.shape[1], l2)
    pen[-1] = 0.0
    for _ in range(iters):
        p = 1.0 / (1.0 + np.exp(-np.clip(Z @ w, -50, 50)))
        g = Z.T @ (sw * (p - y)) + pen * w
        H = (Z * (sw * p * (1 - p))[:, None]).T @ Z + np.diag(pen) + 1e-9 * np.eye(len(w))
        step = np.linalg.solve(H, g)
        w -= step
        if np.abs(step).max() < 1e-10:
            break
    return {"format": FORMAT, "features": list(NAMES), "mean": [float(v) for v in mean],
            "scale": [float(v) for v in scale], "coef": [float(v) for v in w[:-1]], "intercept": float(w[-1]),
            "l2": l2}
