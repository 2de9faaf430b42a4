"""Hand-made physical features of a space-time window, for a classifier that is not a CNN.

Why: CNNs trained on wallcli's simulator read the *form* of its plots (a narrow streak, a faint
local blob) and that form differs in the independent renderer (wall-wide bands with two sharp
edges, waving that flickers the whole wall). Summary statistics that describe the physics rather
than the picture might carry over better: how far above the noise, how many independent
sources (rank), how much is a change of the whole wall, how localised, which temporal rates,
whether the pattern travels along the wall (walking) or stays in place (crouching, waving,
jumping), horizontal against vertical plot.

Input: windows as the nets get them before normalisation, (n, bins, 256, 3) per plot at 30 fps.
"""
from __future__ import annotations

import numpy as np

FPS = 30.0
BANDS = [(0.1, 0.5), (0.5, 1.0), (1.0, 2.0), (2.0, 4.0), (4.0, 8.0), (8.0, 15.0)]


def _plot_features(w: np.ndarray) -> np.ndarray:
    """(n, bins, T, 3) -> (n, k) features of one plot."""
    x = w.astype(np.float64).sum(-1)  # colours summed: luminance-like, best SNR
    x = x - x.mean(axis=2, keepdims=True)
    n, b, t = x.shape
    d = np.diff(x, axis=2)
    sigma = np.sqrt(0.5 * np.mean(d * d, axis=(1, 2))) + 1e-12
    z = x / sigma[:, None, None]
    total = np.mean(z * z, axis=(1, 2)) + 1e-12
    feats = [np.log10(total)]
    # rank: singular values against the white-noise edge (sqrt(b) + sqrt(t))
    s = np.linalg.svd(z, compute_uv=False)
    edge = np.sqrt(b) + np.sqrt(t)
    e2 = s ** 2
    feats += [np.log10(s[:, 0] / edge), np.log10(s[:, 1] / edge), np.log10(s[:, 2] / edge),
              e2[:, 0] / e2.sum(1), (e2[:, 0] + e2[:, 1]) / e2.sum(1),
              np.minimum((s > 1.3 * edge).sum(1), 8).astype(np.float64)]
    # whole-wall change: the spatial mean's share of the energy
    g = z.mean(axis=1)  # (n, t)
    feats.append(b * np.mean(g * g, axis=1) / (b * total))
    # localisation of the top spatial mode (participation ratio / bins) and of the energy profile
    u, sv, vt = np.linalg.svd(z, full_matrices=False)
    u1 = u[:, :, 0]
    feats.append(1.0 / (np.sum(u1 ** 4, axis=1) + 1e-12) / b)
    prof = np.mean(z * z, axis=2)
    prof = prof / prof.sum(1, keepdims=True)
    feats.append(1.0 / (np.sum(prof ** 2, axis=1) + 1e-12) / b)
    # temporal rates of the top mode, as fractions of its power, and how sharp its peak is
    c1 = vt[:, 0, :] * sv[:, 0:1]
    spec = np.abs(np.fft.rfft(c1 * np.hanning(t), axis=1)) ** 2
    f = np.fft.rfftfreq(t, 1.0 / FPS)
    tot = spec[:, f >= 0.1].sum(1) + 1e-12
    for lo, hi in BANDS:
        feats.append(spec[:, (f >= lo) & (f < hi)].sum(1) / tot)
    m = (f >= 0.4) & (f <= 6.0)
    feats.append(np.log10(spec[:, m].max(1) / (np.median(spec[:, m], axis=1) + 1e-12) + 1e-12))
    # travelling vs standing: 2-D spectrum's asymmetry between +k and -k at the same frequency
    F = np.abs(np.fft.fft2(z, axes=(1, 2))) ** 2
    kb = np.fft.fftfreq(b)
    ft = np.fft.fftfreq(t)
    pos = (kb[:, None] * ft[None, :]) > 0
    neg = (kb[:, None] * ft[None, :]) < 0
    ep, en = F[:, pos].sum(1), F[:, neg].sum(1)
    feats.append(np.abs(ep - en) / (ep + en + 1e-12))
    # edges: share of the energy in fast temporal changes (sharp shadow edges, held codec noise)
    z2 = z.copy()
    feats.append(np.log10(np.mean(np.diff(z2, axis=2) ** 2, axis=(1, 2)) / 2.0 + 1e-12))
    return np.stack(feats, axis=1)


def features(h: np.ndarray, v: np.ndarray) -> np.ndarray:
    """(n, bins, 256, 3) horizontal and vertical windows -> (n, k) float32 features."""
    fh, fv = _plot_features(h), _plot_features(v)
    ratio = (fv[:, 0] - fh[:, 0])[:, None]  # log energy of vertical over horizontal
    return np.concatenate([fh, fv, ratio], axis=1).astype(np.float32)


NAMES = None  # filled lazily by names()


def names() -> list[str]:
    per = ["log_energy", "sv1", "sv2", "sv3", "share1", "share12", "n_above", "whole_wall", "u1_extent",
           "energy_extent"] + [f"band_{lo}_{hi}" for lo, hi in BANDS] + ["peak_sharp", "travel", "diff_energy"]
    return [f"h_{p}" for p in per] + [f"v_{p}" for p in per] + ["v_over_h"]
