"""Nuisances removed before analysis (issue 27 point 2): aliased mains flicker (whole-frame and
rolling-shutter bands), exposure steps and drift; what a person does to the wall is kept.

Unit tests on synthetic profiles, then a simulated clip with each nuisance injected at a stated
strength (``wallcli.sim.inject``: the same frames and camera noise): the answers of the clean clip
are kept and the SNR estimate stays within 10 %. The rate over many clips is in
research/corrections/README.md.
"""
import json

import numpy as np
import pytest

from wallcli.camera import corrections as C

T, B, FPS = 256, 64, 30.0
t = np.arange(T) / FPS


def _wall(rng, person=None):
    """(T, 2B) levels: horizontal then vertical bins of a lit wall, camera noise, and a person."""
    level = 100 + 20 * np.sin(np.linspace(0, 3, 2 * B))
    x = level[None] * (1 + (person if person is not None else 0.0))
    return x + rng.standard_normal((T, 2 * B)) * 0.05


def _walker(amp=0.005):
    """A broad shadow sweeping along the horizontal bins and down the vertical ones."""
    pos = np.linspace(5, 55, T)[:, None]
    bins = np.arange(B)[None]
    h = -amp * np.exp(-0.5 * ((bins - pos) / 6) ** 2)
    v = -amp * np.exp(-0.5 * ((bins - 40) / 15) ** 2) * np.exp(-0.5 * ((pos - 30) / 12) ** 2)
    return np.concatenate([h, v], axis=1)


PART = np.repeat([0, 1], B)
VERT = slice(B, 2 * B)


def _residual(corrected, truth):
    """RMS of what the correction left, relative to the person's signal."""
    a, b = corrected - corrected.mean(0), truth - truth.mean(0)
    return float(np.std(a - b) / max(np.std(b), 1e-12))


def test_mains_lines_are_where_the_camera_aliases_100_and_120_hz():
    assert C.mains_lines(30, 30) == [10.0]  # 100 Hz -> 10 Hz; 120 Hz -> 0 (no flicker)
    assert C.mains_lines(25, 30) == [5.0]  # 120 Hz -> 5 Hz; 100 Hz -> 0
    assert C.mains_lines(24, 30) == [4.0]
    assert C.mains_lines(60, 30) == [10.0]  # 100 Hz -> 20 Hz at 60 fps, 10 Hz once resampled to 30
    assert C.mains_lines(29.97, 29.97) == [pytest.approx(10.09)]  # 120 Hz -> 0.12 Hz: drift's business


def test_a_whole_frame_flicker_line_is_found_and_removed():
    rng = np.random.default_rng(0)
    clean = _wall(rng, _walker())
    x = clean * (1 + 0.01 * np.sin(2 * np.pi * 10 * t + 1))[:, None]
    fit = C.fit(x, FPS, lines=[10.0], vertical=VERT, part=PART)
    (f,) = fit.findings
    assert f["kind"] == "flicker" and f["hz"] == pytest.approx(10.0, abs=0.02)
    assert f["amplitude"] == pytest.approx(0.01, rel=0.05) and not f["rolling_shutter"]
    assert _residual(x / (1 + fit.gain), clean) < 0.05


def test_rolling_shutter_bands_are_found_and_removed():
    rng = np.random.default_rng(1)
    clean = _wall(rng, _walker())
    phase = 2 * np.pi * 10 * t[:, None] + np.zeros((1, 2 * B))
    phase[:, B:] += 2 * np.pi * 2.5 * (np.arange(B) + 0.5) / B  # bands down the vertical profile
    x = clean * (1 + 0.01 * np.sin(phase))
    fit = C.fit(x, FPS, lines=[10.0], vertical=VERT, part=PART)
    (f,) = fit.findings
    assert f["rolling_shutter"] and f["bands"] == pytest.approx(2.5, abs=0.2)
    assert _residual(x / (1 + fit.gain), clean) < 0.05


