"""Two people as a travelling shade and an in-place movement at once: per-clip features.

A walker's shade travels (a moving track); a person crouching, waving or jumping changes the wall in
place, periodically. One person draws one of the two; two people (the recordings' two-person rooms
are mostly a walker and a person in place) draw both. ``features(h, v, fps)`` gives, per clip:
the strongest moving track's darkness (W), and the in-place band-passed energy left once every
track's dip is masked (S, horizontal and vertical plots), in units of the noise.
"""
from __future__ import annotations

import numpy as np

from wallcli.signal.track import _width, darkness, track_rows, viterbi


def bandpass(x: np.ndarray, fps: float, lo: float = 0.4, hi: float = 4.0) -> np.ndarray:
    """(T, B) -> the same, keeping lo..hi Hz along time (FFT mask)."""
    X = np.fft.rfft(x - x.mean(0), axis=0)
    f = np.fft.rfftfreq(x.shape[0], 1.0 / fps)
    X[(f < lo) | (f > hi)] = 0
    return np.fft.irfft(X, n=x.shape[0], axis=0)


def inplace_energy(d: np.ndarray, fps: float, mask: np.ndarray | None = None) -> dict:
    bp = bandpass(d, fps)
    if mask is not None:
        bp = np.where(mask, np.nan, bp)
    e = np.sqrt(np.nanmean(bp ** 2, axis=0))  # per bin, rms of 0.4-4 Hz
    e = np.nan_to_num(e)
    # periodicity: the spectrum's peak over its median, summed over bins
    X = np.abs(np.fft.rfft(np.nan_to_num(bp), axis=0)) ** 2
    f = np.fft.rfftfreq(d.shape[0], 1.0 / fps)
    band = (f >= 0.4) & (f <= 4.0)
    prof = X[band].sum(1)
    return {"max": float(e.max()), "med": float(np.median(e)), "peak": float(np.log(prof.max() / (np.median(prof) + 1e-12) + 1e-12))}


def features(h: np.ndarray, v: np.ndarray, fps: float) -> dict:
    T = h.shape[0]
    t = np.arange(T) / fps
    tracks = track_rows(h, t, fps)
    moving = [k for k in tracks if k.as_dict()["moving"]]
    W = max((float(np.median(k.strength)) for k in moving), default=0.0)
    Wdur = max((k.duration for k in moving), default=0.0)
    d = darkness(h, fps)
    p = viterbi(np.clip(d, -6, None), 64 / fps * 1.0)
    mask = np.zeros_like(d, bool)
    for i in range(T):
        g = max(6, int(np.ceil(2.0 * _width(d[i], int(p[i])))))
        mask[i, max(0, p[i] - g):p[i] + g + 1] = True
    sh = inplace_energy(d, fps)
    shm = inplace_energy(d, fps, mask)
    sv = inplace_energy(darkness(v, fps), fps)
    return {"W": W, "Wdur": Wdur, "n_tracks": len(tracks), "n_moving": len(moving),
            "Sh": sh["max"], "Sh_med": sh["med"], "Sh_peak": sh["peak"],
            "Shm": shm["max"], "Shm_med": shm["med"], "Shm_peak": shm["peak"],
            "Sv": sv["max"], "Sv_med": sv["med"], "Sv_peak": sv["peak"]}
