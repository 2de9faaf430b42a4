"""Issue 47: inputs that hung, answered wrongly or crashed (one test or more per item)."""
from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest

from clips import write_clip

DEEP = "[" * 100_000 + "]" * 100_000


def _one_line(err: str) -> bool:
    return err.startswith("Error:") and "Traceback" not in err and "internal error" not in err


# ------------------------------------------------------------------- 8: one JSON loader, depth-limited
def test_json_loader_refuses_deep_nesting_as_bad_json():
    from wallcli.io import jsonfile

    for text in (DEEP, "[" * 65 + "]" * 65, '{"a":' * 500 + "1" + "}" * 500):
        with pytest.raises(json.JSONDecodeError, match="nested more than 64 deep"):
            jsonfile.loads(text)
    assert jsonfile.loads("[" * 64 + "]" * 64) is not None
    with pytest.raises(ValueError):
        jsonfile.loads("[NaN]")
    assert jsonfile.loads("[NaN]", allow_nan=True)[0] != 0


def test_report_names_a_deep_results_line(tmp_path, run_cli):
    res = tmp_path / "results.jsonl"
    res.write_text(json.dumps({"input": "a.mp4", "error": "x is not a readable video"}) + "\n" + DEEP + "\n")
    code, _, err = run_cli("report", res, "-o", tmp_path / "index.html")
    assert code == 0, err
    assert "line 2 is not JSON (nested more than 64 deep" in " ".join(err.split())
    assert "RecursionError" not in err


def test_scan_resume_refuses_a_deep_results_line(tmp_path, run_cli):
    clip = write_clip(tmp_path / "a.mkv", lambda i: np.full((48, 64, 3), 128.0), 30)
    res = tmp_path / "r.jsonl"
    res.write_text(DEEP + "\n")
    code, out, err = run_cli("scan", clip, "-o", res, "--task", "snr", "--workers", "1")
    assert code == 1 and out == "" and _one_line(err), err
    assert "line 1 is not a wallcli scan result" in err
    assert res.read_text() == DEEP + "\n"  # left as it was


def test_a_deep_sidecar_is_a_damaged_one(tmp_path):
    from wallcli.evaluate.labels import read_labels

    (tmp_path / "a.mp4").write_bytes(b"x")
    (tmp_path / "a.json").write_text('{"people": 0, "activity": "none"}')
    (tmp_path / "b.mp4").write_bytes(b"x")
    (tmp_path / "b.json").write_text('{"people": 0, "activity": "none", "deep": ' + DEEP + "}")
    labels = read_labels(tmp_path)
    assert [c.file for c in labels.clips] == ["a.mp4"]
    assert labels.damaged[0][0] == "b.mp4" and "nested more than 64 deep" in labels.damaged[0][1]


# ------------------------------------------------------------------- 6: one clip reached two ways
def _labelled(tmp_path, third: str):
    for v in ("a.mp4", "b.mp4"):
        (tmp_path / v).write_bytes(f"{v}: not decoded here".encode())  # two copies of one are one clip (issue 55)
    (tmp_path / "labels.csv").write_text(f"file,people,activity\na.mp4,1,walking\nb.mp4,0,none\n{third},1,walking\n")
    return tmp_path


@pytest.mark.parametrize("link", ["hard", "sym"])
def test_a_clip_linked_twice_is_a_duplicate(tmp_path, link, run_cli):
    from wallcli.errors import WallcliError
    from wallcli.evaluate.labels import read_labels

    d = _labelled(tmp_path, "c.mp4")
    (d / "c.mp4").hardlink_to(d / "a.mp4") if link == "hard" else (d / "c.mp4").symlink_to(d / "a.mp4")
    with pytest.raises(WallcliError, match="twice: line 2 .'a.mp4'. and line 4 .'c.mp4'."):
        read_labels(d)
    code, out, err = run_cli("evaluate", d, "--task", "count")
    assert code == 1 and out == "" and _one_line(err) and len(err.splitlines()) == 1


