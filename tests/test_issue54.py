"""Issue #54, as a new user meets it: the README's and --help's lines, and what the tool prints."""

import re
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from clips import write_clip

ROOT = Path(__file__).resolve().parent.parent


def _wall(i, _base=np.random.default_rng(0).uniform(80, 160, (64, 80, 3))):
    return _base + 3 * np.sin(i / 3)


@pytest.mark.parametrize("codec,warned", [("mpeg4", True), ("ffv1", False)])
def test_a_reencoded_stream_on_stdin_is_warned_of_once(tmp_path, codec, warned):
    """`ffmpeg -i SRC -f nut -` re-encodes to MPEG-4 Part 2 and the answers change: a stream on
    stdin in such a codec gets one warning saying to copy it; a lossless one gets none."""
    path = write_clip(tmp_path / f"{codec}.nut", _wall, 60, codec=codec, fmt="nut", options={})
    with open(path, "rb") as fh:
        out = subprocess.run([sys.executable, "-m", "wallcli", "snr", "-", "--json"], stdin=fh,
                             capture_output=True, text=True, timeout=120)
    assert out.returncode == 0, out.stderr
    said = [line for line in out.stderr.splitlines() if "-c copy" in line]
    assert len(said) == (1 if warned else 0), out.stderr
    if warned:
        assert said[0].startswith("Warning: -: ") and "mpeg4" in said[0]


def test_every_ffmpeg_pipe_line_copies_the_stream(run_cli):
    """Every `ffmpeg ... -f nut -` line a user reads (README, docs, --help) copies the stream."""
    texts = {p.name: p.read_text() for p in [ROOT / "README.md", *(ROOT / "docs").glob("*.md"),
                                             *(ROOT / "examples").glob("*.sh")]}
    for command in ("count", "activity", "stplot", "scan"):
        code, out, err = run_cli(command, "--help")
        assert code == 0
        texts[f"{command} --help"] = out + err
    lines = [(name, line) for name, text in texts.items() for line in text.splitlines()
             if re.search(r"ffmpeg .*-f (nut|mpegts|matroska) -", line)]
    assert len(lines) >= 4  # the README's two and count's, activity's and stplot's
    assert [(n, line) for n, line in lines if "-c copy" not in line] == []
