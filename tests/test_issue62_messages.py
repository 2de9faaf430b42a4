"""Messages that match what the tool then does (issue 62 point 14): amplify never suggests a size it
refuses and warns of a tiny ROI as the other commands do; a huge-header .npz is called compressed
only when it is; --stream on a space-time plot is refused as --roi is."""
from __future__ import annotations

import re
import zipfile

import numpy as np
import pytest

from clips import one_error, tiny_clip, write_plot


@pytest.mark.parametrize("text", ["99999x99999", "16385x3", "16383x5", "16383x2001", "3x3", "641x361"])
@pytest.mark.parametrize("panels", [1, 2])
def test_an_odd_size_is_refused_with_a_suggestion_that_is_accepted(text, panels):
    from wallcli.cli.amplify import MAX_OUTPUT_PIXELS, parse_scale
    from wallcli.errors import UsageError

    with pytest.raises(UsageError) as info:
        parse_scale(text, 64, 48, panels)
    m = re.search(r"e\.g\. (\d+)x(\d+)", str(info.value))
    if m:  # the suggestion is a size amplify writes
        w, h = parse_scale(f"{m[1]}x{m[2]}", 64, 48, panels)
        assert panels * w * h <= MAX_OUTPUT_PIXELS
    if text == "99999x99999":
        assert "e.g." not in str(info.value) and "16384" in str(info.value)


def test_amplify_warns_of_a_tiny_roi(tmp_path, run_cli):
    clip = tiny_clip(tmp_path / "c.mkv")
    code, out, err = run_cli("amplify", clip, tmp_path / "o.mp4", "--roi", "0,0,2,2")
    assert code == 0, err
    assert "Warning:" in err and "too small" in " ".join(err.split()) and "(2x2 px)" in err
    code, out, err = run_cli("amplify", clip, tmp_path / "o2.mp4")  # 32x24: the whole frame is small too
    assert "too small" in " ".join(err.split())


def _huge_header_npz(path, compression):
    from numpy.lib import format as npy

    with zipfile.ZipFile(path, "w", compression) as zf:
        with zf.open("horizontal.npy", "w") as f:  # declares 300 MB, holds a few bytes
            npy.write_array_header_1_0(f, {"descr": "<f4", "fortran_order": False, "shape": (64, 400_000, 3)})
            f.write(bytes(64))
    return path


@pytest.mark.parametrize("compression", [zipfile.ZIP_STORED, zipfile.ZIP_DEFLATED])
def test_a_huge_header_npz_is_called_compressed_only_when_it_is(tmp_path, run_cli, compression):
    path = _huge_header_npz(tmp_path / "h.npz", compression)
    code, out, err = run_cli("count", path, "--json")
    line = one_error(err)
    assert code == 1 and out == ""
    if compression == zipfile.ZIP_STORED:
        assert "(compressed)" not in line and "uncompressed" in line and "more than the file holds" in line
    else:
        assert "(compressed)" in line


@pytest.mark.parametrize("command", ["track", "count"])
def test_stream_on_a_plot_is_refused_as_roi_is(tmp_path, run_cli, command):
    plot = write_plot(tmp_path / "p.npz")
    code, out, err = run_cli(command, plot, "--roi", "0,0,8,8")
    assert code == 2 and "--roi applies to videos" in one_error(err)
    code, out, err = run_cli(command, plot, "--stream", "1")
    assert code == 2 and out == "" and "--stream applies to videos" in one_error(err)
    code, out, err = run_cli(command, plot, "--json")  # and without it the plot is read
    assert code == 0, err


def test_a_one_frame_clip_is_refused_by_amplify_without_an_internal_error_or_warning(tmp_path, run_cli):
    from clips import write_clip

    src = write_clip(tmp_path / "one.mp4", lambda i: np.full((16, 16, 3), 100.0), 1)
    code, out, err = run_cli("amplify", src, tmp_path / "o.mp4")
    assert code == 1 and "only 1 frame" in one_error(err) and "internal" not in err