def test_a_missing_clip_is_not_a_duplicate_a_byte_identical_copy_is(tmp_path):
    from wallcli.errors import WallcliError
    from wallcli.evaluate.labels import read_labels

    d = _labelled(tmp_path, "c.mp4")
    (d / "c.mp4").write_bytes((d / "a.mp4").read_bytes() + b"\0")  # another recording
    (d / "labels.csv").write_text((d / "labels.csv").read_text() + "gone.mp4,0,none\n")
    assert [c.file for c in read_labels(d).clips] == ["a.mp4", "b.mp4", "c.mp4", "gone.mp4"]
    # issue 55: the same bytes under another name is one recording scored twice
    (d / "c.mp4").write_bytes((d / "a.mp4").read_bytes())
    with pytest.raises(WallcliError, match="byte-identical"):
        read_labels(d)


# ------------------------------------------------------------------- 10: a huge line in labels.csv
def test_a_huge_labels_line_is_refused_early_naming_it(tmp_path, run_cli):
    import tracemalloc

    from wallcli.errors import WallcliError
    from wallcli.evaluate.labels import read_labels

    d = _labelled(tmp_path, "b.mp4")
    with open(d / "labels.csv", "w") as f:
        f.write("file,people,activity\na.mp4,1,walking\n" + "x" * (32 << 20) + ",0,none\n")
    tracemalloc.start()
    try:
        with pytest.raises(WallcliError, match=r"labels.csv line 3 is longer than"):
            read_labels(d)
        peak = tracemalloc.get_traced_memory()[1]
    finally:
        tracemalloc.stop()
    assert peak < 4 << 20  # the 32 MB line was never held
    code, out, err = run_cli("evaluate", d, "--task", "count")
    assert code == 1 and out == "" and _one_line(err) and "line 3" in err


def test_a_quoted_cell_over_many_lines_names_where_it_failed(tmp_path):
    from wallcli.errors import WallcliError
    from wallcli.evaluate.labels import read_labels

    d = _labelled(tmp_path, "b.mp4")
    (d / "labels.csv").write_text('file,people,activity\na.mp4,1,walking\n"' + "x\n" * 80_000 + '",0,none\n')
    with pytest.raises(WallcliError, match=r"labels.csv line \d+: field larger than field limit"):
        read_labels(d)


# ------------------------------------------------------------------- 11: FIFOs and devices are streams
@pytest.fixture(scope="module")
def mkv(tmp_path_factory) -> Path:
    return write_clip(tmp_path_factory.mktemp("i47") / "c.mkv", lambda i: np.full((48, 64, 3), 100 + 5 * np.sin(i / 5)), 300)


def _stplot_json(run_cli, source) -> dict:
    code, out, err = run_cli("stplot", source, "--json")
    assert code == 0, err
    return json.loads(out)


def test_a_fifo_carrying_a_video_is_read_as_a_stream(mkv, tmp_path, run_cli):
    import os
    import threading

    fifo = tmp_path / "pipe.mkv"
    os.mkfifo(fifo)

    def feed():
        with open(fifo, "wb") as f:
            try:
                f.write(mkv.read_bytes())
            except BrokenPipeError:
                pass

    t = threading.Thread(target=feed, daemon=True)
    t.start()
    try:
        got = _stplot_json(run_cli, fifo)
    finally:
        if t.is_alive():  # the reader never opened it: let the writer go
            os.close(os.open(fifo, os.O_RDONLY | os.O_NONBLOCK))
        t.join(5)
    assert got["frames"] == _stplot_json(run_cli, mkv)["frames"] > 100


