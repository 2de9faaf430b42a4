"""Synthetic space-time plots for the inference tests."""
from __future__ import annotations

import numpy as np


def streak_plot(fps: float, seconds: float, bins: int = 64, seed: int = 0):
    """(horizontal, vertical, time): a streak crossing the wall in noise, 8-bit code values."""
    rng = np.random.default_rng(seed)
    t = np.arange(int(round(fps * seconds))) / fps
    pos = (10 + 4.0 * t) % bins
    streak = np.exp(-0.5 * ((np.arange(bins)[:, None] - pos[None]) / 2.0) ** 2)[..., None] * np.array([0.5, 0.4, 0.3])
    h = (streak + rng.normal(0, 0.02, (bins, t.size, 3))).astype(np.float32)
    v = (0.3 * streak[::-1] + rng.normal(0, 0.02, (bins, t.size, 3))).astype(np.float32)
    return h, v, t
