"""wallcli snr: the estimator against clips of known signal and noise, the closed-form predictor,
--roi auto, the figures and bad input. Clips are lossless RGB (libx264rgb, qp 0) so the codec adds
nothing to the noise we put in; one yuv420p clip checks the chroma path against brute force."""

from __future__ import annotations

import json
import math

import numpy as np
import pytest
from clips import write_clip

from wallcli.io.video import open_video
from wallcli.snr.estimate import SnrAccumulator

T = 300
PERIOD = 40  # frames; the seed's estimator needs a slow signal (>= 30 frames)


def _lossless(path, fn, n=T):
    # libx264rgb at qp 0 stores 8-bit RGB losslessly (decoded as gbrp, no YUV round trip)
    return write_clip(path, fn, n, codec="libx264rgb", pix_fmt="rgb24", options={"qp": "0", "preset": "ultrafast"})


def _estimate(path, roi, **kw):
    with open_video(path) as r:
        acc = SnrAccumulator(roi, **kw)
        for f in r.frames():
            acc.update(f.planes)
    return acc.result()


@pytest.fixture(scope="module")
def gaussian_clip(tmp_path_factory):
    rng = np.random.default_rng(1)
    amp, sigma = 2.0, 1.5

    def fn(i):
        return 120.0 + amp * np.sin(2 * np.pi * i / PERIOD) + rng.normal(0, sigma, (48, 64, 3))

    path = _lossless(tmp_path_factory.mktemp("snr") / "gauss.mkv", fn)
    # 8-bit rounding adds 1/12 code value^2 of white noise (sigma >> 1 step)
    return path, amp**2 / 2, sigma**2 + 1 / 12


def test_gaussian_noise_and_signal_power(gaussian_clip):
    path, signal, noise = gaussian_clip
    res = _estimate(path, (0, 0, 64, 48))
    assert res.frames == T and res.exact and res.roi == (0, 0, 64, 48)
    top = res.scale(1)
    assert np.allclose(top.noise_power, noise, rtol=0.05), top.noise_power
    assert np.allclose(top.signal_power, signal, rtol=0.10), top.signal_power


def test_poisson_read_and_quantisation_noise(tmp_path):
    rng = np.random.default_rng(2)
    level, amp, gain, read = 60.0, 1.5, 20.0, 4.0  # code values; electrons per code value; electrons

    def fn(i):
        mean = level + amp * np.sin(2 * np.pi * i / 50)
        electrons = rng.poisson(mean * gain, (48, 64, 3)) + rng.normal(0, read, (48, 64, 3))
        return electrons / gain  # write_clip quantises to 8 bits, as the camera's ADC would

    path = _lossless(tmp_path / "poisson.mkv", fn)
    res = _estimate(path, (0, 0, 64, 48))
    truth_noise = level / gain + (read / gain) ** 2 + 1 / 12
    top = res.scale(1)
    assert np.allclose(top.noise_power, truth_noise, rtol=0.05), (top.noise_power, truth_noise)
    assert np.allclose(top.signal_power, amp**2 / 2, rtol=0.10), top.signal_power


def _brute_force(path, roi, block):
    """Per-pixel RGB (chroma sample covering each pixel), whole clip in memory, numpy var."""
    x, y, w, h = roi
    frames = []
    with open_video(path) as r:
        for f in r.frames():
            p = f.planes
            u = np.repeat(np.repeat(p.u, 2, 0), 2, 1)[: p.height, : p.width].astype(np.float64)
            v = np.repeat(np.repeat(p.v, 2, 0), 2, 1)[: p.height, : p.width].astype(np.float64)
            rgb = p.to_rgb(p.y.astype(np.float64), u, v).astype(np.float64)[y:y + h, x:x + w]
            bh, bw = h // block, w // block
            rgb = rgb[: bh * block, : bw * block].reshape(bh, block, bw, block, 3).mean(axis=(1, 3))
            frames.append(rgb)
    v = np.stack(frames)
    noise = 0.5 * np.diff(v, axis=0).var(axis=0, ddof=1).mean(axis=(0, 1))
    return v.var(axis=0, ddof=1).mean(axis=(0, 1)) - noise, noise


