"""Clips and pages for the report tests: one short simulated wall clip whose file name is an
HTML injection, reported once per session (the decode and the figures take a few seconds)."""
from __future__ import annotations

import sys
from pathlib import Path

import numpy as np
import pytest

sys.path.insert(0, str(Path(__file__).parent))

from clips import write_clip  # noqa: E402

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


@pytest.fixture(scope="session")
def hostile_clip(tmp_path_factory) -> Path:
    return write_clip(tmp_path_factory.mktemp("clips") / f"{HOSTILE}.mp4", wall_frame, FRAMES)


@pytest.fixture(scope="session")
def clip_report(hostile_clip, tmp_path_factory) -> Path:
    out = tmp_path_factory.mktemp("report") / "clip.html"
    assert run_main("report", hostile_clip, "-o", out) == 0
    return out
