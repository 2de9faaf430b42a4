"""Clips and pages for the report tests: one short simulated wall clip whose file name is an
HTML injection, reported once per session (the decode and the figures take a few seconds)."""
from __future__ import annotations

import sys
from pathlib import Path

import pytest

sys.path.insert(0, str(Path(__file__).parent))

from clips import write_clip  # noqa: E402
from report_clips import HOSTILE, FRAMES, run_main, wall_frame  # noqa: E402


@pytest.fixture(scope="session")
def hostile_clip(tmp_path_factory) -> Path:
    return write_clip(tmp_path_factory.mktemp("clips") / f"{HOSTILE}.mp4", wall_frame, FRAMES)


@pytest.fixture(scope="session")
def clip_report(hostile_clip, tmp_path_factory) -> Path:
    out = tmp_path_factory.mktemp("report") / "clip.html"
    assert run_main("report", hostile_clip, "-o", out) == 0
    return out
