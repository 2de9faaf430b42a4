"""Probe: how the plots' differences grow with the lag, and how heavy their tails are, per clip.

N(k) = half the mean square of y(t + k) - y(t) (the light changes removed): white noise keeps N(k)
flat, a smooth signal grows as k^2, a codec's held noise (blocks that step now and then) grows as k
until its hold is over. Kurtosis of the lag-1 differences: 3 for Gaussian noise, far more for steps.

    python research/noise/lag_probe.py CLIP...
"""
from __future__ import annotations

import contextlib
import io
import sys

import numpy as np

LAGS = (1, 2, 4, 8, 16)


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
    print("clip | signal_db | N(k)/N(1), k = " + ", ".join(map(str, LAGS[1:])) + " | kurtosis(dy) | zero share")
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
        n = {k: sum(0.5 * np.mean((y[..., k:, :] - y[..., :-k, :]) ** 2) for y in ys) for k in LAGS}
        d = np.concatenate([np.diff(y, axis=-2).ravel() for y in ys])
        kurt = float(np.mean(d ** 4) / np.mean(d ** 2) ** 2)
        zero = float(np.mean(np.abs(d) < 1e-6 * np.sqrt(np.mean(d ** 2))))
        print(f"{clip.split('/')[-1]} | {np.mean(dbs):.2f} | " + ", ".join(f"{n[k] / n[1]:.2f}" for k in LAGS[1:])
              + f" | {kurt:.1f} | {zero:.3f}", flush=True)


if __name__ == "__main__":
    main()