def test_yuv420_matches_brute_force_and_snaps_roi(tmp_path):
    rng = np.random.default_rng(3)
    yy, xx = np.mgrid[0:48, 0:64]

    def fn(i):
        wave = 3.0 * np.sin(2 * np.pi * (i / PERIOD - xx / 64.0))[..., None] * np.array([1.0, 0.5, -0.7])
        return 110.0 + 0.5 * xx[..., None] + wave + rng.normal(0, 2.0, (48, 64, 3))

    path = write_clip(tmp_path / "c420.mp4", fn, 60, pix_fmt="yuv420p")
    res = _estimate(path, (3, 5, 40, 30))
    assert res.roi == (4, 6, 38, 28)  # whole 2x2 chroma samples
    for block in (1, 2, 4):
        sig, noi = _brute_force(path, res.roi, block)
        s = res.scale(block)
        # float32 RGB (as Planes.to_rgb gives) differs from float64 at the 1e-5 level
        assert np.allclose(s.noise_power, noi, rtol=2e-4), (block, s.noise_power, noi)
        assert np.allclose(s.signal_power, sig, rtol=2e-4, atol=1e-4), (block, s.signal_power, sig)


@pytest.fixture(scope="module")
def white_clip(tmp_path_factory):
    rng = np.random.default_rng(4)
    sigma = 2.0
    path = _lossless(tmp_path_factory.mktemp("snr") / "white.mkv",
                     lambda i: 100.0 + rng.normal(0, sigma, (128, 128, 3)))
    return path, sigma**2 + 1 / 12


def test_block_scales_follow_white_noise_law(white_clip):
    path, noise = white_clip
    res = _estimate(path, (0, 0, 128, 128), max_pixels=0)
    assert [s.block for s in res.scales] == [1, 2, 4, 8, 16, 32]
    n1 = res.scale(1).noise_power
    assert np.allclose(n1, noise, rtol=0.05)
    for s in res.scales:
        ratio = s.noise_power * s.block**2 / n1
        assert np.allclose(ratio, 1.0, atol=0.10), (s.block, ratio)
        assert np.all(np.abs(s.signal_power) < 0.15 * s.noise_power), (s.block, s.signal_power)


def test_tile_lattice_sample_is_unbiased(white_clip):
    path, noise = white_clip
    res = _estimate(path, (0, 0, 128, 128), max_pixels=4096)
    assert not res.exact and res.sampled_pixels == 4096
    assert np.allclose(res.scale(1).noise_power, noise, rtol=0.05)
    assert np.allclose(res.scale(8).noise_power * 64, noise, rtol=0.10)


# ------------------------------------------------------------------------------------ CLI
CONTRACT = {"input", "roi", "frames", "channels", "signal_power", "noise_power", "snr_db", "scales"}


def test_cli_json_contract_and_figures(run_cli, gaussian_clip, tmp_path):
    path, signal, noise = gaussian_clip
    plot, heat = tmp_path / "s.png", tmp_path / "h.png"
    code, out, err = run_cli("snr", path, "--roi", "0,0,64,48", "--json", "--plot", plot, "--heatmap", heat)
    assert code == 0, err
    data = json.loads(out)
    assert CONTRACT <= set(data)
    assert data["roi"] == [0, 0, 64, 48] and data["frames"] == T and data["channels"] == ["r", "g", "b"]
    assert [s["block"] for s in data["scales"]] == [1, 2, 4, 8, 16, 32]
    assert data["scales"][0]["noise_power"] == data["noise_power"]
    assert all(set(s) >= {"block", "signal_power", "noise_power", "snr_db"} for s in data["scales"])
    db = 10 * math.log10(data["signal_power"][1] / data["noise_power"][1])
    assert data["snr_db"][1] == pytest.approx(db)
    for png in (plot, heat):
        assert png.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    code, out, _ = run_cli("snr", path)  # rich table on stdout
    assert code == 0 and "32x32" in out


