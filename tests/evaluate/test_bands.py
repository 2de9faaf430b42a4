"""evaluate's SNR bands (CONTRACT.md by_band) and --min-snr, from a labels.csv with an snr_db
column and from the measured SNR, on simulated clips."""
from __future__ import annotations

import json
import shutil

import pytest

from wallcli.evaluate.score import band_of

# stem -> (people, activity, detectable, snr_db cell): bands empty 2, <0 dB 1, 0-10 dB 1, >=10 dB 2
KNOWN = {"empty": (0, "none", 1, ""), "walk": (1, "walking", 1, "12"), "jump": (1, "jumping", 1, "5"),
         "crouch": (1, "crouching", 0, "-3"), "stand": (0, "none", 1, ""), "two": (2, "mixed", 1, "15")}
BAND_KEYS = ["snr_db", "band", "clips", "correct", "decided", "correct_decided"]


@pytest.fixture(scope="module")
def with_snr(sims, tmp_path_factory):
    d = tmp_path_factory.mktemp("with_snr")
    lines = ["file,people,activity,detectable,snr_db"]
    for stem, (people, act, det, snr) in KNOWN.items():
        shutil.copy(sims / f"{stem}.mp4", d / f"{stem}.mp4")
        lines.append(f"{stem}.mp4,{people},{act},{det},{snr}")
    (d / "labels.csv").write_text("\n".join(lines) + "\n")
    return d


def _figures(rows: list[dict], band: str) -> list:
    sel = [r for r in rows if r["band"] == band]
    dec = [r for r in sel if r["confident"] is True and r["error"] is None]
    return [len(sel), sum(r["correct"] for r in sel), len(dec), sum(r["correct"] for r in dec)]


def _flat(out: str) -> str:
    """A table as words: cells apart by one space, whatever the widths."""
    return " ".join(out.replace("│", " ").split())


def test_band_edges():
    assert band_of(True, 30.0) == "empty" and band_of(False, -0.01) == "<0 dB" and band_of(False, 0.0) == "0-10 dB"
    assert band_of(False, 9.99) == "0-10 dB" and band_of(False, 10.0) == ">=10 dB" and band_of(False, None) == "not measured"


@pytest.mark.slow
def test_bands_from_the_labels_snr_cover_every_clip(with_snr, run_cli):
    code, out, err = run_cli("evaluate", with_snr, "--task", "count", "--json", "--jobs", "2")
    assert code == 0, err
    res = json.loads(out)
    assert res["snr_source"] == "labels" and res["scored"] == 5 and res["clips"] == 6  # crouch: not detectable
    rows = {r["file"]: r for r in res["rows"]}
    assert {n: r["band"] for n, r in rows.items()} == {"empty.mp4": "empty", "walk.mp4": ">=10 dB", "jump.mp4": "0-10 dB",
                                                       "crouch.mp4": "<0 dB", "stand.mp4": "empty", "two.mp4": ">=10 dB"}
    assert [list(b) for b in res["by_band"]] == [BAND_KEYS] * 4
    assert [b["snr_db"] for b in res["by_band"]] == [[None, None], [None, 0], [0, 10], [10, None]]
    assert '"snr_db": [null, 0], "band": "<0 dB"' in out  # CONTRACT.md's very text
    assert [b["clips"] for b in res["by_band"]] == [2, 1, 1, 2]
    for b in res["by_band"]:
        assert [b["clips"], b["correct"], b["decided"], b["correct_decided"]] == _figures(res["rows"], b["band"])
    assert res["min_snr"] is None and res["excluded"] == 0

    code, out, err = run_cli("evaluate", with_snr, "--task", "activity", "--jobs", "2")
    assert code == 0, err
    text = _flat(out)
    assert "By SNR band, all 5 scored clips (SNR: labels.csv snr_db)" in text and "measured SNR" not in text
    # the contract's "empty" band holds every clip where nobody moves, a still person included
    assert "nobody moving 2" in text and "empty rooms" not in text and "10 dB and over 1" in text


