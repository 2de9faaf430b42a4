"""A candidate temporal-noise-reduction detector, measured and NOT shipped (README_tnr_awb.md):
on the transfer set's clean clips it reads correlation as strong as a real blend (codec-held
blocks in the lossy ones, the renderer's own slowly varying noise and shadow edges in the
lossless ones), so correcting on it would move clean clips' signal_db by 5-30 dB.

    PYTHONPATH=. python research/pipelines/noise_lags.py CLIP...   # the fit per clip

The idea, as first written for wallcli/signal/:

Phones and DVRs blend each frame with the previous output on still scenes (``out = a prev +
(1 - a) in``). The slow light a person casts passes almost untouched; the sensor noise comes out
correlated from frame to frame. Every noise figure here is half the mean square of consecutive
differences (paper suppl. §3.2), which is the noise's variance only when frames' noise is
independent: with lag-1 autocorrelation r it is (1 - r) of it, and the noise a slow signal is
measured against (its power at low frequencies, (1 + a) / (1 - a) times the variance for the
recursive filter) is larger still, so ``signal_db`` read 4-10 dB too high.

The noise's own correlation is measured where no signal is: on the differences between luma
pixels two columns apart (a wall's light, a shadow, exposure and white balance change both
alike; each pixel's noise is its own), in tiles spread over the frame. What the camera's shake
or a gain change leaves there (the wall's texture moving, or scaled) is regressed out of every
frame difference (the tiles' mean texture, and its two gradients). Then, over lags k = 1..LAGS,

    d_k = 1/2 mean (z_t - z_{t-k})^2 = W + A (1 - a^k) + c k^2

(W: white noise such as the 8-bit rounding, A: the recursively filtered noise, c: what slow
change is left) is fitted, a on a grid, the rest by least squares, all >= 0. The noise figure of
a plot, half its mean square difference (``d_1`` in these units), then stands for
``W + A (1 - a)``; the variance is ``W + A`` and the low-frequency noise ``W + A (1 + a) / (1 - a)``:
:meth:`TemporalNoise.correction` hands out both ratios, and ``window_signal_db`` uses them.

Where the blending is too strong to undo (a >= A_MAX), the figure is only an upper bound:
the correction says so (``bound``) and the answers are not decided on it.
"""

from __future__ import annotations

from collections import deque
from itertools import combinations

import numpy as np

LAGS = 8  # frame differences of lags 1..LAGS
TILE = 32  # tiles of TILE x TILE luma pixels
MAX_TILES = 24
MIN_FRAMES = 32  # frames measured before anything is said
MIN_LAG1 = 0.12  # the noise's lag-1 autocorrelation from which it would be corrected
A_MAX = 0.9  # blending stronger than this: the figure is an upper bound, not corrected
GRID = np.round(np.arange(0.0, 0.96, 0.01), 2)


def _tiles(h: int, w: int) -> list[tuple[int, int]]:
    from wallcli.camera.tnr import _tiles as tiles

    return tiles(h, w, TILE, MAX_TILES)