def test_an_exposure_step_is_found_and_removed():
    rng = np.random.default_rng(2)
    clean = _wall(rng, _walker())
    ramp = np.clip((t - 4.0) / 0.1, 0, 1)
    x = clean * (1 + 0.02 * ramp)[:, None]
    fit = C.fit(x, FPS, lines=[10.0], t0=10.0, vertical=VERT, part=PART)
    (f,) = fit.findings
    assert f["kind"] == "exposure"
    (step,) = f["steps"]
    assert step["time"] == pytest.approx(14.0, abs=0.1) and step["size"] == pytest.approx(0.02, rel=0.1)
    assert _residual(x / (1 + fit.gain), clean) < 0.1


@pytest.mark.parametrize("gap", [0.15, 0.3, 0.45])
def test_two_close_steps_are_fitted_jointly(gap):
    """Two exposure steps closer than the half second averaged on either side of one (issue 27:
    the first detector blocked the second, and the drift fit took up what was left): both are
    found, each sized within 10 % (30 % where their ramps touch), and the correction leaves a tenth of the walker's signal."""
    rng = np.random.default_rng(6)
    clean = _wall(rng, _walker())
    first = np.clip((t - 4.0) / 0.2, 0, 1)
    second = np.clip((t - (4.2 + gap)) / 0.1, 0, 1)
    x = clean * ((1 - 0.02 * first) * (1 + 0.02 * second))[:, None]
    fit = C.fit(x, FPS, lines=[10.0], vertical=VERT, part=PART)
    kinds = {f["kind"]: f for f in fit.findings}
    steps = kinds["exposure"]["steps"]
    assert len(steps) == 2 and "drift" not in kinds
    assert steps[0]["time"] == pytest.approx(4.1, abs=0.1) and steps[1]["time"] == pytest.approx(4.25 + gap, abs=0.15)
    rel = 0.1 if gap >= 0.3 else 0.3  # where the ramps touch, the level between them is seen in a few frames
    assert steps[0]["size"] == pytest.approx(-0.02, rel=rel) and steps[1]["size"] == pytest.approx(0.02, rel=rel)
    assert _residual(x / (1 + fit.gain), clean) < 0.1


def test_two_steps_of_one_sign_with_a_short_level_between_are_one_step():
    """Two -2 % steps 0.2 s apart (ramps of 0.17 and 0.33 s): together a change over 0.7 s, too slow
    for one light's step, the level between them shorter than a ramp (issue 27: neither was found
    and the drift fit took the 4 %). Judged as one step of two quick ramps: found, 4 %, removed;
    a person's change as long, with no level in it, is not (the lamp of the test below)."""
    rng = np.random.default_rng(10)
    clean = _wall(rng, _walker())
    g = (1 - 0.02 * np.clip((t - 4.0) / 0.17, 0, 1)) * (1 - 0.02 * np.clip((t - 4.37) / 0.33, 0, 1))
    x = clean * g[:, None]
    fit = C.fit(x, FPS, lines=[10.0], vertical=VERT, part=PART)
    kinds = {f["kind"]: f for f in fit.findings}
    assert "drift" not in kinds
    assert sum(st["size"] for st in kinds["exposure"]["steps"]) == pytest.approx(-0.0396, rel=0.1)
    # 14 times the walker's signal uncorrected, 4.3 fitted as drift; the size, measured across the
    # wider gap, is off by 0.1 % here
    assert _residual(x / (1 + fit.gain), clean) < 0.6


@pytest.mark.parametrize("at", [0.3, 8.1])
def test_a_step_near_the_end_of_the_stretch_is_found(at):
    """A step with only a quarter of a second of plateau between it and the stretch's end (0.5 s
    were needed before): found, sized, removed."""
    rng = np.random.default_rng(7)
    clean = _wall(rng, _walker())
    x = clean * (1 + 0.02 * np.clip((t - at) / 0.1, 0, 1))[:, None]
    fit = C.fit(x, FPS, lines=[10.0], vertical=VERT, part=PART)
    (f,) = fit.findings
    (step,) = f["steps"]
    assert step["time"] == pytest.approx(at + 0.05, abs=0.1) and step["size"] == pytest.approx(0.02, rel=0.1)
    assert _residual(x / (1 + fit.gain), clean) < 0.1


