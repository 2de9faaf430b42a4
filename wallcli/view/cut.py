"""Did the shot change? The view check's cut watch: block means of the luma sampled CUT_RATE
times a second, compared one sample to the next beyond a whole-frame gain, and on a coarse grid
of cells for cuts between alike walls (see CUT_CELLS)."""
from __future__ import annotations

import statistics
from collections import deque

import numpy as np

from wallcli.view.image import _block_side, _robust_sigma, _sampled_luma, _upper_median, _whole_block_bounds
from wallcli.view.limits import (
    CLIP_HI, CUT_CALM, CUT_CELLS, CUT_FRACTION, CUT_RATE, CUT_REACH, CUT_SIDE, CUT_SPIKE, DARK, HISTORY, K_CUT,
    MIN_USABLE, REL_CUT, SIGMA_FLOOR,
)


_SQRT2 = np.sqrt(2.0)  # numpy's float64: the threshold below is float64, as it always was


class CutWatch:
    """The cut watch's state: the last sample's blocks and time, the noise of the steps, the
    changed shares and coarse steps of the last few. Memory independent of the clip's length."""

    def __init__(self) -> None:
        self.t = None  # of the last sample
        self._prev = None
        self._fracs = (1.0, 1.0)  # changed shares of the last two frames (none calm before the first)
        self._sig: deque = deque(maxlen=HISTORY)
        self._grid = None  # (sample shape, rows and columns whole blocks tile, block grid size)
        # the coarse gain-free steps (time of the later sample, RMS): the clip's, and the last few
        self._steps: deque = deque(maxlen=HISTORY + CUT_REACH + 1)

    def due(self, t: float) -> bool:
        """Whether the frame at ``t`` is the watch's next sample (CUT_RATE a second)."""
        return self.t is None or t - self.t >= 1.0 / CUT_RATE - 1e-3

    def __call__(self, t: float, planes, roi) -> tuple[float | None, bool]:
        """The time of the previous sample if it was a cut: much of the frame changed from the
        sample before it, beyond a whole-frame gain (exposure, flicker), with calm samples on
        either side (a hard shadow sweeping the wall changes as much, but over several frames).
        Judged on CUT_RATE frames a second, one sample late, on block means of the luma sampled
        at most CUT_SIDE pixels wide (a cut changes whole blocks: a gather of pixels, not a resize,
        is enough to see it). And whether this sample changed much of the frame (CUT_CALM or more):
        anything suspect, that every frame be checked for a while."""
        import cv2

        y = _sampled_luma(planes, roi, CUT_SIDE)
        if self._grid is None or self._grid[0] != y.shape:  # the block grid, kept while the size is
            rows, cols = _whole_block_bounds(y.shape)
            side = _block_side((rows.stop - rows.start, cols.stop - cols.start))
            self._grid = (y.shape, rows, cols, ((cols.stop - cols.start) // side, (rows.stop - rows.start) // side))
        _, rows, cols, size = self._grid
        blocks = cv2.resize(y[rows, cols], size, interpolation=cv2.INTER_AREA)
        prev, t_prev = self._prev, self.t
        self._prev, self.t = blocks, t
        if prev is None or prev.shape != blocks.shape:
            return None, False
        # every step on a few hundred blocks: each numpy call's overhead, not its work, is the cost
        ok = (np.minimum(blocks, prev) >= DARK) & (np.maximum(blocks, prev) < CLIP_HI)
        b, p = blocks[ok], prev[ok]
        if b.size == 0:
            return None, False
        self._sig.append(_robust_sigma(b - p))
        sigma = max(statistics.median(self._sig), SIGMA_FLOOR)
        gain = _upper_median(b / p)  # p >= DARK > 0
        threshold = np.maximum(b * REL_CUT, K_CUT * sigma * _SQRT2)
        frac = np.count_nonzero(np.abs(b - gain * p) > threshold) / b.size
        before = self._fracs
        self._fracs = (before[1], frac)
        spike = self._coarse_spike(t, blocks, prev, ok, gain)
        if before[1] > CUT_FRACTION and before[0] < CUT_CALM and frac < CUT_CALM:
            return t_prev, frac >= CUT_CALM
        return spike, frac >= CUT_CALM

    def _coarse_spike(self, t, blocks, prev, ok, gain) -> float | None:
        """The time of the step CUT_REACH samples back if it was a cut by its coarse pattern (see
        CUT_CELLS): a step far above the clip's usual and its neighbours', and above REL_CUT / 2."""
        import cv2

        k = max(1, max(blocks.shape) // CUT_CELLS)
        hh, ww = blocks.shape[0] // k * k, blocks.shape[1] // k * k
        step = np.nan
        if hh and ww and np.count_nonzero(ok) / ok.size >= MIN_USABLE:
            r = np.where(ok, (blocks - gain * prev) / np.maximum(prev, DARK), np.float32(0.0))
            size = (ww // k, hh // k)
            cells = cv2.resize(r[:hh, :ww], size, interpolation=cv2.INTER_AREA)
            share = cv2.resize(ok[:hh, :ww].astype(np.float32), size, interpolation=cv2.INTER_AREA)
            m = share > 0.5  # cells mostly usable: their mean is the usable blocks' mean
            if m.any():
                x = cells[m] / share[m]
                # np.mean's float32 sum and division, without its Python wrapper (on every sample)
                step = float(np.sqrt(np.add.reduce(x * x) / x.size))
        steps = self._steps
        steps.append((t, step))
        n = 2 * CUT_REACH + 1
        if len(steps) < n + 3:  # a median of at least 3 earlier steps
            return None
        t_mid, mid = steps[-CUT_REACH - 1]
        if not mid > REL_CUT / 2:  # nan (too little usable) too
            return None
        recent = [s for _, s in list(steps)[-n:]]
        others = [s for i, s in enumerate(recent) if i != CUT_REACH and s == s]
        earlier = [s for _, s in list(steps)[:-n + CUT_REACH] if s == s]
        if len(earlier) < 3 or (others and mid <= CUT_SPIKE * max(others)):
            return None
        return t_mid if mid > CUT_SPIKE * statistics.median(earlier) else None
