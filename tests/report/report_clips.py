"""Shared by the report tests (a module of its own: `conftest` names several modules in this suite)."""
from __future__ import annotations

import numpy as np

HOSTILE = "<img src=x onerror=alert(1)>"
FRAMES = 270  # 9 s at 30 fps: two windows of 256 frames (the last one end-aligned)


def wall_frame(i: int, fps: float = 30.0, h: int = 48, w: int = 64) -> np.ndarray:
    """A grey wall with a faint shadow sweeping across it (a few code values) and camera noise."""
    x = np.arange(w)
    pos = (8 + 12.0 * i / fps) % w
    shade = 6.0 * np.exp(-0.5 * ((x - pos) / 4.0) ** 2)
    img = np.full((h, w, 3), 120.0) - shade[None, :, None] * np.array([1.0, 0.8, 0.6])
    return img + np.random.default_rng(i).normal(0, 1.0, img.shape)


def run_main(*args) -> int:
    from wallcli.cli.app import main

    try:
        main([str(a) for a in args])
    except SystemExit as exc:
        return exc.code if isinstance(exc.code, int) else (0 if exc.code is None else 1)
    return 0
