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
