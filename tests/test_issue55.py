"""Issue 55 (reliability, 5th round): one regression test (or a few) per item, on clips made here."""
from __future__ import annotations

import json
import os
import subprocess
import sys
from fractions import Fraction

import numpy as np
import pytest
from clips import grey_wall, model_with, one_error, tiny_clip, write_clip


_wall = grey_wall
_one_error = one_error


@pytest.fixture
def clip(tmp_path):
    return tiny_clip(tmp_path / "c.mkv")


# 1 ------------------------------------------------------- scan --force keeps the old results
@pytest.mark.parametrize("name", ["keep.jsonl", "keep.csv"])
def test_scan_force_that_fails_before_a_line_leaves_the_old_results(tmp_path, run_cli, clip, name):
    out = tmp_path / name
    out.write_text("old results, a line per video\n")  # --force does not read them
    code, stdout, err = run_cli("scan", clip, "-o", out, "--force", "--scheduler", "tcp://127.0.0.1:1")
    assert code == 1 and stdout == "" and "127.0.0.1:1" in _one_error(err)
    assert out.read_text() == "old results, a line per video\n"
    assert sorted(p.name for p in tmp_path.iterdir()) == sorted(["c.mkv", name])


# 2 ------------------------------------------- a short write to stdout is an error, -u or not
@pytest.mark.skipif(sys.platform != "linux", reason="RLIMIT_FSIZE emulates a nearly full disk")
@pytest.mark.parametrize("unbuffered", ["1", ""])
def test_stdout_cut_short_by_a_full_disk_fails_even_unbuffered(tmp_path, unbuffered):
    import resource

    from clips import write_plot

    plot = write_plot(tmp_path / "p.npz", seconds=20)
    out = tmp_path / "o.json"

    def small_disk():  # the file may grow to 200 bytes: the first write is cut short, the next fails
        resource.setrlimit(resource.RLIMIT_FSIZE, (200, 200))

    env = {**os.environ, "PYTHONUNBUFFERED": unbuffered}
    with open(out, "wb") as f:
        run = subprocess.run([sys.executable, "-m", "wallcli", "count", str(plot), "--json"], stdout=f,
                             stderr=subprocess.PIPE, preexec_fn=small_disk, env=env, timeout=120)
    assert run.returncode == 1 and out.stat().st_size == 200
    assert "cannot write to stdout" in _one_error(run.stderr.decode())


# 3 ------------------------------------------------------------ amplify keeps the source's times
def _times(path) -> list[float]:
    import av

    with av.open(str(path)) as c:
        return [float(f.pts * f.time_base) for f in c.decode(video=0)]


