"""Temporal noise reduction (``simulate --tnr A``): each frame blended with the last output, so
the clip's noise is correlated from frame to frame by about A while the room is the seed's; the
analyses find it (``corrections`` kind ``temporal_nr``) and decide nothing on the figure it inflates."""

from __future__ import annotations

import json

import numpy as np
import pytest


def _lumas(path):
    from wallcli.io.video import open_video

    with open_video(path) as reader:
        return np.stack([f.planes.y.astype(np.float64) for f in reader.frames()])


def _lag1(y: np.ndarray) -> float:
    """The lag-1 autocorrelation of the noise of pixels two columns apart (the wall's light and
    texture cancel there, each pixel's noise does not)."""
    z = y[:, :, 2:] - y[:, :, :-2]
    z = z - z.mean(axis=0)
    return float(np.sum(z[1:] * z[:-1]) / np.sum(z * z))


@pytest.fixture(scope="module")
def blended(tmp_path_factory):
    from wallcli.cli.app import main

    d = tmp_path_factory.mktemp("tnr")
    out = {}
    for name, extra in (("clean", []), ("tnr", ["--tnr", "0.6"])):
        out[name] = d / f"{name}.mkv"
        with pytest.raises(SystemExit) as exc:
            main(["simulate", "-o", str(out[name]), "--people", "0", "--seed", "4", "--size", "64x48",
                  "--duration", "2", "--level", "120", "--read-noise", "3", *extra])
        assert exc.value.code in (0, None)
    return out


def test_tnr_correlates_the_noise_and_keeps_the_room(blended):
    clean, tnr = _lumas(blended["clean"]), _lumas(blended["tnr"])
    assert abs(_lag1(clean)) < 0.08
    assert 0.5 <= _lag1(tnr) <= 0.7
    # the same room and camera: the mean image is the seed's, the noise is smaller
    assert np.abs(tnr.mean(axis=0) - clean.mean(axis=0)).mean() < 0.5
    assert np.diff(tnr, axis=0).std() < 0.6 * np.diff(clean, axis=0).std()
    cam = json.loads(blended["tnr"].with_suffix(".json").read_text())["camera"]
    assert cam["tnr"] == 0.6


def test_recursive_filter_is_the_blend():
    from wallcli.sim.isp import RecursiveFilter

    f = RecursiveFilter(0.5)
    outs = [f(np.full((2, 2), v, np.float32))[0, 0] for v in (4.0, 0.0, 8.0)]
    assert outs == [4.0, 2.0, 5.0]
    with pytest.raises(ValueError):
        RecursiveFilter(1.0)


def test_tnr_and_awb_are_refused_for_a_dataset_and_out_of_range(tmp_path, run_cli):
    for opt, bad in (("--tnr", "0.99"), ("--awb-drift", "0.5")):
        code, _, err = run_cli("simulate", "--dataset", "2", "-o", tmp_path / "d", opt, "0.1")
        assert code != 0 and opt in err
        code, _, err = run_cli("simulate", "-o", tmp_path / "x.mkv", opt, bad)
        assert code != 0 and opt in err


def _frames(ys):
    from types import SimpleNamespace

    return [SimpleNamespace(time=i / 30, gap=0.0, planes=SimpleNamespace(y=y)) for i, y in enumerate(ys)]


@pytest.mark.parametrize("a", [0.0, 0.6])
def test_temporal_noise_reads_the_blend(a):
    from wallcli.camera.tnr import TemporalNoise

    rng = np.random.default_rng(2)
    wall = 100 + 10 * rng.random((72, 96))
    noise = np.zeros_like(wall)
    tap = TemporalNoise()
    for f in _frames([None] * 80):
        noise = a * noise + (1 - a) * 4 * rng.standard_normal(wall.shape)
        f.planes.y = np.clip(np.rint(wall + noise), 0, 255).astype(np.uint8)
        tap(f)
    assert abs(tap.lag1() - a) < 0.12
    assert (tap.correction() is None) == (a == 0.0)


def test_a_codec_that_holds_blocks_is_not_judged():
    """Noise held in whole blocks from one frame to the next is the codec's, not a camera's blend."""
    from wallcli.camera.tnr import TemporalNoise

    rng = np.random.default_rng(3)
    tap = TemporalNoise()
    y = rng.integers(90, 110, (72, 96)).astype(np.uint8)
    for i, f in enumerate(_frames([None] * 80)):
        y = y.copy()
        y[:, 48:] = rng.integers(90, 110, (72, 48))  # the left half held, the right half new
        f.planes.y = y
        tap(f)
    assert tap.lag1() is None and tap.correction() is None


@pytest.fixture(scope="module")
def walker(tmp_path_factory):
    from wallcli.cli.app import main

    d = tmp_path_factory.mktemp("tnrwalk")
    out = {}
    for name, extra in (("clean", []), ("tnr", ["--tnr", "0.7"])):
        out[name] = d / f"{name}.mkv"
        with pytest.raises(SystemExit) as exc:
            main(["simulate", "-o", str(out[name]), "--people", "1", "--seed", "6", "--size", "96x72",
                  "--duration", "9", "--level", "120", "--read-noise", "2", *extra])
        assert exc.value.code in (0, None)
    return out


@pytest.mark.parametrize("task", ["count", "activity"])
def test_a_blended_clip_is_listed_and_not_decided_on_its_figure(walker, run_cli, task):
    got = {}
    for name in ("clean", "tnr"):
        code, out, _ = run_cli(task, walker[name], "--json")
        assert code == 0
        got[name] = json.loads(out)
    assert [c for c in got["clean"]["corrections"] if c["kind"] == "temporal_nr"] == []
    (found,) = [c for c in got["tnr"]["corrections"] if c["kind"] == "temporal_nr"]
    assert found["bound"] is True and 0.4 <= found["lag1"] <= 0.9
    # the blend reads the figure higher than the clean clip's; no answer is decided on it
    assert got["tnr"]["signal_db"] > got["clean"]["signal_db"]
    assert got["tnr"]["view"]["usable"]
    for rec in [got["tnr"], *got["tnr"]["windows"]]:
        assert rec["confident"] is False and "upper bound" in rec["reason"]
