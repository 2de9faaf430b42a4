"""Auto white balance hunting (``simulate --awb-drift``): per-colour gains found and divided out
before the grey corrections, listed as ``corrections`` kind ``white_balance``; the answers are
the clean clip's."""

from __future__ import annotations

import json

import numpy as np
import pytest


@pytest.fixture(scope="module")
def hunted(tmp_path_factory):
    """One walker (seed 3, 128x96, 10 s, lossless), clean and with a 2 % white-balance hunt: the
    same room, camera and noise (the hunt draws from its own stream)."""
    from wallcli.cli.app import main

    d = tmp_path_factory.mktemp("awb")
    out = {}
    for name, extra in (("clean", []), ("awb", ["--awb-drift", "0.02"])):
        out[name] = d / f"{name}.mkv"
        with pytest.raises(SystemExit) as exc:
            main(["simulate", "-o", str(out[name]), "--people", "1", "--seed", "3", "--size", "128x96",
                  "--duration", "10", "--level", "120", *extra])
        assert exc.value.code in (0, None)
    return out


def _wb(result):
    return [c for c in result["corrections"] if c["kind"] == "white_balance"]


def test_simulate_records_the_hunt(hunted):
    cam = json.loads(hunted["awb"].with_suffix(".json").read_text())["camera"]
    assert cam["awb_drift"] == 0.02
    assert json.loads(hunted["clean"].with_suffix(".json").read_text())["camera"]["awb_drift"] == 0.0


@pytest.mark.parametrize("task", ["count", "activity"])
def test_a_hunted_clip_keeps_the_clean_answer_and_lists_the_hunt(hunted, run_cli, task):
    got = {}
    for name in ("clean", "awb"):
        code, out, _ = run_cli(task, hunted[name], "--json")
        assert code == 0
        got[name] = json.loads(out)
    assert _wb(got["clean"]) == []
    (wb,) = _wb(got["awb"])
    assert len(wb["amplitude"]) == 3 and 0.004 <= max(wb["amplitude"]) <= 0.04
    assert got["awb"]["label"] == got["clean"]["label"]
    assert abs(got["awb"]["signal_db"] - got["clean"]["signal_db"]) <= 3.0
    # the colours' gains differ: the hunt was not left in the profiles the networks read
    p = np.array(got["awb"]["probabilities"]) - np.array(got["clean"]["probabilities"])
    assert np.abs(p).max() < 0.3


def test_white_balance_finds_per_colour_gains_and_leaves_a_grey_change_alone():
    """On synthetic profiles: a colour-only drift is found per colour and removed; the same drift
    on all colours alike (a light's level) is not a white balance (the grey fit's business)."""
    from wallcli.camera.whitebalance import white_balance

    rng = np.random.default_rng(1)
    t = np.arange(256) / 30.0
    level = 100 + 20 * rng.random((64, 1, 3))
    noise = 0.02 * rng.standard_normal((64, 256, 3))
    colour = np.stack([1 + 0.01 * np.sin(2 * np.pi * 0.08 * t), np.ones_like(t),
                       1 - 0.015 * np.sin(2 * np.pi * 0.05 * t + 1)], axis=1)  # (T, 3)
    res = white_balance([level * colour[None] + noise], 30.0)
    assert res is not None
    gains, found = res
    assert found["kind"] == "white_balance" and found["amplitude"][0] > 0.004 and found["amplitude"][2] > 0.006
    ratio = gains / gains.mean(axis=0)
    want = colour / colour.mean(axis=1, keepdims=True)
    assert np.abs(ratio - want / want.mean(axis=0)).max() < 0.003
    grey = (1 + 0.02 * np.sin(2 * np.pi * 0.08 * t))[None, :, None]
    assert white_balance([level * grey + noise], 30.0) is None
