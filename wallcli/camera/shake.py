"""Camera shake taken out of a stretch of profiles by regression on the measured shifts.

A camera that moves by (dx, dy) changes each profile bin by what the picture's structure at the
bin's edges makes of that motion: a door frame's edge inside a bin moves its mean by the frame's
contrast times dx, and a skirting board entering the ROI's bottom moves every column mean with
dy. Re-binning each frame at the moved edges (``blocks._FusedProjection._shifted``) undoes the
first-order part only: a linear read of the running sum within a pixel, and the codec's
re-encoding of a moving picture, leave a residue the networks read as a person (research/shake).
Here each bin's change is instead *fitted* over the stretch as a smooth function of the shift,
``b1 dx + b2 dy + b3 dx^2 + b4 dy^2 + b5 dx dy``, and removed, whatever the mechanism: the fit
learns every bin's own response from the stretch itself. A person's light is not a function of
the camera's position, but a slow one (a walk across the room, a few cycles a window) has few
independent samples, and a fit on the levels took up to a third of it by chance (tests/
test_shake.py). So each bin's response is fitted on *frame-to-frame changes*, where a shake's
jitter is large and a person's slow light is small, and then removed from the levels: on the
test's wall the residue fell from 0.12 to 0.035 codes (the noise's own 0.03), the person's plot
kept at a correlation of 0.995 instead of 0.94.

Applied only where the shifts moved by at least ``MIN_PX`` and explain the profiles beyond
chance (an F statistic of ``MIN_F``): a still camera's shifts are noise, and fitting them would
only remove a little of the person's signal.
"""
from __future__ import annotations

from typing import Any

import numpy as np

MIN_PX = 0.05  # rms shift (luma pixels) below which nothing is fitted
MIN_F = 4.0  # pooled F statistic of the five shift terms over the series, against 1 by chance
TERMS = 5


def design(shifts: np.ndarray) -> np.ndarray:
    """(T, 5) centred regressors dx, dy, dx^2, dy^2, dx dy of (T, 2) shifts."""
    s = np.asarray(shifts, np.float64)
    s = s - s.mean(axis=0)
    dx, dy = s[:, 0], s[:, 1]
    x = np.stack([dx, dy, dx * dx, dy * dy, dx * dy], axis=1)
    return x - x.mean(axis=0)


def unshake(series: np.ndarray, shifts: np.ndarray) -> tuple[np.ndarray, dict[str, Any] | None]:
    """(series with the shake's part removed, the ``corrections`` finding or None).

    ``series``: (T, K) raw levels of the same frames (profile bins and colours); ``shifts``: (T, 2)
    each sample's measured (dx, dy) in luma pixels, from any fixed reference."""
    y = np.asarray(series, np.float64)
    s = np.asarray(shifts, np.float64)
    t = y.shape[0]
    if t <= 4 * TERMS or s.shape != (t, 2):
        return y, None
    c = s - s.mean(axis=0)
    rms = float(np.sqrt(np.mean(np.sum(c * c, axis=1))))
    if rms < MIN_PX:
        return y, None
    x = design(s)
    dx, dy = np.diff(x, axis=0), np.diff(y, axis=0)
    beta, *_ = np.linalg.lstsq(dx, dy, rcond=1e-10)
    dfit = dx @ beta
    ss_fit = float(np.sum(dfit * dfit))
    ss_res = float(np.sum((dy - dfit) ** 2))
    f = (ss_fit / TERMS) / max(ss_res / max(t - 1 - TERMS, 1), 1e-30)
    if f < MIN_F:
        return y, None
    fit = x @ beta
    yc = y - y.mean(axis=0)
    return y - fit, {"kind": "shake", "rms_px": round(rms, 3),
                     "max_px": round(float(np.sqrt(np.max(np.sum(c * c, axis=1)))), 3),
                     "explained": round(float(np.sum(fit * fit)) / max(float(np.sum(yc * yc)), 1e-30), 4)}


def regressors(dx: float, dy: float) -> np.ndarray:
    """The five terms of one sample's shift, uncentred (design() centres a stretch of them)."""
    return np.array([dx, dy, dx * dx, dy * dy, dx * dy], np.float64)