def test_roi_auto_finds_the_signal_patch(run_cli, tmp_path):
    rng = np.random.default_rng(5)
    patch = (70, 10, 70, 70)  # x, y, w, h; on the 10-pixel candidate grid of a 160x96 frame, >= 64 px a side

    def fn(i):
        img = 90.0 + rng.normal(0, 1.0, (96, 160, 3))
        x, y, w, h = patch
        img[y:y + h, x:x + w] += 3.0 * np.sin(2 * np.pi * i / PERIOD)
        return img

    path = _lossless(tmp_path / "patch.mkv", fn)
    code, out, err = run_cli("snr", path, "--roi", "auto", "--json", "--heatmap", tmp_path / "h.png")
    assert code == 0, err
    data = json.loads(out)
    x, y, w, h = data["roi"]
    px, py, pw, ph = patch
    inter = max(0, min(x + w, px + pw) - max(x, px)) * max(0, min(y + h, py + ph) - max(y, py))
    assert inter / (w * h + pw * ph - inter) > 0.8, data["roi"]
    assert data["roi_mode"] == "auto" and data["snr_db"][1] > 0


def test_roi_auto_avoids_a_mover_in_view(run_cli, tmp_path):
    """A dark object pacing in the left of the view changes its pixels far more than the faint
    patch on the right: the view check marks where it went, and --roi auto picks the patch."""
    rng = np.random.default_rng(6)
    patch = (108, 36, 72, 72)  # x, y, w, h in a 192x128 frame (12-pixel cells; --roi auto takes >= 64 px)
    wall = 110.0 + 4.0 * rng.normal(0, 1.0, (128, 192, 1))  # some texture: an object has edges on it

    def fn(i):
        img = wall + rng.normal(0, 1.0, (128, 192, 3))
        x, y, w, h = patch
        img[y:y + h, x:x + w] += 3.0 * np.sin(2 * np.pi * i / PERIOD)
        if i >= 30:  # it walks in after a second, slowly back and forth over x = 8-70
            x0 = 8 + int(24 + 24 * np.sin(2 * np.pi * (i - 30) / 200))
            img[30:100, x0:x0 + 14] = 45.0
        return img

    path = _lossless(tmp_path / "mover.mkv", fn)
    heat = tmp_path / "where.png"
    code, out, err = run_cli("snr", path, "--roi", "auto", "--json", "--heatmap", heat)
    assert code == 0, err
    assert heat.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    data = json.loads(out)
    assert data["auto"]["avoided_cells"] > 0 and data["auto"]["avoided"] == ["moving object"], data["auto"]
    x, y, w, h = data["roi"]
    assert x >= 70, data["roi"]  # clear of everything the object covered (x < 70)
    px, py, pw, ph = patch
    inter = max(0, min(x + w, px + pw) - max(x, px)) * max(0, min(y + h, py + ph) - max(y, py))
    assert inter / (w * h) > 0.5, data["roi"]


def test_roi_auto_never_picks_a_sliver(run_cli):
    """On examples/walking.mp4 --roi auto chose a 10x40 px strip, which the plots' 64 bins
    spread over 10 pixels (count then said 2, not 1): the ROI is at least 64 px a side, as
    --help states."""
    from pathlib import Path

    clip = Path(__file__).resolve().parents[1] / "examples" / "walking.mp4"
    code, out, err = run_cli("snr", clip, "--roi", "auto", "--json")
    assert code == 0, err
    x, y, w, h = json.loads(out)["roi"]
    assert w >= 64 and h >= 64, (x, y, w, h)
    code, out, _ = run_cli("snr", "--help")
    assert "at least 64 px on each side" in " ".join(out.split())


