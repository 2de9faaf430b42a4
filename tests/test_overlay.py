"""Burned-in overlays (a CCTV clock and a camera name, ``simulate --overlay``): found, masked out of
every analysis and listed in ``view.masked``; the same text moving through the view is an object
and stays refused."""

from __future__ import annotations

import json

import av
import numpy as np
import pytest

from clips import write_clip

SIM = ["--people", "1", "--activity", "walking", "--seed", "5", "--size", "160x120", "--duration", "9.5"]


@pytest.fixture(scope="module")
def stamped(tmp_path_factory):
    """One walker (seed 5, 160x120, 9.5 s, lossless), clean and with a clock and a camera name;
    and the clean frames with the clock's text sliding across the view (an object, not an overlay)."""
    from wallcli.cli.app import main
    from wallcli.sim.overlay import text_mask

    d = tmp_path_factory.mktemp("overlay")
    out = {}
    for name, extra in (("clean", []), ("overlay", ["--overlay", "--camera-name", "CAM 01"])):
        out[name] = d / f"{name}.mkv"
        with pytest.raises(SystemExit) as exc:
            main(["simulate", "-o", str(out[name]), *SIM, *extra])
        assert exc.value.code in (0, None)
    with av.open(str(out["clean"])) as c:
        frames = [f.to_ndarray(format="rgb24") for f in c.decode(video=0)]

    def moving(i):
        # the clock's text, moved 1 px a frame to the right and down a row every 8 frames
        f = frames[i].astype(np.float64)
        m = np.roll(np.roll(text_mask(120, 160, 0.0), i % 100, axis=1), 30 + i // 8 % 40, axis=0)
        f[m] = 255.0
        return f

    out["moving"] = write_clip(d / "moving.mkv", moving, len(frames), codec="ffv1", pix_fmt="yuv444p")
    return out


def _count(run_cli, path):
    code, out, err = run_cli("count", path, "--json")
    assert code == 0, err
    return json.loads(out)


def test_simulate_draws_the_clock_and_says_so(stamped):
    truth = json.loads(stamped["overlay"].with_suffix(".json").read_text())
    assert truth["overlay"] == "clock" and truth["camera_name"] == "CAM 01"
    with av.open(str(stamped["overlay"])) as c:
        a, b = [f.to_ndarray(format="rgb24").astype(int) for f, _ in zip(c.decode(video=0), range(31))][29:31]
    # the clock steps at 1 s (frame 30): only its top-left corner changes, by a text's contrast
    diff = np.abs(b - a).max(axis=2)
    assert diff[:20, :60].max() > 40 and diff[20:, :].max() < 40


def test_overlay_is_masked_listed_and_the_answer_is_the_clean_one(stamped, run_cli):
    clean, got = _count(run_cli, stamped["clean"]), _count(run_cli, stamped["overlay"])
    assert clean["view"]["usable"] and clean["view"]["masked"] == []
    # before: "moving object" at 1.3-2.1 s and four more spans, the clip refused
    assert got["view"]["usable"], got["view"]["reason"]
    boxes = [m["box"] for m in got["view"]["masked"]]
    assert all(m["kind"] == "overlay" for m in got["view"]["masked"])
    # the clock at the top left and the name at the bottom right, each in a box no larger than a line of text
    assert any(x < 10 and y < 10 for x, y, _, _ in boxes)
    assert any(x + w > 150 and y + h > 110 for x, y, w, h in boxes)
    assert all(h <= 24 and w <= 80 for _, _, w, h in boxes)
    assert got["label"] == clean["label"] == 1
    assert abs(got["signal_db"] - clean["signal_db"]) <= 3.0


def test_text_moving_through_the_view_is_still_an_object(stamped, run_cli):
    got = _count(run_cli, stamped["moving"])
    assert not got["view"]["usable"]
    assert "moving object" in got["view"]["issues"]
    assert got["view"]["masked"] == []


def test_snr_auto_roi_leaves_the_overlay_out(stamped, run_cli):
    code, out, err = run_cli("snr", stamped["overlay"], "--roi", "auto", "--json")
    assert code == 0, err
    got = json.loads(out)
    assert got["view"]["usable"] and got["view"]["masked"]
    x, y, w, h = got["roi"]
    for bx, by, bw, bh in (m["box"] for m in got["view"]["masked"]):
        assert bx >= x + w or bx + bw <= x or by >= y + h or by + bh <= y  # no overlap


def test_masked_box_follows_the_light_about_it():
    """A frame-wide gain ramp (exposure) goes on inside a masked box as outside: the box is no
    frozen patch that a change of light would make stand out."""
    from types import SimpleNamespace

    from wallcli.camera.overlay import OverlayFilter
    from wallcli.io.planes import Planes
    from wallcli.io.video import Frame
    from wallcli.sim.overlay import text_mask

    rng = np.random.default_rng(0)
    wall = 120 + 20 * rng.random((72, 96))

    def frame(i):
        y = wall * (1 + 0.002 * i) + rng.normal(0, 2, wall.shape)
        y[text_mask(72, 96, i / 30)] = 235
        return Frame(i, i / 30, Planes(y.astype(np.float32), None, None, "gray"))

    reader = SimpleNamespace(info=SimpleNamespace(fps=30), frames=lambda: (frame(i) for i in range(90)))
    f = OverlayFilter(reader)
    out = list(f.frames())
    assert len(out) == 90 and f.masked()
    x, y, w, h = f.masked()[0]["box"]
    inside = [float(o.planes.y[y:y + h, x:x + w].mean()) for o in out[60:]]
    # over the last second the light rose 6 %: the box rose with it (a frozen patch: 0 %)
    assert 0.04 < inside[-1] / inside[0] - 1 < 0.08


def test_date_and_time_through_h264_are_masked_whole(tmp_path, run_cli):
    """A wider frame (the date too) through H.264: the codec touches the static text now and
    then, and bold strokes are their own small neighbourhood; before, only the seconds were
    masked and the rest of the line read as a moving object when the light moved."""
    from wallcli.cli.app import main

    clip = tmp_path / "wide.mp4"
    with pytest.raises(SystemExit) as exc:
        main(["simulate", "-o", str(clip), "--people", "1", "--seed", "7", "--size", "640x480", "--duration", "9",
              "--overlay", "--camera-name", "CAM 01"])
    assert exc.value.code in (0, None)
    got = _count(run_cli, clip)
    assert got["view"]["usable"], got["view"]["reason"]
    top = [m["box"] for m in got["view"]["masked"] if m["box"][1] < 40]
    # the line of text runs from x = 12 to about 450: masked along most of it
    assert sum(w for _, _, w, _ in top) > 300


def test_the_clocks_first_steps_before_it_is_recognised_are_taken_back(tmp_path, run_cli):
    """The clock is only known for one after it has stepped a few times; those first steps were
    flagged as a moving object and refused the clip (a 160x120 H.264 walker, seed 3: 'moving
    object at 0.8-0.9 s', the overlay masked from 1.0 s). A real object's flags stay (the
    moving-text test above)."""
    from wallcli.cli.app import main

    clip = tmp_path / "early.mp4"
    with pytest.raises(SystemExit) as exc:
        main(["simulate", "-o", str(clip), "--people", "1", "--activity", "walking", "--seed", "3", "--size",
              "160x120", "--duration", "12", "--overlay", "--camera-name", "CAM 01"])
    assert exc.value.code in (0, None)
    got = _count(run_cli, clip)
    assert got["view"]["masked"], "the overlay was not found"
    assert got["view"]["usable"], got["view"]["reason"]
    assert "moving object" not in got["view"]["issues"]


def _gray_clock(n, fps=30, seed=1):
    """A noisy flat 96x72 wall with the clock (a step at every second) as a reader of n gray frames."""
    from types import SimpleNamespace

    from wallcli.io.planes import Planes
    from wallcli.io.video import Frame
    from wallcli.sim.overlay import text_mask

    rng = np.random.default_rng(seed)
    wall = 120 + 20 * rng.random((72, 96))

    def frame(i):
        y = wall + rng.normal(0, 2, wall.shape)
        y[text_mask(72, 96, i / fps)] = 235
        return Frame(i, i / fps, Planes(y.astype(np.float32), None, None, "gray"))

    return SimpleNamespace(info=SimpleNamespace(fps=fps), frames=lambda: (frame(i) for i in range(n)))


def test_a_clock_found_in_the_first_seconds_is_masked_from_the_clips_start():
    """The seconds digit is recognised at its first step (1 s) or later; the frames before are
    held back (decoded once), so the step at 1 s and every frame before it are masked too."""
    from wallcli.camera.overlay import OverlayFilter

    f = OverlayFilter(_gray_clock(150))
    out = list(f.frames())
    assert len(out) == 150 and [o.time for o in out] == [i / 30 for i in range(150)]
    masked = f.masked()
    # found at its first step (1 s) or later, masked from the first frame
    assert masked and all(m["masked_from"] == 0.0 and m["from"] >= 1.0 for m in masked)
    x, y, w, h = masked[0]["box"]
    box = np.stack([o.planes.y[y:y + h, x:x + w] for o in out[:60]]).astype(np.float32)
    # no step inside the box at 1 s (frame 30) nor anywhere in the first 2 s (a digit's step: about
    # 100 codes): what is left follows the light about the box (here its noise, under 2 codes);
    # before, frames 0-31 were handed on unmasked
    assert float(np.abs(np.diff(box, axis=0)).max()) < 5.0


def test_the_start_held_back_is_bounded():
    """At most HOLD_SECONDS of frames wait, whatever the clip's length: memory stays flat."""
    from wallcli.camera import overlay

    f = overlay.OverlayFilter(_gray_clock(600))
    most = 0
    for i, _ in enumerate(f.frames()):
        most = max(most, len(f._waiting))
    assert i == 599 and most <= overlay.HOLD_SECONDS * 30 + overlay.AFTER + 2


def test_a_steps_whole_text_line_is_masked_from_the_start():
    """On a wall a codec holds still (over half the frame unchanged, where the static finder says
    nothing), only the digits that step are found by their steps: the clock at 16:00:51 stepped its
    seconds from 1 s, and its tens of seconds and minute first at 9 s, after the start held back;
    before, they were masked only from 9 s. A step now grows to its whole line of text (the date
    and the time), masked from the clip's start."""
    from types import SimpleNamespace

    from wallcli.io.planes import Planes
    from wallcli.io.video import Frame
    from wallcli.camera.overlay import OverlayFilter
    from wallcli.sim.overlay import EPOCH, text_mask

    rng = np.random.default_rng(2)
    wall = np.round(110 + 20 * rng.random((60, 80)).repeat(8, 0).repeat(8, 1))

    def frame(i):
        y = np.array(wall)
        y[text_mask(480, 640, i / 30, start=EPOCH + 51)] = 235
        return Frame(i, i / 30, Planes(y.astype(np.uint8), None, None, "gray"))

    reader = SimpleNamespace(info=SimpleNamespace(fps=30), frames=lambda: (frame(i) for i in range(300)))
    f = OverlayFilter(reader)
    out = list(f.frames())
    masked = f.masked()
    assert masked and all(m["from"] < 2 and m["masked_from"] == 0.0 for m in masked), masked
    top = [m["box"] for m in masked if m["box"][1] < 60]
    # the line "2026-11-26 16:00:51" runs from x = 13 to about 450: all of it (before: the seconds, 55 px)
    assert min(x for x, _, _, _ in top) < 20 and max(x + w for x, _, w, _ in top) > 440
    band = np.stack([o.planes.y[10:70, :460] for o in out]).astype(np.float32)
    assert float(np.abs(np.diff(band, axis=0)).max()) < 1.0  # no step left anywhere in the line


def test_simulate_starts_the_clock_where_asked(tmp_path):
    """--clock-start: a recorder's clock does not read :00 at the clip's start; from 16:00:58 its
    tens of seconds and minute step at 2 s (a wider change than a seconds digit's)."""
    from wallcli.cli.app import main
    from wallcli.sim.overlay import EPOCH, text_mask

    clip = tmp_path / "late.mkv"
    with pytest.raises(SystemExit) as exc:
        main(["simulate", "-o", str(clip), *SIM[:-1], "3", "--overlay", "--clock-start", "16:00:58"])
    assert exc.value.code in (0, None)
    assert json.loads(clip.with_suffix(".json").read_text())["clock_start"] == "16:00:58"
    with av.open(str(clip)) as c:
        f = [x.to_ndarray(format="rgb24").astype(int) for x, _ in zip(c.decode(video=0), range(61))]
    start = EPOCH - EPOCH % 86400 + 16 * 3600 + 58
    for i in (0, 30, 60):  # the frames hold the clock's text from 16:00:58 on
        assert f[i][text_mask(120, 160, i / 30, start=start)].min() > 200
    # and not the default clock's: at 2 s it reads 16:00:02, whose strokes are not all drawn
    other = text_mask(120, 160, 2.0) & ~text_mask(120, 160, 2.0, start=start)
    assert other.any() and f[60][other].min() < 200
    with pytest.raises(SystemExit) as exc:
        main(["simulate", "-o", str(tmp_path / "bad.mkv"), *SIM, "--overlay", "--clock-start", "25:00:00"])
    assert exc.value.code not in (0, None)


@pytest.mark.parametrize("shape,top", [((90, 160), 256), ((91, 161), 10), ((3, 3), 2), ((1, 1), 256), ((2, 1), 5)])
def test_the_noise_figures_read_off_a_histogram_are_numpys(shape, top):
    """The step threshold's median and 90th percentile of 8-bit differences, read off their
    histogram (a tenth of sorting them), are numpy's order statistics exactly."""
    from wallcli.camera.overlay import _median_p90

    a = np.random.default_rng(sum(shape) + top).integers(0, top, shape).astype(np.uint8)
    median, p90 = _median_p90(a)
    assert median == float(np.median(a.astype(np.float32)))
    assert p90 == pytest.approx(float(np.percentile(a.astype(np.float32), 90)), abs=1e-4)