@pytest.mark.parametrize("how", ["/dev/stdin", "/dev/fd/N"])
def test_dev_stdin_and_process_substitution_are_read(mkv, how):
    import os
    import subprocess
    import sys

    r, w = os.pipe()
    source = "/dev/stdin" if how == "/dev/stdin" else f"/dev/fd/{r}"
    p = subprocess.Popen([sys.executable, "-m", "wallcli", "stplot", source, "--json"], stdin=r if how == "/dev/stdin"
                         else subprocess.DEVNULL, pass_fds=(r,), stdout=subprocess.PIPE, stderr=subprocess.PIPE)
    os.close(r)
    try:
        with os.fdopen(w, "wb") as f:
            f.write(mkv.read_bytes())
    except BrokenPipeError:
        pass
    out, err = p.communicate(timeout=120)
    assert p.returncode == 0, err.decode()
    assert json.loads(out)["frames"] > 100


# ------------------------------------------------------------------- 12: a reader that left
@pytest.mark.parametrize("args", [["count", "{clip}", "--follow"], ["stplot", "{clip}", "--json"], ["--help"]])
def test_a_closed_stdout_pipe_says_so_in_one_line(mkv, args):
    import os
    import subprocess
    import sys

    r, w = os.pipe()
    os.close(r)  # the reader has gone before the first write: EPIPE, deterministically
    try:
        p = subprocess.run([sys.executable, "-m", "wallcli", *(a.format(clip=mkv) for a in args)], stdout=w,
                           stderr=subprocess.PIPE, text=True, timeout=120)
    finally:
        os.close(w)
    assert p.returncode == 1, p.stderr
    assert "Error: stdout was closed by its reader before the output was complete" in p.stderr
    assert "Traceback" not in p.stderr and p.stderr.count("Error:") == 1, p.stderr


# ------------------------------------------------------------------- 13: one rule per option, in --help
@pytest.mark.parametrize("command", ["count", "stplot", "snr", "amplify"])
def test_roi_rules_are_the_same_everywhere(mkv, tmp_path, run_cli, command):
    extra = {"count": ["--json"], "stplot": ["--json"], "snr": ["--json"], "amplify": [tmp_path / "o.mp4"]}[command]
    code, out, err = run_cli(command, mkv, *extra, "--roi", "")
    assert code == 2 and out == "" and "--roi must be four integers" in err and len(err.splitlines()) == 1
    for roi in ("0,0,1,1", "0,0,1,40", "5,5,40,1"):
        code, out, err = run_cli(command, mkv, *extra, "--roi", roi)
        assert code == 1 and out == "", (roi, err)
        assert f"ROI {roi} is smaller than 2x2 pixels" in err and "64x48" in err and len(err.splitlines()) == 1
    assert not (tmp_path / "o.mp4").exists()


@pytest.mark.parametrize("args", [["count", "{clip}", "--plot", "x.txt"], ["snr", "{clip}", "--heatmap", "x.jpg"],
                                  ["snr", "--predict", "--plot", "x"], ["stplot", "{clip}", "--png", "x.npz"],
                                  ["evaluate", "{folder}", "--task", "count", "--plot", "x.svg"]])
def test_a_figure_name_must_say_png(mkv, tmp_path, run_cli, args, monkeypatch):
    monkeypatch.chdir(tmp_path)
    code, out, err = run_cli(*(a.format(clip=mkv, folder=mkv.parent) for a in args))
    assert code == 2 and out == "" and "writes a PNG; its name must end in .png" in err
    assert not any(tmp_path.iterdir())
    command = [a for a in args if not a.startswith("{")][0]
    code, out, _ = run_cli(command, "--help")
    assert code == 0 and "must end in .png" in " ".join(out.split())


def test_amplify_writes_the_size_asked_or_refuses(mkv, tmp_path, run_cli):
    from wallcli.cli.amplify import parse_scale
    from wallcli.errors import UsageError

    for text in ("1x1", "65x48", "64x3"):
        with pytest.raises(UsageError, match="even width and height"):
            parse_scale(text, 64, 48)
    assert parse_scale("2x2", 64, 48) == (2, 2) and parse_scale("0.5", 64, 48) == (32, 24)
    assert parse_scale("0.01", 64, 48) == (2, 2)  # a factor is rounded, as --help says
    code, out, err = run_cli("amplify", mkv, tmp_path / "o.mp4", "--scale", "1x1")
    assert code == 2 and "even width and height" in err and not (tmp_path / "o.mp4").exists()
    code, out, _ = run_cli("amplify", "--help")
    assert "even numbers" in " ".join(out.split())