class TemporalNoise:
    """A frame tap (``FrameTee``) that measures how correlated the noise is from frame to frame.

    Memory: LAGS + 2 sampled tile stacks, whatever the length. Frames after a gap in the
    timestamps start a new run (a difference across the gap is not one frame's).
    """

    def __init__(self) -> None:
        self._corners = None
        self._hist: deque = deque(maxlen=LAGS)
        self._sum = np.zeros(LAGS)
        self._n = np.zeros(LAGS)
        self._mean = None
        self._frames = 0
        self.frames = 0  # frames measured

    def __call__(self, frame) -> None:
        y = frame.planes.y
        if self._corners is None:
            self._corners = _tiles(*y.shape)
            self._shape = y.shape
        if not self._corners or y.shape != self._shape:
            return
        if getattr(frame, "gap", 0.0):
            self._hist.clear()
        z = np.stack([y[r:r + TILE, c:c + TILE + 2] for r, c in self._corners]).astype(np.float32)
        z = z[:, :, 2:] - z[:, :, :-2]
        self._frames += 1
        self._mean = z.copy() if self._mean is None else self._mean + (z - self._mean) / np.float32(self._frames)
        if self._hist:
            maps = self._maps()
            for k, old in enumerate(reversed(self._hist)):
                self._sum[k] += self._residual(z - old, maps)
                self._n[k] += z.size
        self._hist.append(z)
        self.frames += 1

    def _maps(self) -> np.ndarray:
        """(3, pixels): the tiles' mean texture and its gradients, what a gain or a shift makes of it."""
        m = self._mean
        return np.stack([m.ravel(), np.gradient(m, axis=2).ravel(), np.gradient(m, axis=1).ravel()]).astype(np.float64)

    @staticmethod
    def _residual(diff: np.ndarray, maps: np.ndarray) -> float:
        d = diff.ravel().astype(np.float64)
        gram = maps @ maps.T
        b = maps @ d
        try:
            coef = np.linalg.solve(gram + 1e-9 * np.trace(gram) * np.eye(3), b)
        except np.linalg.LinAlgError:
            return float(d @ d)
        return float(max(d @ d - b @ coef, 0.0))

    def fit(self) -> dict | None:
        """{'a', 'white', 'ar', 'slow', 'lag1'} (variances in squared codes of the tiles'
        differences), None before MIN_FRAMES."""
        if self.frames < MIN_FRAMES or not np.all(self._n > 0):
            return None
        d = 0.5 * self._sum / self._n
        return fit_lags(d)

    def correction(self) -> dict | None:
        """The ``corrections`` entry (docs/contract.md) with the noise ratios, None when the
        noise is independent from frame to frame (or too few frames were seen)."""
        f = self.fit()
        if f is None or f["lag1"] < MIN_LAG1:
            return None
        w, ar, a = f["white"], f["ar"], f["a"]
        measured = w + ar * (1 - a)  # what half the mean square difference reads
        bound = a >= A_MAX
        out = {"kind": "temporal_nr", "lag1": round(f["lag1"], 3), "blend": round(a, 2),
               "variance_ratio": round((w + ar) / measured, 3),
               "noise_ratio": round((w + ar * (1 + a) / (1 - a)) / measured, 3)}
        if bound:
            out["bound"] = True  # too strong to undo: signal_db an upper bound
        return out


def fit_lags(d: np.ndarray) -> dict | None:
    """The model ``d_k = W + A (1 - a^k) + c k^2`` fitted to half mean square differences
    ``d`` (lags 1..len(d)): a on GRID, (W, A, c) >= 0 by least squares."""
    d = np.asarray(d, np.float64)
    if not np.all(np.isfinite(d)) or d[0] <= 0:
        return None
    k = np.arange(1, d.size + 1, dtype=np.float64)
    best = None
    for a in GRID:
        cols = np.stack([np.ones_like(k), 1 - a ** k, k * k], axis=1)
        for use in _subsets(0.0 < a):
            x, *_ = np.linalg.lstsq(cols[:, use], d, rcond=None)
            if np.any(x < 0):
                continue
            err = float(np.sum((cols[:, use] @ x - d) ** 2))
            if best is None or err < best[0] - 1e-12 * float(d @ d):
                coef = np.zeros(3)
                coef[list(use)] = x
                best = (err, float(a), coef)
    if best is None:
        return None
    _, a, (w, ar, c) = best
    if ar <= 0:
        a = 0.0
    var = w + ar
    return {"a": a, "white": float(w), "ar": float(ar), "slow": float(c),
            "lag1": float(ar * a / var) if var > 0 else 0.0}


def _subsets(ar: bool) -> list[tuple[int, ...]]:
    idx = (0, 1, 2) if ar else (0, 2)
    return [s for n in range(1, len(idx) + 1) for s in combinations(idx, n)]


if __name__ == "__main__":
    import sys

    from wallcli.io.video import open_video

    for path in sys.argv[1:]:
        tap = TemporalNoise()
        with open_video(path) as reader:
            for frame in reader.frames():
                tap(frame)
        print(path, tap.fit(), tap.correction())