class ShakeSums:
    """The SNR estimator's per-pixel sums corrected for the same regression, after the fact.

    The estimator keeps, per pixel, sums over time of its centred value c, c^2 and its frame
    difference d^2 (snr.py), never the series. The shake's fit needs only more sums: per pixel
    sum(X c) and sum(dX d) (five each, with X the shift's terms), and the frame's sum(X), sum(dX),
    sum(X X^T), sum(dX dX^T). With b = sum(dX dX^T)^-1 sum(dX d), fitted on the changes as
    :func:`unshake` fits them, the series c - X b has sums that follow from these exactly:
    sum(c') = sum(c) - b.sum(X), sum(c'^2) = sum(c^2) - 2 b.sum(X c) + b^T sum(X X^T) b, and
    alike for d. All are linear in the pixels, so block sizes come from the same pyramid.

    The SNR estimator feeds it blocks of 2x2 pixels (a quarter of the values), and each frame
    adds ten scaled copies of them: a BLAS product over buffered chunks was no faster per value
    and its threads spun on the other core.
    """

    def __init__(self, shape: tuple[int, ...]):
        self.shape = tuple(shape)
        n = int(np.prod(self.shape))
        self.xc = np.zeros((TERMS, n))
        self.dxd = np.zeros((TERMS, n))
        self.sx = np.zeros(TERMS)
        self.sdx = np.zeros(TERMS)
        self.xx = np.zeros((TERMS, TERMS))
        self.dxdx = np.zeros((TERMS, TERMS))
        self._prev = None
        self.frames = 0

    def first(self, dx: float, dy: float) -> None:
        """The first frame: its value is the origin (c = 0), its shift counts in the frame sums."""
        x = regressors(dx, dy)
        self.sx += x
        self.xx += np.outer(x, x)
        self._prev = x
        self.frames = 1

    def add(self, c: np.ndarray, d: np.ndarray, dx: float, dy: float) -> None:
        x = regressors(dx, dy)
        step = x - self._prev
        self._prev = x
        # float64 products: a float32 one rounds a faint signal's share of the sums
        c, d = c.reshape(-1).astype(np.float64), d.reshape(-1).astype(np.float64)
        for j in range(TERMS):
            self.xc[j] += x[j] * c
            self.dxd[j] += step[j] * d
        self.sx += x
        self.sdx += step
        self.xx += np.outer(x, x)
        self.dxdx += np.outer(step, step)
        self.frames += 1

    def finding(self, sd: np.ndarray, dsum: np.ndarray, dxd: np.ndarray) -> dict[str, Any] | None:
        """The shake found, judged as :func:`unshake` does, on blocks' changes (``sd``, ``dsum``:
        their sums of squared differences and of differences; ``dxd``: their (5, ...) sums of
        dX d), or None: then leave the sums."""
        t = self.frames
        if t <= 4 * TERMS:
            return None
        mean = self.sx[:2] / t
        var = self.xx[0, 0] / t - mean[0] ** 2 + self.xx[1, 1] / t - mean[1] ** 2
        rms = float(np.sqrt(max(var, 0.0)))
        if rms < MIN_PX:
            return None
        a = dxd.reshape(TERMS, -1)
        beta = np.linalg.lstsq(self.dxdx, a, rcond=1e-10)[0]
        ss_fit = float(np.sum(beta * a))
        ss_tot = float(np.sum(sd))  # the changes' own, uncentred as the fit on them is
        f = (ss_fit / TERMS) / max((ss_tot - ss_fit) / max(t - 1 - TERMS, 1), 1e-30)
        if f < MIN_F:
            return None
        return {"kind": "shake", "rms_px": round(rms, 3), "explained": round(ss_fit / max(ss_tot, 1e-30), 4)}

    def corrected(self, s1, s2, sd, dsum, xc, dxd):
        """(s1, s2, sd, dsum) of one block size with the shake's fit removed; ``xc``, ``dxd``: that
        size's (5, ...) block sums of sum(X c) and sum(dX d)."""
        shape = s1.shape
        xc, dxd = xc.reshape(TERMS, -1), dxd.reshape(TERMS, -1)
        ds = dsum.reshape(-1).astype(np.float64)
        beta = np.linalg.lstsq(self.dxdx, dxd, rcond=1e-10)[0]
        s1c = s1.reshape(-1) - self.sx @ beta
        s2c = s2.reshape(-1) - 2 * np.sum(beta * xc, axis=0) + np.sum(beta * (self.xx @ beta), axis=0)
        sdc = sd.reshape(-1) - 2 * np.sum(beta * dxd, axis=0) + np.sum(beta * (self.dxdx @ beta), axis=0)
        dsc = ds - self.sdx @ beta
        return s1c.reshape(shape), s2c.reshape(shape), sdc.reshape(shape), dsc.reshape(shape)