# ------------------------------------------------------------------- 4: a bare .h264 stream's rate
@pytest.mark.parametrize("fps", [30, 24])
def test_a_bare_h264_stream_is_read_at_its_codec_rate(tmp_path, run_cli, fps):
    clip = write_clip(tmp_path / "r.h264", lambda i: np.full((48, 64, 3), 100 + 5 * np.sin(i / 5)), 400,
                      fmt="h264", fps=fps)
    out = _stplot_json(run_cli, clip)
    assert out["fps"] == fps and out["fps_source"] == "codec"
    assert out["duration"] == pytest.approx(399 / fps, abs=0.15)  # at 25 fps: 15.9 s
    assert any("codec headers" in w for w in out["warnings"])
    assert _stplot_json(run_cli, mkv_of(tmp_path, fps))["fps_source"] == "container"


def mkv_of(tmp_path, fps):
    return write_clip(tmp_path / "m.mkv", lambda i: np.full((48, 64, 3), 100 + 5 * np.sin(i / 5)), 60, fps=fps)


# ------------------------------------------------------------------- 7: the frame size changes mid-stream
@pytest.fixture(scope="module")
def two_sizes(tmp_path_factory) -> Path:
    d = tmp_path_factory.mktemp("sizes")
    a = write_clip(d / "a.ts", lambda i: np.full((48, 64, 3), 100 + 5 * np.sin(i / 5)), 300, fmt="mpegts")
    b = write_clip(d / "b.ts", lambda i: np.full((72, 96, 3), 100 + 5 * np.sin(i / 5)), 300, fmt="mpegts")
    (d / "ab.ts").write_bytes(a.read_bytes() + b.read_bytes())
    return d / "ab.ts"


SIZE_LINE = "the frame size changes from 64x48 to 96x72 at frame 300"


@pytest.mark.parametrize("command", ["count", "stplot", "snr", "report", "amplify"])
def test_a_frame_size_change_is_one_clear_line_everywhere(two_sizes, tmp_path, run_cli, command):
    out_file = {"report": ["-o", tmp_path / "r.html"], "amplify": [tmp_path / "o.mp4"]}.get(command, ["--json"])
    code, out, err = run_cli(command, two_sizes, *out_file)
    assert code == 1 and out == "" and _one_line(err), err
    assert SIZE_LINE in err and [line for line in err.splitlines() if line.startswith("Error:")] == err.splitlines()[-1:]
    assert not any(tmp_path.iterdir())  # amplify wrote nothing at the first size


def test_scan_gives_the_video_its_error_line(two_sizes, tmp_path, run_cli):
    res = tmp_path / "r.jsonl"
    run_cli("scan", two_sizes, "-o", res, "--task", "snr", "--workers", "1")
    (line,) = [json.loads(s) for s in res.read_text().splitlines()]
    assert SIZE_LINE in line["error"] and "internal error" not in line["error"]


# ------------------------------------------------------------------- 5: too small for the camera-motion check
def _pan(tmp_path, w, h):
    import cv2

    tex = cv2.GaussianBlur(np.random.default_rng(1).normal(128, 30, (200, 400, 3)), (0, 0), 2)
    return write_clip(tmp_path / f"pan{w}x{h}.nut", lambda i: tex[50:50 + h, 10 + i:10 + i + w], 120, fps=30,
                      codec="rawvideo", pix_fmt="yuv444p", options={})


