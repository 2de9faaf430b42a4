"""Probe: is a plot's slow change spatially coherent (a person's light on the wall moves many bins
together) or spatially white (a codec's held residue, bin by bin)? The power at 0.1-2.5 Hz in each
spatial DCT component across the bins: coarse (1..7) against fine (16..) components, per component.

    python research/noise/coherence_probe.py CLIP...
"""
from __future__ import annotations

import contextlib
import io
import sys

import numpy as np

LOW = (0.1, 2.5)


def dct_basis(n: int) -> np.ndarray:
    k = np.arange(n)[:, None]
    x = np.arange(n)[None]
    b = np.cos(np.pi * (x + 0.5) * k / n)
    return b / np.linalg.norm(b, axis=1, keepdims=True)


def coherence(ys, fps: float = 30.0) -> tuple[np.ndarray, np.ndarray]:
    """Per window: (coarse / fine slow power per component, fine slow / fine fast power)."""
    co = fi = fh = 0.0
    for y in ys:  # (n, bins, T, 3)
        n_b, T = y.shape[-3], y.shape[-2]
        z = np.einsum("kb,nbtc->nktc", dct_basis(n_b), y)
        w = np.hanning(T)
        P = np.abs(np.fft.rfft(z * w[:, None], axis=-2)) ** 2 / np.sum(w * w)  # (n, k, F, 3)
        f = np.fft.rfftfreq(T, 1 / fps)
        lo = (f >= LOW[0]) & (f <= LOW[1])
        hi = f >= 6.0
        co = co + P[:, 1:8][:, :, lo].mean(axis=(1, 2, 3))
        fi = fi + P[:, 16:][:, :, lo].mean(axis=(1, 2, 3))
        fh = fh + P[:, 16:][:, :, hi].mean(axis=(1, 2, 3))
    return co / fi, fi / fh


def main() -> None:
    from wallcli.infer import windows
    from wallcli.signal.window import remove_light_changes
    from wallcli.cli.app import main as cli

    got = []
    orig = windows.window_signal_db

    def tap(parts):
        db = orig(parts)
        got.append((db, [remove_light_changes(x, off) for x, off in parts]))
        return db

    windows.window_signal_db = tap
    print("clip | signal_db | coarse/fine slow (median over windows) | fine slow/fast")
    for clip in sys.argv[1:]:
        got.clear()
        with contextlib.redirect_stdout(io.StringIO()), contextlib.redirect_stderr(io.StringIO()):
            try:
                cli(["count", clip, "--json"])
            except SystemExit:
                pass
        if not got:
            print(clip, "no windows")
            continue
        dbs = np.concatenate([np.atleast_1d(g[0]) for g in got])
        ys = [np.concatenate([g[1][i] for g in got]) for i in range(len(got[0][1]))]
        c, r = coherence(ys)
        print(f"{clip.split('/')[-1]} | {np.mean(dbs):.2f} | {np.median(c):.1f} | {np.median(r):.1f}", flush=True)


if __name__ == "__main__":
    main()


def coherent_db(ys, fps: float = 30.0, k_sig: int = 16, k_white: int = 16) -> np.ndarray:
    """Per window: the spatially coherent slow power (components under ``k_sig``, less the white
    level that the fine components show at each frequency) over the consecutive-difference noise."""
    S = N = 0.0
    for y in ys:
        n_b, T = y.shape[-3], y.shape[-2]
        z = np.einsum("kb,nbtc->nktc", dct_basis(n_b), y)
        w = np.hanning(T)
        P = (np.abs(np.fft.rfft(z * w[:, None], axis=-2)) ** 2 / np.sum(w * w)).mean(-1)  # (n, k, F)
        white = np.median(P[:, k_white:], axis=1, keepdims=True)  # (n, 1, F)
        S = S + np.sum(np.mean(P[:, 1:k_sig] - white, axis=-1), axis=-1) / n_b
        N = N + 0.5 * np.mean(np.diff(y, axis=-2) ** 2, axis=(-3, -2, -1))
    return np.maximum(10 * np.log10(np.maximum(S / N, 1e-30)), -30.0)
