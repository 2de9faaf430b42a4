"""Temporal mean removal: the wall's static light is the mean; the people are what is left.

``clip`` subtracts the mean over the whole recording (best for files). ``window`` (trailing
moving average over ``seconds``) and ``ema`` (exponential running mean with time constant
``seconds``) are causal, so they work on live streams and follow slow lighting drift.
"""

from __future__ import annotations

from collections import deque

import numpy as np

MODES = ("clip", "window", "ema")


class RunningMean:
    """Causal mean of a stream of equally shaped rows, as a function of their timestamps."""

    def __init__(self, mode: str, seconds: float):
        if mode not in ("window", "ema"):
            raise ValueError(f"unknown running-mean mode {mode!r}")
        if not seconds > 0:
            raise ValueError("the mean's time span must be > 0 seconds")
        self.mode, self.seconds = mode, float(seconds)
        self._mean = None
        self._t = None
        self._buf: deque = deque()
        self._sum = None

    def update(self, t: float, row: np.ndarray) -> np.ndarray:
        """Add a row observed at time ``t``; return the current mean (float64)."""
        row = np.asarray(row, dtype=np.float64)
        if self.mode == "ema":
            if self._mean is None:
                self._mean = row.copy()
            else:
                # Time-aware decay so variable frame rates weigh time, not frames.
                a = 1.0 - np.exp(-max(t - self._t, 0.0) / self.seconds)
                self._mean += a * (row - self._mean)
            self._t = t
            return self._mean
        self._buf.append((t, row))
        self._sum = row.copy() if self._sum is None else self._sum + row
        while self._buf and self._buf[0][0] <= t - self.seconds:
            self._sum -= self._buf.popleft()[1]
        return self._sum / len(self._buf)


def remove_mean(rows: np.ndarray, times: np.ndarray, mode: str = "clip", seconds: float = 10.0) -> np.ndarray:
    """Mean-removed copy of ``rows`` (time along axis 0), float32."""
    rows = np.asarray(rows, dtype=np.float64)
    if mode == "clip":
        return (rows - rows.mean(axis=0, keepdims=True)).astype(np.float32)
    rm = RunningMean(mode, seconds)
    out = np.empty(rows.shape, np.float32)
    for i, (t, r) in enumerate(zip(times, rows)):
        out[i] = r - rm.update(float(t), r)
    return out


def remove_mean_in_place(rows: np.ndarray, times: np.ndarray, mode: str = "clip", seconds: float = 10.0,
                         chunk: int = 128) -> np.ndarray:
    """:func:`remove_mean` written over ``rows`` (float32, time along axis 0), a ``chunk`` of rows
    at a time: the same values, without a second (or float64) copy of a long plot. Returns the
    clip mean (float64) of the rows as they were."""
    clip = rows.mean(axis=0, dtype=np.float64)
    if mode == "clip":
        for i in range(0, rows.shape[0], chunk):
            rows[i:i + chunk] = rows[i:i + chunk] - clip  # in float64, rounded once, as remove_mean
        return clip
    rm = RunningMean(mode, seconds)
    for i, t in enumerate(times):
        r = rows[i].astype(np.float64)
        rows[i] = r - rm.update(float(t), r)
    return clip