@pytest.mark.parametrize("w,h", [(30, 30), (8, 8), (3, 5)])
def test_a_pan_too_small_to_check_is_not_called_usable(tmp_path, run_cli, w, h):
    code, out, err = run_cli("snr", _pan(tmp_path, w, h), "--json")
    assert code == 0, err
    view = json.loads(out)["view"]
    assert view["usable"] is False and "too small to check" in view["issues"]
    assert "too small to check for camera motion" in view["reason"]


def test_a_pan_large_enough_is_still_caught(tmp_path, run_cli):
    code, out, err = run_cli("snr", _pan(tmp_path, 40, 40), "--json")
    view = json.loads(out)["view"]
    assert view["usable"] is False and "camera motion" in view["issues"] and "too small to check" not in view["issues"]


def test_a_tiny_roi_is_too_small_to_check(mkv, run_cli):
    code, out, err = run_cli("count", mkv, "--json", "--roi", "2,2,8,8")
    assert code == 0, err
    res = json.loads(out)
    assert res["view"]["usable"] is False and "too small to check" in res["view"]["issues"]
    assert res["confident"] is False


# ------------------------------------------------------------------- 2: a jump of the timestamps
JUMP = 10_000.0  # s, after frame 300 of 600 (30 fps): interpolated over, 300,000 rows and ~4,700 windows


@pytest.fixture(scope="module")
def jumpy(tmp_path_factory) -> Path:
    from fractions import Fraction

    rng = np.random.default_rng(0)
    return write_clip(tmp_path_factory.mktemp("jump") / "j.mkv",
                      lambda i: np.full((48, 64, 3), 100 + 5 * np.sin(i / 5)) + rng.normal(0, 2, (48, 64, 3)), 600,
                      time_base=Fraction(1, 1000), pts_fn=lambda i: round((i / 30 + JUMP * (i >= 300)) * 1000))


def _cli(args, timeout=120, **kw):
    """wallcli in a child process, killed (by subprocess.run) if it outlives ``timeout``."""
    import subprocess
    import sys

    return subprocess.run([sys.executable, "-m", "wallcli", *map(str, args)], capture_output=True, text=True,
                          timeout=timeout, **kw)


@pytest.mark.parametrize("how", ["json", "follow", "npz"])
def test_a_timestamp_jump_costs_nothing_and_no_window_sits_in_it(jumpy, tmp_path, how):
    source = jumpy
    if how == "npz":
        source = tmp_path / "p.npz"
        assert _cli(["stplot", jumpy, "-o", source]).returncode == 0
    p = _cli(["count", source, "--follow" if how == "follow" else "--json"])
    assert p.returncode == 0, p.stderr
    # --follow: a line per window, then the clip's answer (the --json object, with its windows)
    windows = ([w for w in map(json.loads, p.stdout.splitlines()) if "windows" not in w] if how == "follow"
               else json.loads(p.stdout)["windows"])
    before = [w for w in windows if w["end"] <= 10.0 + 1e-3]
    after = [w for w in windows if w["start"] >= JUMP + 10.0 - 1e-3]
    assert before and after and len(before) + len(after) == len(windows) <= 4, [(w["start"], w["end"]) for w in windows]
    # cut on either side of the gap, none spans it: the view check has no fault to find in them
    assert all(w["view"]["usable"] for w in windows), [w["view"] for w in windows]


def test_a_repeat_left_out_after_a_jump_hands_its_gap_on():
    """The frame after a jump may copy the one before it (a recorder re-sending its last picture):
    the repeat filter drops it, and the next frame must still restart the grid."""
    from types import SimpleNamespace

    from wallcli.camera.repeats import RepeatFilter
    from wallcli.io.planes import Planes
    from wallcli.io.video import Frame

    rng = np.random.default_rng(0)
    ys = [rng.integers(0, 255, (16, 16), dtype=np.uint8) for _ in range(40)]
    ys[20] = ys[19].copy()  # the first frame after the jump repeats the last one before it
    frames = [Frame(i, i / 30 + JUMP * (i >= 20), Planes(ys[i], None, None, kind="gray"),
                    gap=(JUMP + 1 / 30) * (i == 20)) for i in range(40)]
    kept = list(RepeatFilter(SimpleNamespace(frames=lambda: iter(frames))).frames())
    assert len(kept) == 39 and [f.index for f in kept if f.gap] == [21]
    assert [f.gap for f in kept if f.gap] == [pytest.approx(JUMP + 2 / 30)]