def test_predict_equals_closed_forms(run_cli):
    d, r, a, lp, ls, q = 2.5, 0.3, 0.6, 30.0, 180.0, 0.4
    code, out, err = run_cli("snr", "--predict", "--json", "--distance", d, "--radius", r, "--albedo", a,
                             "--person-radiance", lp, "--background-radiance", ls, "--occupancy", q,
                             "--mean-code", 100, "--gain", 5, "--read-noise", 3, "--bits", 10,
                             "--pixels", 400, "--frames", 2)
    assert code == 0, err
    p = json.loads(out)
    signal = q * (a * r**2 / (r**2 + d**2) * (lp - ls)) ** 2
    noise = (100 / 5 + (3 / 5) ** 2 + (2.0 ** (8 - 10)) ** 2 / 12) / (400 * 2)
    assert p["signal_power"] == pytest.approx(signal, rel=1e-12)
    assert p["noise_power"] == pytest.approx(noise, rel=1e-12)
    assert p["snr_db"] == pytest.approx(10 * math.log10(signal / noise), rel=1e-12)
    area = 0.2
    code, out, _ = run_cli("snr", "--predict", "--json", "--approx", "--area", area, "--distance", d,
                           "--contrast", -50, "--albedo", a)
    p = json.loads(out)
    assert p["signal_power"] == pytest.approx((a * area / (math.pi * d**2) * -50) ** 2, rel=1e-12)


def test_predict_sweep(run_cli, tmp_path):
    code, out, err = run_cli("snr", "--predict", "--json", "--sweep", "distance=1:4:0.25", "--plot", tmp_path / "p.png")
    assert code == 0, err
    p = json.loads(out)
    assert p["sweep"]["values"] == pytest.approx(np.arange(1, 4.0001, 0.25).tolist())
    powers = [row["signal_power"] for row in p["rows"]]
    assert all(b < a for a, b in zip(powers, powers[1:]))  # fades with distance
    r, d = 0.25, 4.0
    assert powers[-1] == pytest.approx((0.7 * r**2 / (r**2 + d**2) * (20 - 200)) ** 2)
    assert (tmp_path / "p.png").exists()
    code, out, _ = run_cli("snr", "--predict", "--sweep", "read-noise=1:3:1", "--mean-code", 50, "--gain", 2)
    assert code == 0 and "read-noise" in out
    assert run_cli("snr", "--predict", "--sweep", "height=1:2:1")[0] == 2


@pytest.mark.parametrize("camera, quantity", [((), "signal power"), (("--mean-code", 120, "--gain", 4), "SNR")])
def test_a_sweep_plot_names_what_it_plots(run_cli, tmp_path, monkeypatch, camera, quantity):
    """Without a camera model the sweep plots signal power: the line on stderr, the axis and the
    title say so (stderr said 'predicted SNR' over a figure of signal power), with the x unit."""
    import wallcli.plots.snr as plots

    seen = {}
    real = plots.save_figure

    def keep(fig, path, **kw):
        ax = fig.axes[0]
        seen.update(x=ax.get_xlabel(), y=ax.get_ylabel(), title=ax.get_title(loc="left"))
        return real(fig, path, **kw)

    monkeypatch.setattr(plots, "save_figure", keep)
    code, _, err = run_cli("snr", "--predict", "--sweep", "distance=1:4:1", *camera, "--plot", tmp_path / "p.png")
    assert code == 0, err
    assert f"predicted {quantity} against distance" in err
    assert seen["y"].startswith(f"predicted {quantity}") and quantity in seen["title"]
    assert seen["x"] == "distance (m)"


def test_a_verdict_comes_first_and_tells_an_empty_room_from_a_walker(run_cli):
    """The 1x1 row reads 4.0 dB on the empty example and 4.1 dB on the walker: the first line says
    which one carries a wall signal (the one whose SNR grows with averaging) and at which block."""
    from pathlib import Path

    examples = Path(__file__).resolve().parents[1] / "examples"
    seen = {}
    for name in ("empty", "walking"):
        code, out, err = run_cli("snr", examples / f"{name}.mp4")
        assert code == 0, err
        headline, first = out.splitlines()[:2]  # the headline figure (issue 61), then the verdict
        assert headline.startswith("column SNR ") and len(headline) <= 80
        assert first.startswith("Verdict: ") and len(first) <= 80
        code, out, _ = run_cli("snr", examples / f"{name}.mp4", "--json")
        seen[name] = json.loads(out)["verdict"]
        assert seen[name]["text"] in " ".join(first.split())
    assert seen["empty"]["signal"] is False and "no wall signal" in seen["empty"]["text"]
    assert seen["walking"]["signal"] is True and seen["walking"]["block"] > 1
    assert f"{seen['walking']['block']}x{seen['walking']['block']}" in seen["walking"]["text"]


