"""count/activity --follow (issue 61.1): each window's line carries its column SNR, and the clip's
closing line the headline figure count --json gives, from the same decode."""
from __future__ import annotations

import json

import numpy as np
import pytest

from clips import write_clip

FRAMES, W, H = 330, 48, 36


def _clip(path, amp: float):
    x = np.arange(W)[None, :]
    centre = W * (0.5 + 0.35 * np.sin(2 * np.pi * 0.3 * np.arange(FRAMES) / 30.0))[:, None]
    shade = 120.0 - amp * np.exp(-0.5 * ((x - centre) / (0.15 * W)) ** 2)  # a walker's broad shade
    rng = np.random.default_rng(3)

    def frame(i):
        img = np.repeat(shade[i][None, :, None], H, 0) + 1.5 * rng.standard_normal((H, W, 1))
        return np.repeat(img, 3, axis=2)

    return write_clip(path, frame, FRAMES)


@pytest.fixture(scope="module")
def walker(tmp_path_factory):
    return _clip(tmp_path_factory.mktemp("c") / "walker.mp4", 6.0)


@pytest.fixture(scope="module")
def still(tmp_path_factory):
    return _clip(tmp_path_factory.mktemp("c") / "still.mp4", 0.0)


def _lines(run_cli, task, clip):
    code, out, err = run_cli(task, clip, "--follow")
    assert code == 0, err
    return [json.loads(line) for line in out.splitlines()]


def test_follow_lines_carry_the_column_snr(run_cli, walker, still):
    lines = _lines(run_cli, "count", walker)
    windows, clip = lines[:-1], lines[-1]
    assert len(windows) == len(clip["windows"]) >= 2
    # each window's own figure: a plain shade in every window
    assert all(isinstance(w["column_snr_db"], float) and w["column_snr_db"] > 10 for w in windows)
    # the closing line is count --json's object, the headline included
    code, out, err = run_cli("count", walker, "--json")
    assert code == 0, err
    assert clip["column_snr_db"] == json.loads(out)["column_snr_db"] > 10
    # the figure follows the wall, not the window: a wall with no shade reads lower in every window
    quiet = _lines(run_cli, "count", still)
    assert max(w["column_snr_db"] for w in quiet[:-1]) < min(w["column_snr_db"] for w in windows)
    assert quiet[-1]["column_snr_db"] < clip["column_snr_db"]


def test_activity_follow_lines_carry_it_too(run_cli, walker):
    lines = _lines(run_cli, "activity", walker)
    assert all(isinstance(w["column_snr_db"], float) for w in lines[:-1])
    assert isinstance(lines[-1]["column_snr_db"], float)
