"""The report records every option that changes its answers and lists the corrections; --strict
on a scan's results means what it means on a video (issue 38, items 12 and 13)."""
from __future__ import annotations

import json
import shlex

import pytest
from pagetree import parse, table_rows
from report_clips import run_main


def _facts(page) -> dict[str, str]:
    return {row[0]: row[1] for row in table_rows(page.by_id("evidence").find_all("table")[0])}


@pytest.fixture(scope="module")
def flicker_clip(tmp_path_factory):
    # 100 Hz at 24 fps: a 4 Hz line the deflicker finds
    path = tmp_path_factory.mktemp("flicker") / "f.mp4"
    assert run_main("simulate", "-o", path, "--people", "1", "--activity", "walking", "--seed", "5", "--size",
                    "64x48", "--duration", "10.5", "--fps", "24", "--grid", "8x8", "--flicker", "0.01") == 0
    return path


def test_corrections_found_are_listed(flicker_clip, tmp_path):
    out = tmp_path / "r.html"
    assert run_main("report", flicker_clip, "-o", out) == 0
    facts = _facts(parse(out.read_text(encoding="utf-8")))
    assert "found and removed before analysis" in facts["Corrections"] and "flicker" in facts["Corrections"]
    assert "turned off" not in facts["Corrections"]
    assert facts["View"]


def test_the_command_line_carries_the_corrections_turned_off(flicker_clip, tmp_path):
    out = tmp_path / "r.html"
    assert run_main("report", flicker_clip, "-o", out, "--no-deflicker", "--no-shake") == 0
    page = parse(out.read_text(encoding="utf-8"))
    facts = _facts(page)
    assert "--no-deflicker" in facts["Command"] and "--no-shake" in facts["Command"]
    assert "--no-exposure" not in facts["Command"]
    assert "turned off: --no-deflicker, --no-shake" in facts["Corrections"]
    assert "flicker" not in facts["Corrections"].split("turned off")[1].replace("--no-deflicker", "")
    # run again as recorded: the same answers
    args = shlex.split(facts["Command"])
    again = tmp_path / "again.html"
    args[args.index("-o") + 1] = str(again)
    assert run_main(*args[1:]) == 0
    assert parse(again.read_text(encoding="utf-8")).by_id("verdicts").text() == page.by_id("verdicts").text()


@pytest.fixture
def results(tmp_path):
    lines = [{"input": "a.mp4", "tasks": ["snr"], "error": None, "view": {"usable": True, "issues": [], "reason": None}},
             {"input": "b.mp4", "tasks": ["snr"], "error": None,
              "view": {"usable": False, "issues": ["camera motion"], "reason": "not a static view of the wall: x"}}]
    path = tmp_path / "r.jsonl"
    path.write_text("".join(json.dumps(d) + "\n" for d in lines))
    return path


def test_strict_on_scan_results(results, tmp_path, run_cli):
    code, _, err = run_cli("report", results, "-o", tmp_path / "i.html", "--strict")
    assert code == 1 and "b.mp4" in err and "--strict" in err and not (tmp_path / "i.html").exists()
    code, _, err = run_cli("report", results, "-o", tmp_path / "i.html")
    assert code == 0, err


def test_corrections_options_are_refused_on_scan_results(results, tmp_path, run_cli):
    code, _, err = run_cli("report", results, "-o", tmp_path / "i.html", "--no-shake")
    assert code == 2 and "--no-shake" in err


def test_the_command_line_carries_the_stream(tmp_path):
    import sys
    from pathlib import Path

    sys.path.insert(0, str(Path(__file__).parents[1]))
    from test_video import _two_streams

    clip = _two_streams(tmp_path)
    out = tmp_path / "r.html"
    assert run_main("report", clip, "-o", out, "--stream", "1") == 0
    facts = _facts(parse(out.read_text(encoding="utf-8")))
    assert "--stream 1" in facts["Command"] and facts["Resolution"] == "64 × 48 pixels"
