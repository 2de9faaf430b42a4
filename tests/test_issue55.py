"""Issue 55 (reliability, 5th round): one regression test (or a few) per item, on clips made here."""
from __future__ import annotations

import json
import os
import subprocess
import sys
from fractions import Fraction
from pathlib import Path

import numpy as np
import pytest
from clips import write_clip


def _wall(i, h=24, w=32):
    return np.full((h, w, 3), 120.0) + np.random.default_rng(i).normal(0, 1.0, (h, w, 3))


@pytest.fixture
def clip(tmp_path):
    return write_clip(tmp_path / "c.mkv", _wall, 12, fps=30, codec="ffv1", pix_fmt="bgr0", options={})


def _one_error(err: str) -> str:
    lines = err.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith("Error:") and "Traceback" not in err, err
    return lines[0]


# 1 ------------------------------------------------------- scan --force keeps the old results
@pytest.mark.parametrize("name", ["keep.jsonl", "keep.csv"])
def test_scan_force_that_fails_before_a_line_leaves_the_old_results(tmp_path, run_cli, clip, name):
    out = tmp_path / name
    out.write_text("old results, a line per video\n")  # --force does not read them
    code, stdout, err = run_cli("scan", clip, "-o", out, "--force", "--scheduler", "tcp://127.0.0.1:1")
    assert code == 1 and stdout == "" and "127.0.0.1:1" in _one_error(err)
    assert out.read_text() == "old results, a line per video\n"
    assert sorted(p.name for p in tmp_path.iterdir()) == sorted(["c.mkv", name])