# ------------------------------------------------------------------------------------ bad input
def test_bad_input(run_cli, tmp_path, gaussian_clip):
    path, _, _ = gaussian_clip
    code, _, err = run_cli("snr", tmp_path / "missing.mp4")
    assert code == 1 and err.startswith("Error:") and "no such file" in err
    junk = tmp_path / "junk.mp4"
    junk.write_text("not a video at all\n" * 20)
    code, _, err = run_cli("snr", junk)
    assert code == 1 and "Error:" in err
    code, _, err = run_cli("snr", path, "--roi", "40,40,64,48")
    assert code == 1 and "64x48" in err
    code, _, err = run_cli("snr", path, "--roi", "1,2,3")
    assert code == 2
    assert run_cli("snr")[0] == 2  # no video and no --predict
    short = _lossless(tmp_path / "short.mkv", lambda i: np.full((16, 16, 3), 100.0 + i), n=2)
    code, out, err = run_cli("snr", short, "--json")
    assert code == 1 and "at least 3" in err and out == ""


def test_lattice_tiles_stay_on_whole_chroma_samples():
    # ROI height 130 (2 mod 4) centred a 128-row lattice at row 1: an odd luma row paired with
    # the wrong 4:2:0 chroma row. Every sampled pixel must get the chroma sample that covers it.
    from wallcli.io.video import Planes
    from wallcli.snr.estimate import Lattice

    lat = Lattice.plan((0, 0, 256, 130), 32768)
    assert not lat.exact and lat.oy % 2 == 0 and lat.ox % 2 == 0
    rng = np.random.default_rng(0)
    y = rng.integers(16, 235, (130, 256), dtype=np.uint8)
    u = rng.integers(16, 240, (65, 128), dtype=np.uint8)
    v = rng.integers(16, 240, (65, 128), dtype=np.uint8)
    planes = Planes(y, u, v, kind="yuv", sub_x=1, sub_y=1)
    acc = SnrAccumulator((0, 0, 256, 130))
    acc.update(planes)
    got = acc._rgb(planes)  # (3, nty, th, ntx, tw)
    rows = lat.oy + np.arange(lat.nty)[:, None] * lat.step_y + np.arange(lat.th)[None, :]
    cols = lat.ox + np.arange(lat.ntx)[:, None] * lat.step_x + np.arange(lat.tw)[None, :]
    r, c = rows.reshape(-1)[:, None], cols.reshape(-1)[None, :]
    want = planes.to_rgb(y[r, c].astype(float), u[r // 2, c // 2].astype(float), v[r // 2, c // 2].astype(float))
    want = want.reshape(lat.nty, lat.th, lat.ntx, lat.tw, 3).transpose(4, 0, 1, 2, 3)
    off = planes.to_rgb(np.zeros(1), np.zeros(1), np.zeros(1))[0]  # _rgb drops the affine offset
    assert np.abs(got + off[:, None, None, None, None] - want).max() < 0.05  # float32 rounding only



def test_predict_names_the_unit_of_every_quantity(run_cli):
    import json

    code, out, _ = run_cli("snr", "--predict", "--distance", "2", "--mean-code", "128", "--gain", "4")
    rows = {line.split()[0]: line for line in out.splitlines()[3:] if line.strip()}
    assert code == 0 and "unit" in out
    assert "code values²" in rows["signal_power"] and "code values" in rows["amplitude"] and "dB" in rows["snr_db"]
    assert "fraction" in rows["theta"]
    code, out, _ = run_cli("snr", "--predict", "--distance", "2", "--json")
    got = json.loads(out)
    assert got["units"] == {"theta": "fraction of view blocked", "amplitude": "code values",
                            "signal_power": "code values²"}
    code, out, _ = run_cli("snr", "--predict", "--distance", "2", "--sweep", "distance=1:2:1", "--mean-code", "128",
                           "--gain", "4")
    flat = " ".join(out.split())
    assert code == 0 and "amplitude (cv)" in flat and "(cv²)" in flat and "code values of an 8-bit video" in flat
