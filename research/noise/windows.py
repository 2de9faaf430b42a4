"""The windows `wallcli count` measures `signal_db` on, caught as it runs (the probes' one input).

    from windows import clip_windows
    dbs, ys = clip_windows("clip.mp4")   # reported signal_db per window; per plot, (n, bins, T, 3)
"""
from __future__ import annotations

import contextlib
import io

import numpy as np


def clip_windows(clip: str) -> tuple[np.ndarray, list[np.ndarray]] | None:
    """(the signal_db of each window count reported, [each plot's windows with the whole-wall light
    changes removed, (n, bins, T, 3)]) for ``clip``, or None when count gave no window."""
    from wallcli.cli.app import main as cli
    from wallcli.infer import windows
    from wallcli.signal.window import remove_light_changes

    got = []
    orig = windows.window_signal_db

    def tap(parts, *args, **kwargs):
        db = orig(parts, *args, **kwargs)
        got.append((db, [remove_light_changes(x, off) for x, off in parts]))
        return db

    windows.window_signal_db = tap
    try:
        with contextlib.redirect_stdout(io.StringIO()), contextlib.redirect_stderr(io.StringIO()):
            try:
                cli(["count", clip, "--json"])
            except SystemExit:
                pass
    finally:
        windows.window_signal_db = orig
    if not got:
        return None
    dbs = np.concatenate([np.atleast_1d(g[0]) for g in got])
    return dbs, [np.concatenate([g[1][i] for g in got]) for i in range(len(got[0][1]))]
