"""Where on the wall is the signal? The SNR of every cell of a coarse grid over the frame, in the
same decode as :mod:`wallcli.snr.estimate`'s estimator (the seed's §3.2, per cell), for
``snr --heatmap`` and ``snr --roi auto`` (the best rectangle of cells)."""
from __future__ import annotations

import math

import numpy as np

from wallcli.errors import WallcliError
from wallcli.signal.blocks import Roi, rgb_grid
from wallcli.snr.estimate import MIN_FRAMES, footprint, powers_from_sums, snap_roi


def grid_shape(w: int, h: int, long_side: int, fy: int = 1, fx: int = 1) -> tuple[int, int, int, int]:
    """(rows, cols, cell_h, cell_w): about square cells of whole chroma samples, <= long_side per side."""
    cell = max(fy, fx, math.ceil(max(w, h) / long_side))
    ch, cw = -(-cell // fy) * fy, -(-cell // fx) * fx
    return max(1, h // ch), max(1, w // cw), min(ch, h), min(cw, w)


class GridAccumulator:
    """Signal and noise per cell of a grid over ``roi`` (exact cell means of every pixel), and,
    with ``covariance``, the temporal covariance of the cells' grey levels for ``--roi auto``."""

    def __init__(self, roi: Roi, long_side: int = 48, *, covariance: bool = False):
        self.roi_requested = roi
        self.long_side = long_side
        self.covariance = covariance
        self.frames = 0

    def update(self, planes) -> None:
        if self.frames == 0:
            fy, fx = footprint(planes)
            x, y, w, h = snap_roi(self.roi_requested, fy, fx)
            self.rows, self.cols, self.ch, self.cw = grid_shape(w, h, self.long_side, fy, fx)
            self.grid_roi = (x, y, self.cols * self.cw, self.rows * self.ch)
            # background image: the mean luma, on a stride that keeps it about 480 px wide
            self.bstep = max(1, self.grid_roi[2] // 480)
        g = rgb_grid(planes, self.grid_roi, self.rows, self.cols)
        gx, gy, gw, gh = self.grid_roi
        lum = planes.y[gy:gy + gh:self.bstep, gx:gx + gw:self.bstep]
        if self.frames == 0:
            self.first, self.prev = g, g
            self.s1 = np.zeros_like(g)
            self.s2 = np.zeros_like(g)
            self.sd = np.zeros_like(g)
            self.lum = np.zeros(lum.shape, np.float64)
            if self.covariance:
                k = self.rows * self.cols
                self.c1 = np.zeros(k)
                self.c2 = np.zeros((k, k))
                self.cd = np.zeros((k, k))
        c, d = g - self.first, g - self.prev
        self.prev = g
        self.s1 += c
        self.s2 += c * c
        self.sd += d * d
        self.lum += lum
        if self.covariance:
            gc, gd = c.mean(axis=2).ravel(), d.mean(axis=2).ravel()
            self.c1 += gc
            self.c2 += np.outer(gc, gc)
            self.cd += np.outer(gd, gd)
        self.frames += 1

    def _check(self) -> None:
        if self.frames < MIN_FRAMES:
            raise WallcliError(f"only {self.frames} frame(s) decoded; the noise estimate needs at least "
                               f"{MIN_FRAMES} (it compares consecutive frames, over time)")

    def maps(self) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """(signal, noise) per cell, each (rows, cols, 3) in code values^2, and the mean luma image."""
        self._check()
        dsum = self.prev - self.first
        sig, noi = powers_from_sums(self.s1, self.s2, self.sd, dsum, self.frames, 1.0, ())
        return sig, noi, self.lum / self.frames

    def best_roi(self, avoid: np.ndarray | None = None, min_cells: tuple[int, int] = (1, 1)) -> tuple[Roi, float]:
        """The rectangle of whole cells whose spatially averaged grey level has the highest SNR,
        among those with no cell marked in ``avoid`` ((rows, cols) bool: where the view check
        saw the view fail; a mover in view would otherwise be the 'signal' chosen), at least
        ``min_cells`` (rows, cols) of cells in size. Raises ValueError when every rectangle holds a
        marked cell.

        Var of a rectangle's mean = (sum of the cells' covariances over the rectangle) / n^2, for
        signal and for frame differences alike; 4-D prefix sums give every rectangle at once.
        """
        self._check()
        t = float(self.frames)
        dsum = (self.prev - self.first).mean(axis=2).ravel()
        cov = (self.c2 - np.outer(self.c1, self.c1) / t) / (t - 1.0)
        covd = (self.cd - np.outer(dsum, dsum) / (t - 1.0)) / (t - 2.0)
        r, c = self.rows, self.cols
        y0, y1, x0, x1 = (a.ravel() for a in np.meshgrid(np.arange(r + 1), np.arange(r + 1),
                                                        np.arange(c + 1), np.arange(c + 1), indexing="ij"))
        min_r, min_c = min(int(min_cells[0]), r), min(int(min_cells[1]), c)
        keep = (y1 - y0 >= max(min_r, 1)) & (x1 - x0 >= max(min_c, 1))
        y0, y1, x0, x1 = y0[keep], y1[keep], x0[keep], x1[keep]
        if avoid is not None and avoid.any():
            p = np.zeros((r + 1, c + 1))
            p[1:, 1:] = np.cumsum(np.cumsum(avoid, axis=0), axis=1)
            clean = (p[y1, x1] - p[y0, x1] - p[y1, x0] + p[y0, x0]) == 0
            if not clean.any():
                raise ValueError("every cell was marked")
            y0, y1, x0, x1 = y0[clean], y1[clean], x0[clean], x1[clean]
        n = ((y1 - y0) * (x1 - x0)).astype(np.float64)
        total = _rect_quad(cov, r, c, y0, y1, x0, x1) / n**2
        noise = 0.5 * _rect_quad(covd, r, c, y0, y1, x0, x1) / n**2
        with np.errstate(divide="ignore", invalid="ignore"):
            snr = np.where(noise > 0, (total - noise) / noise, -np.inf)
        i = int(np.argmax(snr))
        gx, gy = self.grid_roi[0], self.grid_roi[1]
        roi = (gx + int(x0[i]) * self.cw, gy + int(y0[i]) * self.ch,
               int(x1[i] - x0[i]) * self.cw, int(y1[i] - y0[i]) * self.ch)
        return roi, float(snr[i])


def _rect_quad(m: np.ndarray, r: int, c: int, y0, y1, x0, x1) -> np.ndarray:
    """For each rectangle: the sum of m[i, j] over cells i and j both inside it."""
    p = np.zeros((r + 1, c + 1, r + 1, c + 1))
    p[1:, 1:, 1:, 1:] = m.reshape(r, c, r, c).cumsum(0).cumsum(1).cumsum(2).cumsum(3)
    out = np.zeros(y0.shape, np.float64)
    for a, sa in ((y1, 1), (y0, -1)):
        for b, sb in ((x1, 1), (x0, -1)):
            for e, se in ((y1, 1), (y0, -1)):
                for f, sf in ((x1, 1), (x0, -1)):
                    out += (sa * sb * se * sf) * p[a, b, e, f]
    return out