# ------------------------------------------------------------------- 1: a stalled stdin
def _stalled(args, head: bytes = b""):
    """wallcli reading a stdin that sends ``head`` and then nothing (the writer stays open)."""
    import subprocess
    import sys

    p = subprocess.Popen([sys.executable, "-m", "wallcli", *map(str, args)], stdin=subprocess.PIPE,
                         stdout=subprocess.PIPE, stderr=subprocess.PIPE)
    if head:
        p.stdin.write(head)
        p.stdin.flush()
    return p


def _finish(p, timeout):
    """(exit code, stderr) once ``p`` ends, its stdin still open (no EOF to end it); killed and
    None if it outlives ``timeout``."""
    import subprocess

    try:
        p.wait(timeout=timeout)
        return p.returncode, p.stderr.read().decode()
    except subprocess.TimeoutExpired:
        p.kill()
        p.wait()
        return None, "still running"
    finally:
        p.stdin.close()
        p.stdout.close()
        p.stderr.close()


@pytest.mark.parametrize("sig", ["SIGINT", "SIGTERM"])
@pytest.mark.parametrize("args,head", [(["count", "-", "--json"], 0), (["count", "-", "--json"], 30_000),
                                       (["count", "-", "--follow"], 30_000)])
def test_a_signal_ends_a_command_whose_stdin_stalled(mkv, sig, args, head):
    import signal
    import time

    p = _stalled(args, mkv.read_bytes()[:head])
    try:
        time.sleep(6)  # started, its handlers installed, waiting on the silent pipe
        assert p.poll() is None, p.communicate()
        p.send_signal(getattr(signal, sig))
        code, err = _finish(p, 20)  # the wait is in steps of 0.2 s: far less than 20
    finally:
        if p.poll() is None:
            p.kill()
            p.wait()
    assert code == 1 and err.strip() == "Error: interrupted", (code, err)


@pytest.mark.parametrize("args,head", [(["count", "-", "--json"], 0), (["stplot", "-", "--json"], 30_000)])
def test_a_stalled_stdin_says_so_after_the_stall_timeout(mkv, args, head):
    p = _stalled([*args, "--stall-timeout", "2"], mkv.read_bytes()[:head])
    code, err = _finish(p, 60)
    assert code == 1 and _one_line(err) and len(err.splitlines()) == 1, (code, err)
    assert "Error: -: no data for 2 s (its writer stalled)" in err and "--stall-timeout" in err


def test_stall_timeout_is_said_in_help(run_cli):
    for command in ("count", "activity", "snr", "stplot", "amplify", "report"):
        code, out, _ = run_cli(command, "--help")
        text = " ".join(out.split())
        # only the commands that have --follow name it (issue 61)
        default = "Default: 30, or for ever with --follow" if command in ("count", "activity") else "Default: 30."
        assert code == 0 and "--stall-timeout" in text and default in text


# ------------------------------------------------------------------- 9: stplot's memory
def _stplot_peak(clip: Path, out: Path) -> tuple[int, int]:
    """(tracemalloc peak of stplot's work on ``clip`` as the command does it, the plot's bytes)."""
    import tracemalloc

    from wallcli.camera.pipeline import CameraPipeline
    from wallcli.io.arrays import save_npz
    from wallcli.io.video import FrameTee, open_video
    from wallcli.signal.stplot import channel_std, compute_stplot, to_arrays
    from wallcli.view.check import ViewCheck

    tracemalloc.start()
    try:
        check = ViewCheck(None)
        with open_video(clip) as reader:
            plot = compute_stplot(FrameTee(CameraPipeline(reader, check), (check,)), register=True, view=check)
        save_npz(out, *to_arrays(plot), force=True)
        channel_std(plot.horizontal)  # (the --json summary)
        peak = tracemalloc.get_traced_memory()[1]
    finally:
        tracemalloc.stop()
    arrays = to_arrays(plot)[0]
    return peak, sum(arrays[k].nbytes for k in ("horizontal", "vertical", "time", "shift"))