@pytest.mark.slow
@pytest.mark.parametrize("floor,out_", [("0", ["crouch.mp4"]), ("10", ["jump.mp4", "crouch.mp4"])])
def test_min_snr_leaves_quiet_clips_out_of_every_figure(with_snr, run_cli, floor, out_):
    code, out, err = run_cli("evaluate", with_snr, "--task", "count", "--json", "--jobs", "2", "--min-snr", floor)
    assert code == 0, err
    res = json.loads(out)
    assert res["excluded"] == len(out_) and res["excluded_files"] == out_ and res["min_snr"] == float(floor)
    assert res["clips"] == 6 - len(out_) and not set(out_) & {r["file"] for r in res["rows"]}
    assert res["all"]["scored"] == res["clips"] and sum(b["clips"] for b in res["by_band"]) == res["clips"]
    assert res["by_band"][0]["clips"] == 2  # empty rooms are always scored
    code, out, err = run_cli("evaluate", with_snr, "--task", "count", "--jobs", "2", "--min-snr", floor)
    text = _flat(out)
    assert f"--min-snr {floor}: {len(out_)} clip{'s' if len(out_) > 1 else ''} under {floor} dB left out" in text


@pytest.mark.slow
def test_without_an_snr_column_bands_are_on_the_measured_snr(labelled, run_cli):
    """... that is, on the column SNR of the same decode (issue 61.1: column_snr_db, the figure every
    command prints first), not on the block SNR of rows[].snr_db nor the answers' signal_db."""
    code, out, err = run_cli("evaluate", labelled, "--task", "count", "--json", "--jobs", "2")
    assert code == 0, err
    res = json.loads(out)
    assert res["snr_source"] == "measured" and res["band_measure"].startswith("column_snr_db")
    assert res["snr_figure"] == "column_snr_db"
    for r in res["rows"]:
        assert r["band"] == band_of(r["truth"] == 0, r["column_snr_db"]) and r["snr_db_labels"] is None
        assert (r["column_snr_db"] is None) == (r["error"] is not None)  # every analysed clip has one
    # clips that failed have no measured SNR: a fifth band, so that every scored clip is counted
    assert [b["band"] for b in res["by_band"]] == ["empty", "<0 dB", "0-10 dB", ">=10 dB", "not measured"]
    assert res["by_band"][-1]["clips"] == 2 and sum(b["clips"] for b in res["by_band"]) == res["clips"] == 9
    for b in res["by_band"]:
        assert [b["clips"], b["correct"], b["decided"], b["correct_decided"]] == _figures(res["rows"], b["band"])

    movers = sorted(r["column_snr_db"] for r in res["rows"] if r["band"] not in ("empty", "not measured"))
    floor = (movers[1] + movers[2]) / 2
    code, out, err = run_cli("evaluate", labelled, "--task", "count", "--json", "--jobs", "2", "--min-snr", floor)
    cut = json.loads(out)
    gone = [r["file"] for r in res["rows"] if r["band"] != "empty" and (r["column_snr_db"] is None or r["column_snr_db"] < floor)]
    assert cut["excluded_files"] == gone and len(gone) == 4 and cut["clips"] == 5
    assert all(r in res["rows"] for r in cut["rows"])

    code, out, err = run_cli("evaluate", labelled, "--task", "count", "--jobs", "2")
    assert "The labels give no snr_db: bands are on the measured column SNR (column_snr_db" in _flat(out)


@pytest.mark.slow
@pytest.mark.parametrize("value", ["nan", "inf", "-inf", "100", "-1e9", "loud", ""])
def test_min_snr_must_be_a_finite_number_in_range(with_snr, run_cli, value):
    code, out, err = run_cli("evaluate", with_snr, "--task", "count", "--min-snr", value)
    assert code == 2 and out == "" and err.startswith("Error: --min-snr must be a number from -99 to 99")
