"""Two stages of a camera's image signal processor that real footage passes through
(``simulate --tnr``, ``--awb-drift``; also applied to decoded clips by research/pipelines).

- **Temporal noise reduction**: phones and DVRs blend each frame with the previous output on
  still scenes, ``out = a * prev_out + (1 - a) * in`` (recursive, a 0.3-0.8). A faint, slow light
  change passes almost untouched, the sensor noise is low-passed: its variance falls by
  (1 - a) / (1 + a) and consecutive frames' noise is correlated (lag-1 autocorrelation a).
- **Auto white balance hunting**: per-colour gains that move slowly and each its own way while
  the camera re-estimates the illuminant's colour.

Both work on linear float frames, before the tone curve and the 8-bit rounding.
"""

from __future__ import annotations

import numpy as np

AWB_HZ = (0.02, 0.15)  # how fast the gains wander: a hunt takes seconds, not frames


class RecursiveFilter:
    """``out = a * prev_out + (1 - a) * in`` frame after frame (float32; any frame shape)."""

    def __init__(self, a: float):
        if not 0.0 <= a < 1.0:
            raise ValueError(f"temporal noise reduction needs 0 <= a < 1 (got {a})")
        self.a = float(a)
        self._prev = None

    def __call__(self, frame: np.ndarray) -> np.ndarray:
        x = np.asarray(frame, np.float32)
        if self._prev is None or not self.a:
            self._prev = x.copy()
        else:
            self._prev = (np.float32(self.a) * self._prev + np.float32(1.0 - self.a) * x).astype(np.float32)
        return self._prev.copy()


def awb_gains(n: int, fps: float, amplitude: float, rng: np.random.Generator) -> np.ndarray:
    """(n, 3) per-colour gains near 1: each colour's own slow wander (two sines of AWB_HZ and a
    ramp), scaled so that its largest excursion from 1 is ``amplitude``; the colours differ."""
    gains = np.ones((n, 3))
    if amplitude <= 0 or n < 2:
        return gains
    t = np.arange(n) / float(fps)
    dur = max(t[-1], 1e-3)
    for c in range(3):
        wave = sum(np.sin(2 * np.pi * rng.uniform(*AWB_HZ) * t + rng.uniform(0, 2 * np.pi)) for _ in range(2))
        wave = wave + rng.uniform(-1, 1) * (t / dur - 0.5)
        wave = wave - wave.mean()
        gains[:, c] = 1.0 + amplitude * wave / max(float(np.abs(wave).max()), 1e-12)
    return gains
