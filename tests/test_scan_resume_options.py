"""A scan's resume knows what made each line: options and models (issue 38, items 2 and 13)."""
from __future__ import annotations

import json
from pathlib import Path

import pytest

SIM = ["--size", "64x48", "--duration", "3", "--fps", "30", "--grid", "8x8", "--crf", "12", "--people", "0"]


@pytest.fixture(scope="module")
def clip(tmp_path_factory) -> Path:
    from wallcli.cli.app import main

    path = tmp_path_factory.mktemp("resume") / "a.mp4"
    with pytest.raises(SystemExit) as exc:
        main(["simulate", "-o", str(path), *SIM])
    assert exc.value.code in (0, None)
    return path


def _lines(path: Path) -> list[dict]:
    return [json.loads(s) for s in path.read_text().splitlines()]


def test_each_line_records_its_options(clip, tmp_path, run_cli):
    out = tmp_path / "r.jsonl"
    code, _, err = run_cli("scan", clip, "-o", out, "--task", "snr", "--workers", "1")
    assert code == 0, err
    (line,) = _lines(out)
    assert line["options"] == {"deflicker": True, "exposure": True, "shake": True, "windows": False}


@pytest.mark.parametrize("flag,key", [("--no-shake", "shake"), ("--no-deflicker", "deflicker"),
                                      ("--no-exposure", "exposure")])
def test_resume_with_other_options_analyses_again(clip, tmp_path, run_cli, flag, key):
    out = tmp_path / "r.jsonl"
    assert run_cli("scan", clip, "-o", out, "--task", "snr", "--workers", "1")[0] == 0
    code, stdout, err = run_cli("scan", clip, "-o", out, "--task", "snr", "--workers", "1", flag, "--json")
    assert code == 0, err
    assert json.loads(stdout)["skipped"] == 0 and "other options" in err
    (line,) = _lines(out)  # replaced, not appended
    assert line["options"][key] is False
    # and the same options again: skipped
    code, stdout, _ = run_cli("scan", clip, "-o", out, "--task", "snr", "--workers", "1", flag, "--json")
    assert code == 0 and json.loads(stdout)["skipped"] == 1


def test_a_line_without_options_is_made_again(clip, tmp_path, run_cli):
    out = tmp_path / "r.jsonl"
    assert run_cli("scan", clip, "-o", out, "--task", "snr", "--workers", "1")[0] == 0
    (line,) = _lines(out)
    del line["options"]  # a line of an older wallcli
    out.write_text(json.dumps(line) + "\n")
    code, stdout, err = run_cli("scan", clip, "-o", out, "--task", "snr", "--workers", "1", "--json")
    assert code == 0 and json.loads(stdout)["skipped"] == 0
    assert "options" in _lines(out)[0]


def test_a_line_of_another_model_is_made_again(tmp_path):
    from wallcli.batch.results import Entry
    from wallcli.batch.scan import same_making

    opts = {"deflicker": True, "exposure": True, "shake": True, "windows": False}
    e = Entry("{}", "a.mp4", 1, "x", ("count",), None, dict(opts), {"count": "old"})
    assert not same_making(e, opts, {"count": "new"})
    assert same_making(e, opts, {"count": "old"})
    assert not same_making(e, dict(opts, windows=True), {"count": "old"})


def test_strict_resume_sees_the_kept_lines(clip, tmp_path, run_cli):
    out = tmp_path / "r.jsonl"
    assert run_cli("scan", clip, "-o", out, "--task", "snr", "--workers", "1")[0] == 0
    (line,) = _lines(out)
    # the verdict an earlier run wrote: the camera moved
    line["view"] = {"usable": False, "issues": ["camera motion"], "reason": "not a static view of the wall: x"}
    out.write_text(json.dumps(line) + "\n")
    code, stdout, err = run_cli("scan", clip, "-o", out, "--task", "snr", "--workers", "1", "--strict", "--json")
    assert json.loads(stdout)["skipped"] == 1
    assert code == 1 and "--strict" in err and "not a static view" in err


def test_strict_resume_from_csv_sees_the_kept_lines(clip, tmp_path, run_cli):
    import csv

    out = tmp_path / "r.csv"
    assert run_cli("scan", clip, "-o", out, "--task", "snr", "--workers", "1")[0] == 0
    rows = list(csv.reader(out.open()))
    header, row = rows[0], rows[1]
    row[header.index("view.usable")] = "false"
    row[header.index("view.reason")] = "not a static view of the wall: x"
    with out.open("w", newline="") as f:
        csv.writer(f, lineterminator="\n").writerows([header, row])
    code, _, err = run_cli("scan", clip, "-o", out, "--task", "snr", "--workers", "1", "--strict")
    assert code == 1 and "--strict" in err