@pytest.mark.parametrize("case", ["gap", "10fps", "vfr"])
def test_amplify_output_frames_keep_their_source_times(tmp_path, run_cli, case):
    if case == "gap":  # 3 s at 30 fps, 2 s of frames missing, 3 s more
        n, fps, tb = 180, 30, Fraction(1, 30)
        pts = lambda i: i if i < 90 else i + 60  # noqa: E731
    elif case == "10fps":  # the stream says 30 fps, its frames are 0.1 s apart
        n, fps, tb = 40, 30, Fraction(1, 30)
        pts = lambda i: 3 * i  # noqa: E731
    else:  # a phone's variable rate: intervals of 1/30 and 1/15 s, in a 1/1000 s time base
        n, fps, tb = 90, 30, Fraction(1, 1000)
        pts = lambda i: round(1000 * (i / 30 + (i // 2) / 30))  # noqa: E731
    src = write_clip(tmp_path / "src.mkv", lambda i: _wall(i, 48, 64), n, fps=fps, codec="ffv1", pix_fmt="bgr0",
                     options={}, pts_fn=pts, time_base=tb)
    code, _, err = run_cli("amplify", src, tmp_path / "amp.mp4", "--gain", "10")
    assert code == 0, err
    want, got = _times(src), _times(tmp_path / "amp.mp4")
    assert len(got) == len(want) == n
    assert np.allclose(np.array(got) - got[0], np.array(want) - want[0], atol=0.002), (got[-1], want[-1])


# 4 ---------------------------------------------------- frame rates from the frames' own times
def _labelled_30(tmp_path, name, step, n=40):
    """A clip whose stream says 30 fps while its frames are ``step`` seconds apart (microsecond times)."""
    import av

    tb = Fraction(1, 1_000_000)
    with av.open(str(tmp_path / name), "w") as c:
        s = c.add_stream("ffv1", rate=30)
        s.width, s.height, s.pix_fmt = 64, 48, "bgr0"
        s.codec_context.time_base = tb
        for i in range(n):
            f = av.VideoFrame.from_ndarray(np.clip(_wall(i, 48, 64), 0, 255).astype(np.uint8), format="rgb24")
            f.pts, f.time_base = round(i * step / tb), tb
            for p in s.encode(f):
                c.mux(p)
        for p in s.encode():
            c.mux(p)
    return tmp_path / name


def test_stplot_and_snr_report_the_rate_the_frames_run_at(tmp_path, run_cli):
    from wallcli.io.arrays import load_npz

    src = _labelled_30(tmp_path, "ten.mkv", 0.1)
    code, _, err = run_cli("stplot", src, "-o", tmp_path / "p.npz", "--bins", "16")
    assert code == 0, err
    arrays, meta = load_npz(tmp_path / "p.npz")
    assert meta["fps"] == pytest.approx(1 / np.median(np.diff(arrays["time"]))) == pytest.approx(10)
    code, out, err = run_cli("snr", src, "--json")
    assert code == 0, err
    assert json.loads(out)["fps"] == pytest.approx(10)


@pytest.mark.parametrize("command", ["snr", "stplot", "amplify"])
@pytest.mark.parametrize("step", [3600.0, 0.001])
def test_rates_outside_10_to_240_fps_are_refused_by_every_command(tmp_path, run_cli, command, step):
    src = _labelled_30(tmp_path, "odd.mkv", step, n=20)
    args = {"stplot": ["-o", tmp_path / "p.npz"], "amplify": [tmp_path / "a.mp4"]}.get(command, [])
    code, out, err = run_cli(command, src, *args)
    assert code == 1 and out == ""
    assert "wallcli reads videos of 10 to 240 fps" in _one_error(err)
    assert sorted(p.name for p in tmp_path.iterdir()) == ["odd.mkv"]


def test_a_30_fps_gif_reads_30_fps(tmp_path, run_cli):
    gif = write_clip(tmp_path / "g.gif", lambda i: _wall(i, 48, 64), 60, fps=30, codec="gif", pix_fmt="rgb8",
                     options={})  # delays of 3, 3 and 4 centiseconds, which FFmpeg's rate reads as 33.3
    code, out, err = run_cli("snr", gif, "--json")
    assert code == 0, err
    assert json.loads(out)["fps"] == pytest.approx(30, abs=0.1)


# 6 ----------------------------------------------------- ROIs too small for the view check
@pytest.mark.parametrize("roi", ["0,0,2,2", "0,0,7,7", "0,0,4,120", "0,0,160,4", "0,0,20,20"])
def test_an_roi_too_small_to_check_is_no_usable_view(tmp_path, run_cli, roi):
    src = write_clip(tmp_path / "w.mkv", lambda i: _wall(i, 120, 160), 40, fps=30, codec="ffv1", pix_fmt="bgr0",
                     options={})
    code, out, err = run_cli("snr", src, "--roi", roi, "--json")
    assert code == 0, err
    view = json.loads(out)["view"]
    assert view["usable"] is False and view["issues"] == ["too small to check"]
    assert "33x33 pixels" in view["reason"]
    code, out, err = run_cli("snr", src, "--roi", roi, "--json", "--strict")
    assert code == 1 and "33x33 pixels" in _one_error(err)


# 9 ------------------------------------------------------------------------- internal errors
def test_a_frame_640_times_wider_than_high_is_no_internal_error(tmp_path, run_cli):
    src = write_clip(tmp_path / "wide.nut", lambda i: _wall(i, 16, 16384), 12, fps=30, codec="rawvideo",
                     pix_fmt="yuv444p", options={})
    for command in ("snr", "stplot"):
        code, out, err = run_cli(command, src, "--json")
        assert code == 0 and "internal error" not in err, err
        assert json.loads(out)["view"]["issues"] == ["too thin to check"]
    code, out, err = run_cli("count", src, "--json")  # too short, said as such: not a crash
    assert code == 1 and "too short" in _one_error(err)


def test_snr_predict_gain_below_a_millionth_is_a_usage_error(run_cli):
    code, out, err = run_cli("snr", "--predict", "--mean-code", "100", "--gain", "1e-200")
    assert code == 2 and out == "" and "--gain" in _one_error(err) and "1e-06" in err


@pytest.mark.parametrize("field,value,words", [
    ("two_stage.confidence.thresholds", "x", "thresholds"),
    ("two_stage.confidence.thresholds", [[0]], "thresholds"),
    ("two_stage.confidence.level", 2, "level"),
    ("two_stage.prior_two_vs_one", 1e308, "prior_two_vs_one"),
    ("two_stage.prior_two_vs_one", -1, "prior_two_vs_one"),
    ("two_stage.prior_two_vs_one", "1:4", "prior_two_vs_one"),
    ("classes", ["a", "b", "c"], "classes"),
])
def test_two_stage_and_class_fields_of_a_card_are_validated_on_load(tmp_path, run_cli, field, value, words):
    from clips import write_plot

    plot = write_plot(tmp_path / "p.npz")
    code, out, err = run_cli("count", plot, "--model", model_with(tmp_path, **{field: value}), "--json")
    assert code == 1 and out == "" and words in _one_error(err)


# 7 ---------------------------------------------------------------------- duplicates and truth
def test_evaluate_refuses_byte_identical_copies(tmp_path, run_cli):
    from wallcli.errors import WallcliError
    from wallcli.evaluate.labels import read_labels

    (tmp_path / "a.mp4").write_bytes(b"one recording")
    (tmp_path / "b.mp4").write_bytes(b"one recording")
    (tmp_path / "labels.csv").write_text("file,people,activity\na.mp4,1,walking\nb.mp4,1,walking\n")
    with pytest.raises(WallcliError, match="byte-identical"):
        read_labels(tmp_path)
    code, out, err = run_cli("evaluate", tmp_path, "--task", "count")
    assert code == 1 and out == "" and "byte-identical" in _one_error(err)


def test_a_sidecar_without_activities_gives_counts_truth_from_moving(tmp_path):
    from wallcli.evaluate.labels import read_labels

    (tmp_path / "a.mp4").write_bytes(b"a")
    (tmp_path / "a.json").write_text(json.dumps({"people": 2, "moving": 1, "activity": "walking"}))
    (clip,) = read_labels(tmp_path).clips
    assert clip.people == 1 and clip.persons == 2


def test_scan_inputs_name_a_hard_linked_pair_once(tmp_path):
    from wallcli.batch.inputs import expand_inputs

    (tmp_path / "a.mp4").write_bytes(b"a")
    os.link(tmp_path / "a.mp4", tmp_path / "b.mp4")
    assert expand_inputs([str(tmp_path)]) == [str(tmp_path / "a.mp4")]


def test_report_shows_one_recording_under_two_names_as_a_copy(tmp_path):
    # issue 62 (8): every file scanned is a row; merging them by sha256 hid files
    from wallcli.report.scan import read_results, summarise

    line = {"input": "a.mp4", "size": 1, "sha256": "ab" * 32, "tasks": ["snr"], "error": None,
            "snr": {"snr_db": [1.0, 1.0, 1.0]}}
    (tmp_path / "r.jsonl").write_text(json.dumps(line) + "\n" + json.dumps({**line, "input": "b.mp4"}) + "\n")
    records, problems = read_results(tmp_path / "r.jsonl")
    assert [r["input"] for r in records] == ["a.mp4", "b.mp4"] and "same sha256" in problems[0]
    assert [r["copy_of"] for r in summarise(records)["rows"]] == [None, "a.mp4"]


# 10 --------------------------------------------------------------------- evidence and leftovers
def test_a_report_on_a_local_playlist_hashes_the_media_it_names(tmp_path, run_cli):
    from wallcli.infer.card import sha256_file

    seg = write_clip(tmp_path / "seg0.ts", lambda i: _wall(i, 48, 64), 30, fps=30, fmt="mpegts")
    (tmp_path / "live.m3u8").write_text("#EXTM3U\n#EXT-X-VERSION:3\n#EXT-X-TARGETDURATION:1\n"
                                        "#EXTINF:1.0,\nseg0.ts\n#EXT-X-ENDLIST\n")
    code, _, err = run_cli("report", tmp_path / "live.m3u8", "-o", tmp_path / "r.html")
    assert code == 0, err
    assert sha256_file(seg) in (tmp_path / "r.html").read_text()


def test_dataset_force_removes_the_old_sets_extra_shards(tmp_path):
    from wallcli.datagen.dataset import build_dataset

    d = tmp_path / "ds"
    d.mkdir()
    (d / "shard-00007.npz").write_bytes(b"an older, larger set's shard")
    m = build_dataset(d, 1, "count", seed=3, jobs=1, windows_per_scene=1, shard_scenes=1, grid=(6, 8), force=True,
                      camera_overrides={"fps": 15.0, "width": 64, "height": 48, "codec": "ffv1"})
    assert sorted(p.name for p in d.glob("shard-*.npz")) == [s["file"] for s in m["shards"]] == ["shard-00000.npz"]


def test_leftover_temporaries_of_killed_runs_are_removed_not_those_of_live_ones(tmp_path, clip, run_cli):
    import fcntl

    dead = tmp_path / ".p.abcd1234.tmp.npz"
    dead.write_bytes(b"half a plot of a run killed with SIGKILL")
    live = tmp_path / ".p.efgh5678.tmp.npz"
    live.write_bytes(b"a plot being written by another run")
    for p in (dead, live):  # both last written a minute ago
        os.utime(p, (p.stat().st_mtime - 60,) * 2)
    with open(live, "rb") as held:
        fcntl.flock(held, fcntl.LOCK_EX)
        code, _, err = run_cli("stplot", clip, "-o", tmp_path / "p.npz", "--bins", "16")
    assert code == 0, err
    assert not dead.exists() and live.exists() and (tmp_path / "p.npz").exists()


# 5 ------------------------------------------------------- --follow and recorders that flush slowly
def _fragmented_mp4(path, n=600):
    """A fragmented MP4 (a fragment a second), as a recorder that must survive a power cut writes it."""
    import av

    rng = np.random.default_rng(0)
    with av.open(str(path), "w", options={"movflags": "frag_keyframe+empty_moov"}) as c:
        s = c.add_stream("libx264", rate=30)
        s.width, s.height, s.pix_fmt = 64, 48, "yuv420p"
        s.options = {"crf": "12", "preset": "ultrafast", "g": "30"}
        for i in range(n):
            img = np.clip(np.full((48, 64, 3), 100.0) + rng.normal(0, 2, (48, 64, 3)), 0, 255).astype(np.uint8)
            for p in s.encode(av.VideoFrame.from_ndarray(img, format="rgb24")):
                c.mux(p)
        for p in s.encode():
            c.mux(p)
    return path.read_bytes()


def test_follow_waits_for_a_header_and_for_a_recorder_slower_than_the_idle_timeout(tmp_path):
    import threading
    import time

    whole = _fragmented_mp4(tmp_path / "whole.mp4")
    growing = tmp_path / "rec.mp4"
    ftyp = int.from_bytes(whole[:4], "big")
    growing.write_bytes(whole[:ftyp])  # only the 'ftyp' box: the header is still being written
    stop = threading.Event()
    # pauses of 0.9 s (under --idle-timeout 1), then of 2 s (over it, under 3 times the pauses seen)
    pauses = [0.9] * 4 + [2.0] * 4

    def record():
        with open(growing, "ab") as f:
            for i, pause in enumerate(pauses):
                if stop.wait(pause):
                    return
                f.write(whole[ftyp + i * (len(whole) - ftyp) // len(pauses):ftyp + (i + 1) * (len(whole) - ftyp) // len(pauses)])
                f.flush()

    t = threading.Thread(target=record, daemon=True)
    start = time.monotonic()
    t.start()
    try:
        p = subprocess.run([sys.executable, "-m", "wallcli", "count", str(growing), "--follow", "--idle-timeout", "1"],
                           capture_output=True, text=True, timeout=120)
    finally:
        stop.set()
        t.join(10)
    assert p.returncode == 0, p.stderr
    clip = json.loads(p.stdout.splitlines()[-1])
    assert clip["windows"][-1]["end"] == pytest.approx(20.0, abs=0.1)
    assert time.monotonic() - start >= sum(pauses)


def test_follow_default_idle_timeout_outlasts_a_5_s_flush(run_cli):
    code, out, _ = run_cli("count", "--help")
    assert code == 0 and "default: 15" in " ".join(out.split()).replace("[", "").lower()


# 8 ------------------------------------------------------------------ memory and interruption
def test_amplify_refuses_output_frames_beyond_two_4k_panels_up_front(tmp_path, run_cli, clip):
    code, out, err = run_cli("amplify", clip, tmp_path / "a.mp4", "--scale", "300")  # 9600x7200
    assert code == 2 and out == "" and "9600x7200" in _one_error(err) and "megapixels" in err
    assert sorted(p.name for p in tmp_path.iterdir()) == ["c.mkv"]


def test_a_writer_left_by_an_error_does_not_encode_what_its_encoder_holds(tmp_path):
    from wallcli.io.writer import VideoWriter

    calls = []

    class Counting:  # the stream, counting the encoder's drains (encode() with no frame)
        def __init__(self, stream):
            self._s = stream

        def encode(self, frame=None):
            calls.append(frame is None)
            return self._s.encode(frame)

    with pytest.raises(KeyboardInterrupt):
        with VideoWriter(tmp_path / "v.mp4", 30, 64, 48, preset="ultrafast") as w:
            w._stream = Counting(w._stream)
            for _ in range(5):
                w.write(np.zeros((48, 64, 3), np.uint8))
            raise KeyboardInterrupt
    assert calls and not any(calls)


def test_a_compressed_npz_that_unpacks_far_beyond_its_size_is_refused_before_reading(tmp_path, run_cli):
    import zipfile

    from numpy.lib import format as npy

    frames, bins = 400_000, 64  # 307 MB a plot once unpacked, a few hundred kB packed
    path = tmp_path / "bomb.npz"
    with zipfile.ZipFile(path, "w", zipfile.ZIP_DEFLATED, compresslevel=1) as zf:
        for name in ("horizontal", "vertical"):
            with zf.open(name + ".npy", "w", force_zip64=True) as f:
                npy.write_array_header_1_0(f, {"descr": "<f4", "fortran_order": False, "shape": (bins, frames, 3)})
                zeros = bytes(1 << 22)
                for _ in range(bins * frames * 3 * 4 // len(zeros)):
                    f.write(zeros)
        with zf.open("time.npy", "w") as f:
            npy.write_array(f, np.arange(frames) / 30.0)
        with zf.open("meta.npy", "w") as f:
            npy.write_array(f, np.array(json.dumps({"format": "wallcli.stplot", "format_version": 1, "bins": bins,
                                                    "fps": 30.0, "roi": [0, 0, 64, 48]})))
    code, out, err = run_cli("count", path, "--json")
    assert code == 1 and out == "" and "unpacks to" in _one_error(err) and "GB" in err


def test_a_pan_of_a_high_contrast_wall_is_not_read_as_still(tmp_path, run_cli):
    import cv2

    big = cv2.GaussianBlur(np.random.default_rng(0).normal(0, 1, (112, 136)).astype(np.float32), (0, 0), 2.0)
    big = 120 + 25 * big / big.std()  # a poster or brickwork: the texture is all 'edges' to the check

    def frame(i):
        dx = int(round(15 * np.sin(2 * np.pi * i / 60)))  # +-15 px
        return np.repeat(big[20:92, 20 + dx:116 + dx, None], 3, axis=2) + np.random.default_rng(i).normal(0, 1, (72, 96, 1))

    src = write_clip(tmp_path / "pan.mp4", frame, 120, fps=30)
    code, out, err = run_cli("snr", src, "--json")
    assert code == 0, err
    view = json.loads(out)["view"]
    assert view["issues"] and view["max_shift_px"] > 10, view


def test_scan_force_interrupted_before_a_line_leaves_the_old_results(tmp_path, clip):
    import signal
    import socket
    import time

    out = tmp_path / "keep.jsonl"
    out.write_text("old results\n")
    with socket.socket() as server:  # takes the connection, never answers Dask's handshake
        server.bind(("127.0.0.1", 0))
        server.listen(4)
        port = server.getsockname()[1]
        p = subprocess.Popen([sys.executable, "-m", "wallcli", "scan", str(clip), "-o", str(out), "--force",
                              "--scheduler", f"tcp://127.0.0.1:{port}"], stdout=subprocess.PIPE, stderr=subprocess.PIPE)
        server.settimeout(60)
        conn, _ = server.accept()  # scan is waiting for the handshake now
        time.sleep(0.5)
        p.send_signal(signal.SIGINT)
        _, err = p.communicate(timeout=60)
        conn.close()
    assert p.returncode == 1 and "interrupted" in _one_error(err.decode())
    assert out.read_text() == "old results\n"


def test_a_reader_that_leaves_early_is_an_error_even_unbuffered(tmp_path):
    from clips import write_plot

    plot = write_plot(tmp_path / "long.npz", seconds=900)  # --json of 200 kB: over a pipe's 64 kB
    p = subprocess.Popen([sys.executable, "-m", "wallcli", "count", str(plot), "--json"], stdout=subprocess.PIPE,
                         stderr=subprocess.PIPE, env={**os.environ, "PYTHONUNBUFFERED": "1"})
    assert p.stdout.read(1)  # `| head -c1`
    p.stdout.close()
    err = p.stderr.read().decode()
    assert p.wait(timeout=120) == 1 and "closed by its reader" in _one_error(err)