def test_stplot_memory_grows_only_by_the_plot(tmp_path):
    """Issue 47 item 9: 9.8 KB a frame at 720p (float64 copies of the whole plot at its end)."""
    rng = np.random.default_rng(0)
    clips = {n: write_clip(tmp_path / f"{n}.mkv", lambda i: np.full((48, 64, 3), 100.0) + rng.normal(0, 2, (48, 64, 3)),
                           n) for n in (60, 300, 1200)}
    _stplot_peak(clips[60], tmp_path / "w.npz")  # imports and first-use caches, outside the measure
    (p1, b1), (p4, b4) = (_stplot_peak(clips[n], tmp_path / f"{n}.npz") for n in (300, 1200))
    per_frame, plot_per_frame = (p4 - p1) / 900, (b4 - b1) / 900  # 1552 B: 2 x 64 bins x 3 colours float32 + 16
    assert per_frame <= 1.1 * plot_per_frame, (per_frame, plot_per_frame)


# ------------------------------------------------------------------- 3: --follow on a growing file
def test_follow_reads_a_file_as_a_recorder_writes_it(tmp_path):
    """Issue 47 item 3: --follow stopped at the current end of a file still being written."""
    import threading
    import time

    rng = np.random.default_rng(0)
    whole = write_clip(tmp_path / "whole.ts", lambda i: np.full((48, 64, 3), 100.0) + rng.normal(0, 2, (48, 64, 3)),
                       600, fmt="mpegts").read_bytes()
    growing = tmp_path / "rec.ts"
    growing.write_bytes(whole[:len(whole) // 10])  # a tenth: 2 s of 20, less than one window
    stop = threading.Event()

    def record():  # the rest in 20 pieces, 0.3 s apart (well under the 5 s --idle-timeout)
        rest = whole[len(whole) // 10:]
        with open(growing, "ab") as f:
            for i in range(20):
                if stop.wait(0.3):
                    return
                f.write(rest[i * len(rest) // 20:(i + 1) * len(rest) // 20])
                f.flush()

    t = threading.Thread(target=record, daemon=True)
    start = time.monotonic()
    t.start()
    try:
        p = _cli(["count", growing, "--follow"], timeout=120)
    finally:
        stop.set()
        t.join(10)
    assert p.returncode == 0 and "truncated" not in p.stderr, p.stderr
    lines = [json.loads(s) for s in p.stdout.splitlines()]
    windows, whole = lines[:-1], lines[-1]  # a line per window, then the clip's answer
    assert [w["start"] for w in whole["windows"]] == [w["start"] for w in windows]
    # 20 s: every stride (the 6th at 10.667 s), then the window aligned to the end
    assert len(windows) == 7 and windows[5]["start"] == pytest.approx(10.667, abs=0.01)
    assert time.monotonic() - start >= 6 + 5 - 1  # it waited for the recorder, then for --idle-timeout
    code = _cli(["count", tmp_path / "whole.ts", "--follow", "--idle-timeout", "0"], timeout=120)
    assert [json.loads(s)["start"] for s in code.stdout.splitlines()[:-1]] == [w["start"] for w in windows]


def test_idle_timeout_is_said_in_help(run_cli):
    for command in ("count", "activity"):
        code, out, _ = run_cli(command, "--help")
        assert code == 0 and "keep reading it as a recorder writes it" in " ".join(out.split())
