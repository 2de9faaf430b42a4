"""Interlaced video (``simulate --interlace``: fields woven from two instants half a frame apart):
found in the decode, its fields brought to one instant, listed under ``corrections``; a progressive
clip is not."""

from __future__ import annotations

import json

import av
import numpy as np
import pytest

SIM = ["--people", "1", "--activity", "walking", "--seed", "5", "--size", "160x120", "--duration", "9.5"]


@pytest.fixture(scope="module")
def woven(tmp_path_factory):
    """One walker (seed 5, 160x120, 9.5 s, lossless): progressive, and interlaced top and bottom
    field first (rendered at 60 fps, woven into 30)."""
    from wallcli.cli.app import main

    d = tmp_path_factory.mktemp("interlace")
    out = {}
    for name, extra in (("progressive", []), ("tff", ["--interlace", "tff"]), ("bff", ["--interlace", "bff"])):
        out[name] = d / f"{name}.mkv"
        with pytest.raises(SystemExit) as exc:
            main(["simulate", "-o", str(out[name]), *SIM, *extra])
        assert exc.value.code in (0, None)
    return out


def _interlace(result):
    return [c for c in result["corrections"] if c["kind"] == "interlace"]


def test_simulate_weaves_two_instants(woven):
    truth = json.loads(woven["tff"].with_suffix(".json").read_text())
    assert truth["interlace"] == "tff" and truth["fps"] == 30 and truth["field_rate"] == 60
    with av.open(str(woven["tff"])) as c:
        frames = [f.to_ndarray(format="gray").astype(float) for f in c.decode(video=0)]
    assert len(frames) == truth["frames"]


@pytest.mark.parametrize("order", ["tff", "bff"])
def test_interlaced_clip_is_found_and_answers_as_the_progressive_one(woven, run_cli, order):
    code, out, err = run_cli("count", woven["progressive"], "--json")
    assert code == 0, err
    clean = json.loads(out)
    assert _interlace(clean) == []
    code, out, err = run_cli("count", woven[order], "--json")
    assert code == 0, err
    got = json.loads(out)
    found = _interlace(got)
    assert len(found) == 1 and found[0]["field_order"] == order
    assert found[0]["field_offset"] == (0.5 if order == "tff" else -0.5)
    assert got["view"]["usable"] and got["label"] == clean["label"] == 1
    assert abs(got["signal_db"] - clean["signal_db"]) <= 3.0


def test_snr_lists_it_too(woven, run_cli):
    code, out, err = run_cli("snr", woven["tff"], "--json")
    assert code == 0, err
    assert [c["field_order"] for c in _interlace(json.loads(out))] == ["tff"]


def _light(k):
    return 1 + 0.05 * np.sin(2 * np.pi * k / 30)


def _frames(n, offset, seed=0):
    """Gray frames of a wall whose light swings by 5 % once a second; the odd rows (bottom field)
    captured ``offset`` frames after the even rows; camera noise on every row."""
    from wallcli.io.planes import Planes
    from wallcli.io.video import Frame

    rng = np.random.default_rng(seed)
    wall = 100 + 30 * rng.random((48, 64))
    for k in range(n):
        y = wall * _light(k) + rng.normal(0, 0.5, wall.shape)
        y[1::2] = wall[1::2] * _light(k + offset) + rng.normal(0, 0.5, wall[1::2].shape)
        yield Frame(k, k / 30, Planes(y.astype(np.float32), None, None, "gray"))


@pytest.mark.parametrize("offset", [0.0, 0.5, -0.5])
def test_fields_are_brought_to_one_instant(offset):
    from types import SimpleNamespace

    from wallcli.camera.interlace import InterlaceFilter

    wall = 100 + 30 * np.random.default_rng(0).random((48, 64))  # _frames' wall
    f = InterlaceFilter(SimpleNamespace(frames=lambda: _frames(60, offset)))
    out = list(f.frames())
    assert len(out) == 60
    if offset == 0:
        assert f.correction() is None
        return
    assert f.correction()["field_order"] == ("tff" if offset > 0 else "bff")
    # once corrected, the bottom field's light is the top field's (up to 0.5 % apart before)
    for k in (45, 50):
        y = out[k].planes.y
        top, bottom = y[0::2].mean() / wall[0::2].mean(), y[1::2].mean() / wall[1::2].mean()
        assert abs(top - _light(k)) < 0.001 and abs(bottom - top) < 0.0005 < abs(_light(k + offset) - _light(k))


def test_a_clip_shown_progressive_is_not_read_further(woven):
    """Once the light's changes have shown both fields at one instant beyond doubt (over 4 s), the
    check stops reading (the decision it would reach stays 'progressive'); a woven clip is still
    found interlaced, never taken for progressive first."""
    from wallcli.camera.interlace import InterlaceFilter
    from wallcli.io.video import open_video

    seen = {}
    for name in ("progressive", "tff", "bff"):
        with open_video(str(woven[name])) as reader:
            f = InterlaceFilter(reader)
            n = sum(1 for _ in f.frames())
        seen[name] = (f.progressive, f.delta, f._n, n)
    progressive, delta, read, frames = seen["progressive"]
    assert progressive and delta is None and read < frames - 30, seen
    assert not seen["tff"][0] and seen["tff"][1] == 0.5, seen
    assert not seen["bff"][0] and seen["bff"][1] == -0.5, seen
