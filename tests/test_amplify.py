"""`wallcli amplify` and the streaming Amplifier: a sub-code-value shadow becomes plainly visible."""

from __future__ import annotations

from fractions import Fraction
from pathlib import Path

import av
import numpy as np
import pytest

from clips import write_clip
from wallcli.signal.amplify import Amplifier, grid_shape, render_panel

W, H, N = 96, 64, 48
FPS = Fraction(24000, 1001)  # a non-integer rate: must come out exactly as it went in
SHADOW_AMP = 0.5  # code values, under per-pixel noise of sigma 1.5
SHADOW_WIDTH = 6.0


def _pos(i: int) -> float:
    return 15.0 + (W - 30.0) * i / (N - 1)  # sweeps left to right over the clip


def _shadow(i: int, width: int = W) -> np.ndarray:
    xs = (np.arange(width) + 0.5) * (W / width) - 0.5
    return np.exp(-0.5 * ((xs - _pos(i)) / SHADOW_WIDTH) ** 2)


@pytest.fixture(scope="module")
def shadow_clip(tmp_path_factory) -> Path:
    rng = np.random.default_rng(7)
    base = np.full((H, W, 3), 118.0) + np.linspace(-15, 15, W)[None, :, None]

    def frame(i):
        noise = rng.normal(0.0, 1.5, (H, W, 1))  # same noise in R, G, B (luma-like sensor noise)
        return base - SHADOW_AMP * _shadow(i)[None, :, None] + noise

    # Lossless H.264: the only rounding is the camera's own 8-bit quantisation (as in write_clip).
    return write_clip(tmp_path_factory.mktemp("amp") / "shadow.mp4", frame, N, fps=FPS,
                      options={"crf": "0", "preset": "ultrafast"})


def _read(path: Path) -> tuple[list[np.ndarray], Fraction]:
    with av.open(str(path)) as c:
        rate = c.streams.video[0].average_rate
        return [f.to_ndarray(format="rgb24").astype(np.float64) for f in c.decode(video=0)], Fraction(rate)


def _leftovers(folder: Path, keep: set[str]) -> list[str]:
    return sorted(p.name for p in folder.iterdir() if p.name not in keep)