def test_step_sizes_are_the_lights_own_whatever_came_before():
    """Gains multiply: the second of two 3 % steps is 3 % of the level the first left, so steps are
    sized (and the drift fitted) in logarithms; the sum of relative sizes would be off by their product."""
    rng = np.random.default_rng(8)
    clean = _wall(rng)
    g = (1 + 0.03 * np.clip((t - 3.0) / 0.1, 0, 1)) * (1 + 0.03 * np.clip((t - 6.0) / 0.1, 0, 1))
    fit = C.fit(clean * g[:, None], FPS, vertical=VERT, part=PART)
    (f,) = fit.findings
    assert [s["size"] for s in f["steps"]] == [pytest.approx(0.03, abs=0.0005)] * 2
    left = np.median(np.log(clean * g[:, None] / (1 + fit.gain) / clean), axis=1)
    assert np.std(left) < 1e-4


def test_a_small_drift_on_noisy_bins_is_judged_on_groups_of_bins():
    """A drift of 0.3 % peak to peak on bins six times noisier than the other tests': no single bin
    can tell it from a person's change, groups of neighbouring bins can; it is removed. The same
    noise without a drift finds nothing."""
    rng = np.random.default_rng(9)
    level = 100 + 20 * np.sin(np.linspace(0, 3, 2 * B))
    noisy = level[None] * (1 + rng.standard_normal((T, 2 * B)) * 0.003)
    drift = 1 + 0.0015 * np.sin(2 * np.pi * 0.08 * t + 0.5)
    fit = C.fit(noisy * drift[:, None], FPS, vertical=VERT, part=PART)
    assert [f["kind"] for f in fit.findings] == ["drift"]
    est = np.median(np.log1p(fit.gain), axis=1)
    truth = np.log(drift) - np.log(drift).mean()
    assert np.std(est - est.mean() - truth) < 0.2 * np.std(truth)
    assert C.fit(noisy, FPS, vertical=VERT, part=PART) is None


def test_a_slow_uniform_drift_is_removed():
    """Where the wall's bins drift alike: here beside a faint walker (0.1 %). A person whose own slow
    changes are as large as the drift hides it (it is then left in: research/corrections)."""
    rng = np.random.default_rng(3)
    clean = _wall(rng, _walker(0.001))
    x = clean * (1 + 0.01 * np.sin(2 * np.pi * 0.06 * t + 0.3))[:, None]
    fit = C.fit(x, FPS, lines=[10.0], vertical=VERT, part=PART)
    assert [f["kind"] for f in fit.findings] == ["drift"]
    left, added = x / (1 + fit.gain) - clean, x - clean
    assert np.std(left - left.mean(0)) < 0.1 * np.std(added - added.mean(0))


@pytest.mark.parametrize("kind", ["walker", "waver", "lamp"])
def test_what_a_person_does_to_the_wall_is_kept(kind):
    """Uneven and not at a mains alias: a walker's shadow, a periodic waver (1.5 Hz), and a person
    stepping in front of a lamp (a 5 % dimming over 0.5 s, uneven along the wall)."""
    rng = np.random.default_rng(4)
    if kind == "walker":
        person = _walker(0.01)
    elif kind == "waver":
        person = _walker(0.01) * (1 + np.sin(2 * np.pi * 1.5 * t))[:, None]
    else:
        shade = np.concatenate([np.linspace(0.01, 0.2, B), 0.05 + 0.02 * np.sin(np.arange(B) / 9)])
        person = -shade[None] * np.clip((t - 4.0) / 0.5, 0, 1)[:, None]
    x = _wall(rng, person)
    assert C.fit(x, FPS, lines=C.mains_lines(30, 30), vertical=VERT, part=PART) is None


def test_lagged_gains_hold_a_bounded_stretch_and_give_every_frame_its_gain():
    rng = np.random.default_rng(5)
    n = 1000
    tt = np.arange(n) / FPS
    truth = 0.01 * np.sin(2 * np.pi * 10 * tt + 0.5)
    level = 100 + 20 * np.sin(np.linspace(0, 3, 2 * B))
    lag = C.LaggedGains(FPS, lines=[10.0], vertical=VERT)
    got = {}
    for i in range(n):
        x = level * (1 + truth[i]) + rng.standard_normal(2 * B) * 0.05
        for j, g in lag.push(x):
            got[j] = g
        assert len(lag._buf) <= lag.window
        assert i + 1 - len(got) < lag.window  # so is the lag (the frames an SNR estimator holds)
    for j, g in lag.flush():
        got[j] = g
    assert sorted(got) == list(range(n))
    est = np.array([got[j].mean() for j in range(n)])
    assert np.std(est - truth) < 0.02 * np.std(truth)
    assert lag.corrections()[0]["kind"] == "flicker"


