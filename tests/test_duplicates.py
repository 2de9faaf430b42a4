"""Repeated frames (a DVR's nominal-rate padding, ``simulate --dup-frames``): found in the decode,
left out as missing samples, listed under ``corrections``; the SNR of a padded clip is the clean one's."""

from __future__ import annotations

import json

import numpy as np
import pytest

from clips import write_clip


@pytest.fixture(scope="module")
def padded(tmp_path_factory):
    """One walker (seed 5, 128x96, 9.5 s, noisy enough that the signal is near the noise, where
    zero differences move the SNR most), clean and with 20 % of its frames copies; and the same
    padding through H.264, whose re-encoded copies need not be bit-exact."""
    from wallcli.cli.app import main

    d = tmp_path_factory.mktemp("dup")
    out = {}
    for name, ext, extra in (("clean", "mkv", []), ("padded", "mkv", ["--dup-frames", "0.2"]),
                             ("padded264", "mp4", ["--dup-frames", "0.2"])):
        out[name] = d / f"{name}.{ext}"
        with pytest.raises(SystemExit) as exc:
            main(["simulate", "-o", str(out[name]), "--people", "1", "--seed", "5", "--size", "128x96",
                  "--duration", "9.5", "--noise-scale", "2.5", *extra])
        assert exc.value.code in (0, None)
    return out


def _dups(result):
    return [c for c in result["corrections"] if c["kind"] == "duplicates"]


def test_simulate_records_the_copies_it_made(padded):
    truth = json.loads(padded["padded"].with_suffix(".json").read_text())
    n = truth["duplicated"]
    assert truth["dup_frames"] == 0.2 and 0.14 * truth["frames"] <= n <= 0.26 * truth["frames"]
    assert "duplicated" not in json.loads(padded["clean"].with_suffix(".json").read_text())


@pytest.mark.parametrize("name", ["padded", "padded264"])
def test_snr_lists_every_copy_and_keeps_the_clean_figure(padded, run_cli, name):
    truth = json.loads(padded[name].with_suffix(".json").read_text())
    code, out, _ = run_cli("snr", padded[name], "--json")
    assert code == 0
    got = json.loads(out)
    assert _dups(got) == [{"kind": "duplicates", "frames": truth["duplicated"],
                           "share": round(truth["duplicated"] / truth["frames"], 4)}]
    assert got["frames"] == truth["frames"]  # the file's frames; the entry says how many were left out
    if name == "padded":
        code, out, _ = run_cli("snr", padded["clean"], "--json")
        clean = json.loads(out)
        assert _dups(clean) == []
        # copies' zero differences read 2.1-2.7 dB too high here before they were left out
        assert np.allclose(got["snr_db"], clean["snr_db"], atol=1.5)


def test_count_lists_the_copies_on_the_clip(padded, run_cli):
    truth = json.loads(padded["padded"].with_suffix(".json").read_text())
    code, out, _ = run_cli("count", padded["padded"], "--json")
    assert code == 0
    got = json.loads(out)
    assert _dups(got) == [{"kind": "duplicates", "frames": truth["duplicated"],
                           "share": round(truth["duplicated"] / truth["frames"], 4)}]
    code, out, _ = run_cli("count", padded["clean"], "--json")
    assert code == 0 and _dups(json.loads(out)) == []


def test_noise_free_still_frames_are_not_repeats(tmp_path, run_cli):
    """A synthetic clip whose frames never differ has no frame noise to judge a copy by: nothing is dropped."""
    path = write_clip(tmp_path / "still.mkv", lambda i: np.full((48, 64, 3), 120.0), 20, codec="ffv1",
                      pix_fmt="yuv444p")
    code, out, _ = run_cli("snr", path, "--json")
    got = json.loads(out)
    assert code == 0 and got["frames"] == 20 and _dups(got) == []


def test_repeat_filter_streams_and_finds_copies_among_the_first_frames():
    """Copies in the first frames (before the clip's typical difference is known) are found too,
    and the frames that pass keep their order and times."""
    from types import SimpleNamespace

    from wallcli.camera.repeats import RepeatFilter

    rng = np.random.default_rng(0)
    copy = np.zeros(60, bool)
    copy[[1, 2, 7, 30, 31, 32, 59]] = True
    ys, y = [], None
    for i in range(60):
        y = y if copy[i] else rng.integers(90, 110, (40, 50)).astype(np.uint8)
        ys.append(y)
    frames = [SimpleNamespace(time=i / 30, planes=SimpleNamespace(y=y)) for i, y in enumerate(ys)]
    f = RepeatFilter(SimpleNamespace(frames=lambda: iter(frames)))
    kept = [fr.time for fr in f.frames()]
    assert kept == [i / 30 for i in range(60) if not copy[i]]
    assert f.correction() == {"kind": "duplicates", "frames": 7, "share": round(7 / 60, 4)}


def test_too_short_quotes_the_files_frames_copies_included(tmp_path, run_cli):
    from wallcli.cli.app import main

    clip = tmp_path / "short.mkv"
    with pytest.raises(SystemExit):
        main(["simulate", "-o", str(clip), "--people", "0", "--seed", "2", "--size", "64x48", "--duration", "3",
              "--dup-frames", "0.3"])
    assert json.loads(clip.with_suffix(".json").read_text())["duplicated"] > 0
    code, _, err = run_cli("count", clip)
    assert code != 0 and "90 frame(s) decoded" in err


def test_dup_frames_is_refused_for_a_dataset_and_out_of_range(tmp_path, run_cli):
    code, _, err = run_cli("simulate", "--dataset", "2", "-o", tmp_path / "d", "--dup-frames", "0.2")
    assert code != 0 and "--dup-frames" in err
    code, _, err = run_cli("simulate", "-o", tmp_path / "x.mkv", "--dup-frames", "0.7")
    assert code != 0 and "--dup-frames" in err
