"""Physical features of a window's two space-time plots: how strong, how spread, how periodic.

Nineteen numbers per window, each a property of the light the people change, not of a room:
per plot, the power over the frame-to-frame noise (``window_power_db``), the whole-wall share
(what every position shares), the first two singular values' shares (how many independent
patterns), the whole-wall signal's spectral peak (its share and its frequency) and the
frame-to-frame change; then, of the vertical plot, the share of its energy in the upper half, the
horizontal against vertical energy, the first temporal pattern's dominant frequency and its peak
share, and the spatial extent of the energy along the wall's height.

A raised arm changes the light where the body does not; a jump moves the whole body and its
shadow: the vertical plot's spread and rhythm are where waving and jumping part
(``wallcli.infer.split``).
"""
from __future__ import annotations

import numpy as np

from wallcli.signal.window import window_power_db

NAMES = ["h_db", "h_wall_share", "h_rank1", "h_rank2", "h_peak_share", "h_peak_hz", "h_log_change",
         "v_db", "v_wall_share", "v_rank1", "v_rank2", "v_peak_share", "v_peak_hz", "v_log_change",
         "v_top_share", "log_h_over_v", "v_pattern_hz", "v_pattern_peak", "v_extent"]
FPS = 30.0


def _centred(w: np.ndarray) -> np.ndarray:
    w = np.asarray(w, np.float64)
    # the colours together (n, bins, T), summed as numpy's mean over the last axis sums them: the
    # same values, ten times faster
    x = (w[..., 0] + w[..., 1] + w[..., 2]) / 3.0 if w.shape[-1] == 3 else w.mean(-1)
    return x - x.mean(2, keepdims=True)


def _plot(w: np.ndarray, off: np.ndarray, x: np.ndarray) -> np.ndarray:
    """Seven of a plot's features; ``x``: its :func:`_centred` form."""
    db = window_power_db([(w, off)])
    tot = (x ** 2).mean((1, 2)) + 1e-20
    g = x.mean(1)
    share = (g ** 2).mean(1) / tot
    e = _energies(x)
    spec = np.abs(np.fft.rfft(g - g.mean(1, keepdims=True), axis=1)) ** 2
    spec[:, 0] = 0
    peak = spec.max(1) / (spec.sum(1) + 1e-20)
    freq = spec.argmax(1) * FPS / x.shape[2]
    change = (np.diff(x, axis=2) ** 2).mean((1, 2)) / tot
    return np.stack([db, share, e[:, 0], e[:, 1], peak, freq, np.log(change + 1e-9)], 1)


def _energies(x: np.ndarray) -> np.ndarray:
    """Each (bins, T) plot's singular values squared, largest first, as shares of their sum: the
    eigenvalues of its bins x bins Gram matrix (an SVD of the plot cost 3 times the CPU, half of it
    in OpenBLAS's helper threads, and was activity's largest cost on a 1080p clip)."""
    s2 = np.maximum(np.linalg.eigvalsh(x @ np.swapaxes(x, 1, 2))[:, ::-1], 0.0)
    return s2 / np.maximum(s2.sum(1, keepdims=True), 1e-30)


def _top_patterns(x: np.ndarray) -> np.ndarray:
    """Each (bins, T) plot's first right singular vector, up to sign and scale (what its spectrum's
    peak and peak share read are blind to): the Gram matrix's top eigenvector u gives u @ x. Where
    the top two singular values are not well apart (or all zero) the vector is ill defined and the
    SVD's own choice is kept, as before."""
    vals, vecs = np.linalg.eigh(x @ np.swapaxes(x, 1, 2))
    out = np.einsum("nb,nbt->nt", vecs[:, :, -1], x)
    for i in np.flatnonzero(~(vals[:, -1] - vals[:, -2] > 1e-6 * np.abs(vals[:, -1]))):
        out[i] = np.linalg.svd(x[i], full_matrices=False)[2][0]
    return out


def _vertical(xh: np.ndarray, xv: np.ndarray) -> np.ndarray:
    """The five features of both plots together, of their :func:`_centred` forms."""
    pv = (xv ** 2).mean(2)
    half = xv.shape[1] // 2
    top = pv[:, :half].sum(1) / (pv.sum(1) + 1e-20)
    hv = np.log((xh ** 2).mean((1, 2)) / ((xv ** 2).mean((1, 2)) + 1e-20) + 1e-20)
    fr, pk = [], []
    for w in _top_patterns(xv):
        sp = np.abs(np.fft.rfft(w)) ** 2
        sp[0] = 0
        fr.append(sp.argmax() * FPS / xv.shape[2])
        pk.append(sp.max() / max(sp.sum(), 1e-30))
    ext = (pv > 0.5 * pv.max(1, keepdims=True)).mean(1)
    return np.stack([top, hv, np.array(fr), np.array(pk), ext], 1)


def window_features(horizontal: np.ndarray, vertical: np.ndarray, h_offset: np.ndarray,
                    v_offset: np.ndarray) -> np.ndarray:
    """(n, len(NAMES)) float64 features of n windows (n, bins, window, 3) per plot, with the
    levels (..., bins, 3) they are relative to."""
    xh, xv = _centred(horizontal), _centred(vertical)
    return np.concatenate([_plot(horizontal, h_offset, xh), _plot(vertical, v_offset, xv), _vertical(xh, xv)], 1)