def test_merge_names_each_step_once():
    found = [[{"kind": "exposure", "steps": [{"time": 3.0, "size": 0.02}]}],
             [{"kind": "exposure", "steps": [{"time": 3.05, "size": 0.021}]}, {"kind": "drift", "amplitude": 0.004}],
             [{"kind": "flicker", "hz": 10.0, "amplitude": 0.01}]]
    merged = {e["kind"]: e for e in C.merge(found)}
    assert len(merged["exposure"]["steps"]) == 1 and merged["drift"]["amplitude"] == 0.004
    assert merged["flicker"]["hz"] == 10.0 and merged["flicker"]["windows"] == 1


# ------------------------------------------------------------------------------ simulated clips
STRENGTH = {"flicker": 0.01, "rolling": 0.01, "exposure": 0.02, "drift": 0.01}


@pytest.fixture(scope="module")
def clips(tmp_path_factory):
    """A walker (seed 3, 128x96, 10.5 s, 30 fps) and an empty room (seed 4), each clean and with
    every nuisance injected: 1 % flicker at 10 Hz (50 Hz mains), the same as rolling-shutter bands
    (2.5 over the frame), two exposure steps of +-2 %, +-1 % drift."""
    from wallcli.cli.app import main
    from wallcli.sim.inject import inject

    d = tmp_path_factory.mktemp("corrections")
    out = {}
    for name, extra in (("walker", ["--people", "1", "--activity", "walking", "--seed", "3"]),
                        ("empty", ["--people", "0", "--seed", "4"])):
        src = d / f"{name}.mkv"
        with pytest.raises(SystemExit) as exc:
            main(["simulate", "-o", str(src), "--size", "128x96", "--duration", "10.5", "--fps", "30", *extra])
        assert exc.value.code in (0, None)
        out[name, "none"] = d / f"{name}-none.mkv"
        inject(src, out[name, "none"], "none", strength=0.0)
        for kind, strength in STRENGTH.items():
            out[name, kind] = d / f"{name}-{kind}.mkv"
            inject(src, out[name, kind], kind, strength=strength, seed=1)
    return out


def _analyse(path, on=True):
    from wallcli.batch.analyse import analyse
    from wallcli.evaluate.clip import GREEN, plot_block
    from wallcli.infer.model import load_model

    models = {t: load_model(t, None) for t in ("count", "activity")}
    out = analyse(str(path), ("count", "activity", "snr"), models, corrections=C.Options() if on else C.OFF)
    scales = {s["block"]: s for s in out["snr"]["scales"]}
    block = plot_block(out["snr"]["roi"], 64, list(scales))
    return out, scales[block]["snr_db"][GREEN]


@pytest.mark.slow
@pytest.mark.parametrize("kind", ["flicker", "rolling", "exposure"])
def test_answers_and_snr_of_the_clean_clip_are_kept(clips, kind):
    clean, clean_snr = _analyse(clips["walker", "none"])
    assert clean["corrections"] == []  # nothing found on the clean clip
    got, snr = _analyse(clips["walker", kind])
    assert got["count"]["label"] == clean["count"]["label"]
    assert got["activity"]["label"] == clean["activity"]["label"]
    assert abs(10 ** ((snr - clean_snr) / 10) - 1) <= 0.10, (snr, clean_snr)
    assert abs(10 ** ((got["count"]["signal_db"] - clean["count"]["signal_db"]) / 10) - 1) <= 0.10
    kinds = {c["kind"] for c in got["corrections"]}
    assert ("flicker" if kind == "rolling" else kind) in kinds
    for task in ("count", "activity", "snr"):
        assert got[task]["corrections"], task
    if kind == "rolling":
        flick = next(c for c in got["activity"]["corrections"] if c["kind"] == "flicker")
        assert flick["rolling_shutter"] and flick["hz"] == pytest.approx(10.0, abs=0.05)
    if kind == "flicker":  # without the correction the SNR estimate is far off: the test can tell
        _, off = _analyse(clips["walker", kind], on=False)
        assert abs(off - clean_snr) > 3


