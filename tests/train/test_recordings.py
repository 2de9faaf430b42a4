"""Training on labelled recordings: windows cut as inference cuts them, fixed folds, the card's block."""
from __future__ import annotations

import json

import numpy as np
import pytest

pytest.importorskip("torch")

from wallcli.train.recordings import fold_of, harvest_clip, load_recordings  # noqa: E402

SMALL = ["--duration", "10.5", "--size", "64x48", "--grid", "16x16"]
# (stem, people, activity, seed)
SCENES = [("c01_empty", 0, "none", 1), ("c02_walk", 1, "walking", 3), ("c03_jump", 1, "jumping", 3),
          ("c04_walk", 1, "walking", 7), ("c05_empty", 0, "none", 4), ("c06_two", 2, "walking,crouching", 3)]


def test_folds_come_from_the_clip_number_not_from_a_draw():
    assert fold_of("t001_p0_none.mp4", 5) == 1
    assert fold_of("t220_p1_waving.mp4", 5) == 0  # the first number is the clip's: p1 is not
    assert fold_of("clip-17.mkv", 5) == 2
    # a name without digits: a CRC of the name, the same every time
    assert fold_of("lobby.mp4", 5) == fold_of("lobby.mp4", 5)
    assert {fold_of(f"room{i}.mp4", 3) for i in range(6)} == {0, 1, 2}


@pytest.fixture(scope="module")
def clips(tmp_path_factory):
    from wallcli.cli.app import main

    d = tmp_path_factory.mktemp("recordings")
    for stem, people, act, seed in SCENES:
        try:
            main(["simulate", "-o", str(d / f"{stem}.mp4"), "--people", str(people), "--activity", act,
                  "--seed", str(seed), *SMALL])
        except SystemExit as exc:
            assert not exc.code
    return d


def test_windows_are_the_ones_count_answers_on(clips, run_cli):
    """The harvested windows at the card's stride give the very answer `wallcli count` gives."""
    from wallcli.infer.twostage import load_classifier
    from wallcli.train.folds import clip_probabilities
    from wallcli.train.recordings import Recording

    clip = clips / "c02_walk.mp4"
    code, out, _ = run_cli("count", clip, "--json")
    assert code == 0
    want = json.loads(out)
    a = harvest_clip(clip)
    assert a["horizontal"].dtype == np.float32  # never rounded to 8 bits
    assert np.all(np.diff(a["starts"]) > 0) and int(a["frames"]) == int(a["starts"][-1]) + 256
    rec = Recording(name=clip.name, people=1, activity="walking", persons=1, snr_db=None, detectable=True,
                    starts=a["starts"], horizontal=a["horizontal"], vertical=a["vertical"], h_offset=a["h_offset"],
                    v_offset=a["v_offset"], usable=bool(a["usable"]), frames=int(a["frames"]))
    got = clip_probabilities(load_classifier("count"), rec)
    assert np.allclose(got, want["probabilities"], atol=1e-5)
    assert len(rec.eval_index(64)) == len(want["windows"])


def test_cache_is_reused_and_keyed_by_the_clip(clips, tmp_path):
    recs = load_recordings([clips], tmp_path / "cache")
    assert [r.name for r in recs] == sorted(f"{s}.mp4" for s, *_ in SCENES)
    files = sorted((tmp_path / "cache").glob("*.npz"))
    assert len(files) == len(SCENES)
    stamp = [f.stat().st_mtime_ns for f in files]
    again = load_recordings([clips], tmp_path / "cache", task="activity")
    assert len(again) == len(SCENES) - 1  # activity is not defined for two people
    assert [f.stat().st_mtime_ns for f in sorted((tmp_path / "cache").glob("*.npz"))] == stamp
    files[0].write_bytes(b"not a zip")  # a damaged entry is cut again, not trusted
    assert len(load_recordings([clips], tmp_path / "cache")) == len(SCENES)


@pytest.mark.slow
def test_train_clips_folds_writes_the_out_of_fold_block(clips, tmp_path, run_cli):
    """The worked example of docs/adapt.md, small: two folds, one epoch."""
    out = tmp_path / "site-count.onnx"
    args = ["train", "count", "--clips", clips, "--folds", "2", "--epochs", "1", "--batch-size", "8",
            "--init", _shipped("count"), "--lr", "1e-4", "--clip-cache", tmp_path / "cache", "--out", out]
    code, _, err = run_cli(*args)
    assert code == 0, err
    assert "out of fold (2 folds" in err and "detectable" in err
    card = json.loads(out.with_suffix(".json").read_text())
    rec = card["recordings"]
    assert rec["clips"] == len(SCENES) and rec["folds"] == 2
    det = rec["out_of_fold"]["detectable"]
    assert det["clips"] == len(SCENES) and 0 <= det["right"] <= det["clips"]
    assert sum(b["clips"] for b in rec["out_of_fold"]["by_band"].values()) == len(SCENES)
    assert "confidence" in card and "out-of-fold" in card["confidence"]["fitted_on"]
    # the model runs as users run it
    code, text, err = run_cli("count", clips / "c02_walk.mp4", "--model", out, "--json")
    assert code == 0, err
    assert json.loads(text)["label"] in (0, 1, 2)
    # a rerun answers every fold from its kept answers: no fold is trained again
    code, _, err = run_cli(*args, "--force")
    assert code == 0, err
    assert err.count("answers kept from an earlier run") == 2


def test_train_needs_something_to_train_on(run_cli, tmp_path):
    code, _, err = run_cli("train", "count", "--out", tmp_path / "m.onnx")
    assert code == 2 and "--data" in err and "--clips" in err
    code, _, err = run_cli("train", "count", "--data", tmp_path, "--folds", "3", "--out", tmp_path / "m.onnx")
    assert code == 2 and "--folds needs --clips" in err


def _shipped(task):
    from wallcli.infer.model import shipped_model_path

    return shipped_model_path(task)
