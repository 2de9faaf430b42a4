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
    # --smooth 0 given: this shadow crosses the frame in 2 s, faster than the smoothing the
    # automatic choice would add (it lags the moving edge); the chosen defaults are tested below
    code, stdout, err = run_cli("amplify", shadow_clip, out, "--cells", "16", "--smooth", "0", "--json")
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
    code, _, err = run_cli("amplify", shadow_clip, out, "--side-by-side", "--scale", "0.5", "--cells", "16",
                             "--smooth", "0")
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
    amp = Amplifier(calib_frames=10, mean_seconds=5.0, colour=True)  # per channel: sigma is each channel's
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


# -- issue 46 item 11: the defaults are chosen from the clip's own signal and noise -------------
EXAMPLES = Path(__file__).resolve().parent.parent / "examples"


def _strip_snr(path: Path, skip: int = 60) -> np.ndarray:
    """Per vertical strip (4 across) of the output: the amplified signal averaged over the strip
    and over each second, its spread over time, against the frame-to-frame noise of the strip's
    mean (std of consecutive differences / sqrt 2). The first ``skip`` frames (the calibration
    window, the mean still settling) are left out."""
    frames, _ = _read(path)
    x = np.array(frames[skip:], np.float32) - 128.0
    out = []
    for k in range(4):
        w = x.shape[2] // 4
        r = x[:, :, k * w:(k + 1) * w].mean(axis=(1, 2, 3))
        seconds = r[: len(r) // 30 * 30].reshape(-1, 30).mean(axis=1)
        out.append(np.std(seconds) / (np.std(np.diff(r)) / np.sqrt(2)))
    return np.array(out)


def test_defaults_show_the_walker_on_walking_mp4(run_cli, tmp_path):
    """At its defaults, amplify on examples/walking.mp4 chooses coarser blocks and smoothing from
    the measured SNR, and the person's light stands well above the output's frame-to-frame noise:
    far more than with the old defaults (--cells 64 --smooth 0), and more than the same defaults
    give on examples/empty.mp4 (the same room, nobody in it)."""
    import json

    new, old, empty = tmp_path / "new.mp4", tmp_path / "old.mp4", tmp_path / "empty.mp4"
    code, stdout, err = run_cli("amplify", EXAMPLES / "walking.mp4", new, "--json")
    assert code == 0, err
    chosen = json.loads(stdout)
    assert chosen["cells_mode"] == "auto" and chosen["smooth_mode"] == "auto" and chosen["gain_mode"] == "auto"
    assert chosen["cells"] < 64 and chosen["smooth"] > 0, chosen
    assert chosen["snr_db"] >= 12.0 and chosen["snr_db"] > chosen["tried"][0]["snr_db"] + 6, chosen
    assert chosen["tried"][0] == {"cells": 64, "smooth": 0.0, "snr_db": chosen["tried"][0]["snr_db"]}
    assert f"{chosen['cells']} columns" in " ".join(err.split())
    code, _, err = run_cli("amplify", EXAMPLES / "walking.mp4", old, "--cells", "64", "--smooth", "0")
    assert code == 0, err
    code, _, err = run_cli("amplify", EXAMPLES / "empty.mp4", empty)
    assert code == 0, err
    s_new, s_old, s_empty = _strip_snr(new), _strip_snr(old), _strip_snr(empty)
    assert len(_read(new)[0]) == 360
    assert s_new.min() > 12 and s_new.min() > 3 * s_old.max(), (s_new, s_old)
    assert np.median(s_new) > 2 * np.median(s_empty), (s_new, s_empty)


def test_given_cells_and_smooth_win(run_cli, tmp_path):
    """An explicit --cells and/or --smooth is used as given; only what is left out is chosen."""
    import json

    clip = EXAMPLES / "walking.mp4"
    code, stdout, err = run_cli("amplify", clip, tmp_path / "a.mp4", "--cells", "64", "--smooth", "0", "--json")
    assert code == 0, err
    both = json.loads(stdout)
    assert (both["cells"], both["smooth"], both["grid"]) == (64, 0.0, [48, 64])
    assert both["cells_mode"] == both["smooth_mode"] == "given" and both["tried"] == []
    code, stdout, err = run_cli("amplify", clip, tmp_path / "b.mp4", "--cells", "16", "--gain", "300", "--json")
    assert code == 0, err
    cells = json.loads(stdout)
    assert (cells["cells"], cells["cells_mode"], cells["grid"]) == (16, "given", [12, 16])
    assert cells["smooth_mode"] == "auto" and {t["cells"] for t in cells["tried"]} == {16}
    assert cells["gain"] == 300 and cells["gain_mode"] == "fixed"
    code, stdout, err = run_cli("amplify", clip, tmp_path / "c.mp4", "--smooth", "0.05", "--json")
    assert code == 0, err
    smooth = json.loads(stdout)
    assert smooth["smooth"] == 0.05 and smooth["smooth_mode"] == "given" and smooth["cells_mode"] == "auto"
    assert {t["smooth"] for t in smooth["tried"]} == {0.05}
    # given both, the output is the one those options always gave: the same video either way
    code, _, err = run_cli("amplify", clip, tmp_path / "d.mp4", "--cells", "16", "--smooth", "0.3", "--gain", "300")
    assert code == 0, err
    code, _, err = run_cli("amplify", clip, tmp_path / "e.mp4", "--smooth", "0.3", "--cells", "16", "--gain", "300",
                           "--gain-seconds", "5")
    assert code == 0, err
    assert (tmp_path / "d.mp4").read_bytes() == (tmp_path / "e.mp4").read_bytes()


def test_measured_snr_follows_the_noise_and_the_smoothing():
    """measured_snr_db: a slow signal under white noise reads its true SNR; smoothing raises it
    by the noise share the low-pass removes; noise alone reads far below the target."""
    from wallcli.signal.amplify import TARGET_SNR_DB, auto_steps, choose_step, measured_snr_db

    rng = np.random.default_rng(5)
    t = np.arange(90) / 30.0
    slow = np.sin(2 * np.pi * 0.5 * t)[:, None, None, None] * np.ones((1, 6, 8, 3))
    noise = rng.normal(0, 0.5, slow.shape)
    snr0 = measured_snr_db(t, slow + noise, 0.0)
    assert snr0 == pytest.approx(10 * np.log10(0.5 / 0.25), abs=1.0)
    assert measured_snr_db(t, slow + noise, 0.3) > snr0 + 8
    assert measured_snr_db(t, noise, 0.0) < 0 and measured_snr_db(t, noise, 0.3) < TARGET_SNR_DB
    steps = auto_steps(None, None)
    assert steps[0] == (64, 0.0) and auto_steps(16, None) == [(16, s) for s in (0.0, 0.1, 0.2, 0.3, 0.5)]
    assert auto_steps(8, 0.2) == [(8, 0.2)]
    assert choose_step(steps, {st: (20.0 if st == (16, 0.2) else 3.0) for st in steps}) == (16, 0.2)
    assert choose_step(steps, {st: float(i) for i, st in enumerate(steps)}) == steps[-1]


def test_automatic_gain_keeps_pure_noise_near_grey():
    """On blocks of noise alone (an empty room), full scale is at least NOISE_FULL_SCALE noise
    sigmas: the noise is shown as speckle of at most +-127/NOISE_FULL_SCALE levels, not stretched
    into bright blobs that would look like people."""
    import numpy as np

    from wallcli.signal.amplify import NOISE_FULL_SCALE, AutoAmplifier

    rng = np.random.default_rng(3)
    amp = AutoAmplifier(calib_frames=60)
    shown = []
    for i in range(120):
        grids = {c: (100.0 + rng.normal(0, 1.0, (max(c * 3 // 4, 1), c, 3))).astype(np.float32) for c in amp.wanted}
        shown += [d for _, d in amp.push(i / 30, grids)]
    shown += [d for _, d in amp.flush()]
    late = np.stack(shown[60:]) - 128.0
    assert amp.gain is not None and late.std() <= 127.0 / 10 * 1.3
