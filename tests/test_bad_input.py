"""Bad input: one 'Error:' line on stderr, a non-zero exit code, no traceback, no output left behind."""

import numpy as np
import pytest

from clips import write_clip


def _ok_clip(path, n=30):
    return write_clip(path, lambda i: np.full((48, 64, 3), 100.0 + i % 3), n)


def _assert_clean_failure(code, out, err, tmp_path, expected_code=1, keep=()):
    assert code == expected_code, (code, err)
    lines = err.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith("Error:"), err
    assert "Traceback" not in err and out == ""
    leftovers = [p.name for p in tmp_path.iterdir() if p.name not in keep]
    assert leftovers == [], leftovers


def test_missing_file(tmp_path, run_cli):
    code, out, err = run_cli("stplot", tmp_path / "nope.mp4", "-o", tmp_path / "p.npz")
    _assert_clean_failure(code, out, err, tmp_path)
    assert "no such file" in err


@pytest.mark.parametrize("content,word", [(b"hello, I am text\n" * 20, "not a readable video"), (b"", "empty")])
def test_not_a_video(tmp_path, run_cli, content, word):
    bad = tmp_path / "bad.mp4"
    bad.write_bytes(content)
    code, out, err = run_cli("stplot", bad, "-o", tmp_path / "p.npz")
    _assert_clean_failure(code, out, err, tmp_path, keep={"bad.mp4"})
    assert word in err


def test_mp4_cut_in_half(tmp_path, run_cli):
    clip = _ok_clip(tmp_path / "half.mp4", 60)
    data = clip.read_bytes()
    clip.write_bytes(data[: len(data) // 2])  # the index (moov) is at the end: nothing is decodable
    code, out, err = run_cli("stplot", clip, "-o", tmp_path / "p.npz")
    _assert_clean_failure(code, out, err, tmp_path, keep={"half.mp4"})


def test_one_frame_video(tmp_path, run_cli):
    clip = _ok_clip(tmp_path / "one.mp4", 1)
    code, out, err = run_cli("stplot", clip, "-o", tmp_path / "p.npz")
    _assert_clean_failure(code, out, err, tmp_path, keep={"one.mp4"})
    assert "at least 2" in err


@pytest.mark.parametrize("roi", ["40,0,64,48", "0,0,0,10", "-1,0,10,10"])
def test_roi_outside_frame(tmp_path, run_cli, roi):
    clip = _ok_clip(tmp_path / "c.mp4", 5)
    code, out, err = run_cli("stplot", clip, "-o", tmp_path / "p.npz", "--roi", roi)
    _assert_clean_failure(code, out, err, tmp_path, keep={"c.mp4"})
    assert "64x48" in err


def test_malformed_roi_is_a_usage_error(tmp_path, run_cli):
    clip = _ok_clip(tmp_path / "c.mp4", 5)
    code, out, err = run_cli("stplot", clip, "-o", tmp_path / "p.npz", "--roi", "1,2,3")
    _assert_clean_failure(code, out, err, tmp_path, expected_code=2, keep={"c.mp4"})


def test_output_folder_missing(tmp_path, run_cli):
    clip = _ok_clip(tmp_path / "c.mp4", 5)
    code, out, err = run_cli("stplot", clip, "-o", tmp_path / "nowhere" / "p.npz")
    _assert_clean_failure(code, out, err, tmp_path, keep={"c.mp4"})
    assert "does not exist" in err


def test_existing_output_needs_force(tmp_path, run_cli):
    clip = _ok_clip(tmp_path / "c.mp4", 5)
    out_path = tmp_path / "p.npz"
    out_path.write_bytes(b"precious")
    code, out, err = run_cli("stplot", clip, "-o", out_path)
    _assert_clean_failure(code, out, err, tmp_path, keep={"c.mp4", "p.npz"})
    assert out_path.read_bytes() == b"precious" and "--force" in err
    code, _, err = run_cli("stplot", clip, "-o", out_path, "--force")
    assert code == 0, err
    assert out_path.read_bytes()[:2] == b"PK"


def test_output_is_never_the_input(tmp_path, run_cli):
    clip = _ok_clip(tmp_path / "c.mp4", 5).rename(tmp_path / "c.npz")  # a video named .npz
    before = clip.read_bytes()
    code, out, err = run_cli("stplot", clip, "-o", clip, "--force")
    _assert_clean_failure(code, out, err, tmp_path, keep={"c.npz"})
    assert clip.read_bytes() == before


def test_corrupt_npz(tmp_path):
    from wallcli.errors import WallcliError
    from wallcli.io.arrays import load_npz

    bad = tmp_path / "p.npz"
    bad.write_bytes(b"PK\x03\x04 this zip is broken")
    with pytest.raises(WallcliError, match="not a readable .npz"):
        load_npz(bad)


def test_non_zip_npz_is_refused_without_unpickling_advice(tmp_path):
    import pickle

    from wallcli.errors import WallcliError
    from wallcli.io.arrays import load_npz

    evil = tmp_path / "p.npz"
    evil.write_bytes(pickle.dumps({"format": "wallcli.stplot"}))
    with pytest.raises(WallcliError, match="not a readable .npz") as info:
        load_npz(evil)
    assert "pickle" not in str(info.value)


def test_pickled_npz_is_refused(tmp_path):
    from wallcli.errors import WallcliError
    from wallcli.io.arrays import load_npz

    evil = tmp_path / "p.npz"
    np.savez(evil, meta=np.array([{"format": "wallcli.stplot"}], dtype=object))
    with pytest.raises(WallcliError):
        load_npz(evil)


def test_debug_env_shows_traceback(tmp_path, run_cli, monkeypatch):
    from wallcli.errors import WallcliError

    monkeypatch.setenv("WALLCLI_DEBUG", "1")
    with pytest.raises(WallcliError):
        run_cli("stplot", tmp_path / "nope.mp4", "--json")


@pytest.mark.parametrize("signame", ["SIGTERM", "SIGINT"])
def test_sigterm_removes_the_temporary_output(tmp_path, signame):
    # `kill PID` must unwind like Ctrl-C: one error line, exit 1 (not death by a signal: see
    # wallcli.errors.Interrupted), and no `.NAME.XXXX.tmp.mp4` left behind.
    import signal
    import subprocess
    import sys
    import time

    out = tmp_path / "v.mp4"
    proc = subprocess.Popen([sys.executable, "-m", "wallcli", "simulate", "-o", str(out), "--size", "64x48",
                             "--duration", "600", "--grid", "8x8"],
                            stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    deadline = time.monotonic() + 60
    while not list(tmp_path.glob(".v.*.tmp.mp4")) and time.monotonic() < deadline and proc.poll() is None:
        time.sleep(0.05)
    assert list(tmp_path.glob(".v.*.tmp.mp4")), "the temporary output never appeared"
    proc.send_signal(getattr(signal, signame))
    stdout, stderr = proc.communicate(timeout=60)
    assert proc.returncode == 1 and stdout == ""
    assert stderr.strip().splitlines() == ["Error: interrupted"]
    assert list(tmp_path.iterdir()) == []