def test_shadow_becomes_visible(shadow_clip, run_cli, tmp_path):
    out = tmp_path / "amp.mp4"
    code, stdout, err = run_cli("amplify", shadow_clip, out, "--cells", "16", "--json")
    assert code == 0, err
    frames, rate = _read(out)
    assert len(frames) == N
    assert rate == FPS
    assert frames[0].shape == (H, W, 3)
    assert _leftovers(tmp_path, {"amp.mp4"}) == []  # no temp file left beside the output
    # The first frame is neutral grey, not a blinding flash (the mean starts from it).
    assert abs(frames[0].mean() - 128) < 2 and frames[0].std() < 2
    corr, depth = [], []
    for i in range(N // 2, N):
        profile = frames[i].mean(axis=(0, 2)) - 128.0
        corr.append(np.corrcoef(profile, -_shadow(i))[0, 1])
        depth.append(-profile[int(round(_pos(i)))])
    # Input: the shadow is a third of a code value deep under noise 1.5. Output: tens of levels.
    assert np.mean(corr) > 0.75, corr
    assert np.median(depth) > 20, depth
    import json

    summary = json.loads(stdout)
    assert summary["frames"] == N and summary["gain_mode"] == "auto" and summary["gain"] > 10


def test_control_without_shadow_stays_uncorrelated(tmp_path, run_cli):
    rng = np.random.default_rng(3)
    clip = write_clip(tmp_path / "flat.mp4", lambda i: np.full((H, W, 3), 118.0) + rng.normal(0, 1.5, (H, W, 1)),
                      N, fps=FPS, options={"crf": "0", "preset": "ultrafast"})
    out = tmp_path / "flat-amp.mp4"
    code, _, err = run_cli("amplify", clip, out, "--cells", "16")
    assert code == 0, err
    frames, _ = _read(out)
    corr = [np.corrcoef(frames[i].mean(axis=(0, 2)), -_shadow(i))[0, 1] for i in range(N // 2, N)]
    assert abs(np.mean(corr)) < 0.4


def test_side_by_side_and_scale(shadow_clip, run_cli, tmp_path):
    out = tmp_path / "sbs.mp4"
    code, _, err = run_cli("amplify", shadow_clip, out, "--side-by-side", "--scale", "0.5", "--cells", "16")
    assert code == 0, err
    frames, rate = _read(out)
    assert len(frames) == N and rate == FPS
    assert frames[0].shape == (H // 2, W, 3)  # each panel halved, two panels side by side
    # Left panel: the original (a bright gradient); right: grey-centred signal.
    left, right = frames[-1][:, : W // 2], frames[-1][:, W // 2:]
    assert abs(left.mean() - 118) < 6
    assert abs(np.median(right) - 128) < 12

    out2 = tmp_path / "big.mp4"
    code, _, err = run_cli("amplify", shadow_clip, out2, "--scale", "130x70", "--roi", "8,4,64,48")
    assert code == 0, err
    frames2, _ = _read(out2)
    assert frames2[0].shape == (70, 130, 3) and len(frames2) == N


def test_given_gain_is_linear(shadow_clip, run_cli, tmp_path):
    devs = {}
    for g in ("20", "80"):
        out = tmp_path / f"g{g}.mp4"
        code, _, err = run_cli("amplify", shadow_clip, out, "--gain", g, "--cells", "8", "--smooth", "0.05")
        assert code == 0, err
        frames, _ = _read(out)
        devs[g] = np.mean([np.abs(f - 128).mean() for f in frames[N // 2:]])
    assert 2.5 < devs["80"] / devs["20"] < 5.0, devs  # 4x the gain -> ~4x the deviation (some clipping)


def test_amplifier_warm_up_and_calibration():
    rng = np.random.default_rng(0)
    amp = Amplifier(calib_frames=10, mean_seconds=5.0)
    level = 200.0 + 30.0 * rng.random((6, 8, 3))  # a bright, textured wall: all of it must vanish
    out = []
    for i in range(25):
        got = amp.push(i / 30, level + rng.normal(0, 0.1, level.shape), payload=i)
        assert got == [] or i >= 9  # held back until the gain is known, then released in order
        out += got
    out += amp.flush()
    assert [p for p, _ in out] == list(range(25))
    np.testing.assert_allclose(out[0][1], 128.0)  # frame 0: the mean is that frame
    spreads = np.array([np.abs(d - 128).max() for _, d in out[1:]])
    # +-3 robust sigma maps to +-127: noise stays mostly inside the range from the very start.
    assert spreads.max() < 400 and np.median(spreads) < 200
    assert amp.sigma == pytest.approx(0.1, rel=0.35)
    # A shorter clip than the calibration still gets a gain, at flush.
    short = Amplifier(calib_frames=100)
    assert short.push(0.0, level) == [] and short.push(0.04, level + 1) == []
    assert len(short.flush()) == 2 and short.gain is not None


def test_grid_and_render_helpers():
    assert grid_shape(1920, 1080, 64) == (36, 64)
    assert grid_shape(100, 400, 64) == (64, 16)
    assert grid_shape(10, 5, 64) == (5, 10)  # never more blocks than pixels
    d = np.array([[[-100.0, 128.0, 400.0], [128.0, 128.0, 128.0]]], np.float32)
    img = render_panel(d, 4, 2)
    assert img.dtype == np.uint8 and img.shape == (2, 4, 3)
    assert img[0, 0, 0] == 0 and img[0, 0, 2] == 255 and img[0, -1, 1] == 128


@pytest.mark.parametrize("case", ["missing", "not_video", "one_frame", "exists", "no_folder", "roi"])
def test_bad_input(case, shadow_clip, run_cli, tmp_path):
    src, out = shadow_clip, tmp_path / "out.mp4"
    extra: list[str] = []
    if case == "missing":
        src = tmp_path / "nope.mp4"
    elif case == "not_video":
        src = tmp_path / "text.mp4"
        src.write_text("hello, not a video\n")
    elif case == "one_frame":  # discovered only at the end of the stream: the temp file must go
        src = write_clip(tmp_path / "one.mp4", lambda i: np.full((16, 16, 3), 100.0), 1)
    elif case == "exists":
        out.write_bytes(b"keep me")
    elif case == "no_folder":
        out = tmp_path / "missing-dir" / "out.mp4"
    elif case == "roi":
        extra = ["--roi", "90,0,20,20"]
    before = set(p.name for p in tmp_path.iterdir())
    code, stdout, err = run_cli("amplify", src, out, *extra)
    assert code == 1
    assert stdout == ""
    lines = err.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith("Error:"), err
    assert set(p.name for p in tmp_path.iterdir()) == before  # nothing new, no temp files
    if case == "exists":
        assert out.read_bytes() == b"keep me"
        code, _, err = run_cli("amplify", src, out, "--force", "--cells", "8")
        assert code == 0, err
        assert len(_read(out)[0]) == N
    if case == "roi":
        assert f"{W}x{H}" in err