def test_drift_in_an_empty_room_is_removed(clips):
    clean, _ = _analyse(clips["empty", "none"])
    got, _ = _analyse(clips["empty", "drift"])
    assert "drift" in {c["kind"] for c in got["corrections"]}
    assert (got["count"]["label"], got["activity"]["label"]) == (clean["count"]["label"], clean["activity"]["label"])


def test_the_options_turn_each_correction_off_and_follow_lines_say_what_was_removed(clips, run_cli):
    clip = str(clips["walker", "flicker"])
    code, out, _ = run_cli("count", clip, "--json")
    assert code == 0 and json.loads(out)["corrections"][0]["kind"] == "flicker"
    code, out, _ = run_cli("count", clip, "--json", "--no-deflicker")
    assert code == 0 and json.loads(out)["corrections"] == []
    code, out, _ = run_cli("snr", str(clips["walker", "exposure"]), "--json", "--no-exposure")
    assert code == 0 and json.loads(out)["corrections"] == []
    code, out, _ = run_cli("activity", clip, "--follow")
    lines = [json.loads(line) for line in out.splitlines()]
    assert lines and all(line["corrections"][0]["kind"] == "flicker" for line in lines)


@pytest.mark.parametrize("at", [-0.03, 8.43])
def test_a_step_cut_by_the_stretchs_end_is_taken_as_a_ramp(at):
    """A step whose ramp the stretch's end cuts (its last 3 samples on the ramp, or its first 2):
    no plateau to measure it on, so it is not a step the search can find; left in, its few samples
    of offset bent the cubic (issue 27, seeds 7101 and 7105: the residue 0.5-0.75 of a faint
    person's signal). Taken as a ramp, listed as a partial step, removed."""
    rng = np.random.default_rng(11)
    clean = _wall(rng, _walker(0.002))
    x = clean * (1 + 0.02 * np.clip((t - at) / 0.15, 0, 1))[:, None]
    fit = C.fit(x, FPS, lines=[10.0], vertical=VERT, part=PART)
    kinds = {f["kind"]: f for f in fit.findings}
    (step,) = kinds["exposure"]["steps"]
    assert step["partial"] and "drift" not in kinds
    assert _residual(x / (1 + fit.gain), clean) < 0.1
    whole = {"time": round(at + 0.07, 3), "size": 0.02}
    merged = C.merge([fit.findings, [{"kind": "exposure", "steps": [whole]}]])
    assert merged[0]["steps"] == [whole]  # the whole step's size, not the cut one's
    assert C.merge([fit.findings])[0]["steps"][0]["partial"]  # seen only cut: said so


def test_a_slow_ramps_step_is_placed_at_its_middle():
    """Two -2 % steps with 0.33 s ramps 0.8 s apart, on a wall with nobody (issue 27, held-out seed
    7224): the largest difference of adjacent half-second means sat at the second ramp's start, so
    the ramp left out of the fits (a ramp's length, centred there) missed half of it and the spans
    took the rest in: sized -1.4 %, a drift listed for what was left. Placed at the middle of where
    the level moves: both 2 %, no drift."""
    rng = np.random.default_rng(12)
    clean = _wall(rng)
    g = (1 - 0.02 * np.clip((t - 3.5) / 0.33, 0, 1)) * (1 - 0.02 * np.clip((t - 4.3) / 0.33, 0, 1))
    x = clean * g[:, None]
    fit = C.fit(x, FPS, lines=[10.0], vertical=VERT, part=PART)
    kinds = {f["kind"]: f for f in fit.findings}
    assert "drift" not in kinds
    assert [s["size"] for s in kinds["exposure"]["steps"]] == [pytest.approx(-0.02, rel=0.05)] * 2
    left = np.median(np.log(x / (1 + fit.gain) / clean), axis=1)
    assert np.std(left) < 2e-4  # 1.2e-3 before
