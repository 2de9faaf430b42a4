"""Issue 62, scan and its report: an output that is a scanned video, --force interrupted, a full
disk, copies in a report, hand-edited results, CSV formula cells, and '-' as scan's input."""
from __future__ import annotations

import contextlib
import csv
import json
import os
import re
import shutil
import signal
import subprocess
import sys
import time
from pathlib import Path

import pytest
from clips import one_error, simulated_walk, tiny_clip

WALLCLI = [sys.executable, "-m", "wallcli"]


@pytest.fixture(scope="module")
def video(tmp_path_factory) -> Path:
    """One short simulated clip (a window fits; a decode takes a fraction of a second)."""
    return simulated_walk(tmp_path_factory.mktemp("video") / "walk.mp4")


def _lines(path: Path) -> list[dict]:
    return [json.loads(s) for s in path.read_text(encoding="utf-8").splitlines()]


# 1 ------------------------------------------------------------ an output that is a scanned video
@pytest.mark.parametrize("name", ["c1.mp4", "new.MKV"])
def test_an_output_named_as_a_video_is_refused_even_with_force(tmp_path, run_cli, name):
    vids = tmp_path / "vids"
    vids.mkdir()
    for n in ("c1.mp4", "c2.mp4"):
        tiny_clip(vids / n)
    before = (vids / "c1.mp4").read_bytes()
    code, out, err = run_cli("scan", vids, "-o", vids / name, "--force", "--workers", "1")
    assert code == 2 and out == "" and "named as a video" in one_error(err)
    assert (vids / "c1.mp4").read_bytes() == before and not (vids / "new.MKV").exists()


def test_an_output_the_glob_picks_up_is_an_input(tmp_path, run_cli):
    vids = tmp_path / "vids"
    vids.mkdir()
    tiny_clip(vids / "c1.mkv")
    (vids / "notes.txt").write_text("my notes\n")
    code, _, err = run_cli("scan", vids, "--glob", "*", "-o", vids / "notes.txt", "--force", "--workers", "1")
    assert code == 1 and "is one of the inputs" in one_error(err)
    assert (vids / "notes.txt").read_text() == "my notes\n"


# 14 --------------------------------------------------------------------------- '-' is a usage error
def test_stdin_as_scans_input_is_a_usage_error(tmp_path, run_cli):
    code, _, err = run_cli("scan", "-", "-o", tmp_path / "x.jsonl")
    assert code == 2 and "not '-'" in one_error(err)
    assert not (tmp_path / "x.jsonl").exists()


# 2 -------------------------------------------------------------------- --force interrupted
def _side_lines(folder: Path) -> int:
    """Lines written so far to the hidden files beside the results."""
    n = 0
    for p in folder.iterdir():
        if p.name.startswith("."):
            with contextlib.suppress(OSError):
                n += p.read_bytes().count(b"\n")
    return n


@pytest.mark.skipif(not hasattr(os, "killpg"), reason="needs process groups")
def test_force_interrupted_after_its_first_new_line_keeps_the_old_results(tmp_path, video):
    folder = tmp_path / "v"
    folder.mkdir()
    names = [f"v{i:02d}.mp4" for i in range(16)]
    for n in names:
        shutil.copy(video, folder / n)
    res = tmp_path / "out"
    res.mkdir()
    out = res / "r.jsonl"
    old = [{"input": str(folder / n), "size": None, "sha256": None, "duration": None, "frames": None,
            "tasks": ["snr"], "error": "an old failure"} for n in names]
    out.write_text("".join(json.dumps(d) + "\n" for d in old))
    before = out.read_bytes()
    proc = subprocess.Popen([*WALLCLI, "scan", str(folder), "-o", str(out), "--task", "snr", "--force",
                             "--workers", "1"], stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, text=True,
                            start_new_session=True)
    try:
        deadline = time.monotonic() + 180
        while time.monotonic() < deadline and proc.poll() is None:
            if out.read_bytes() != before or _side_lines(res) >= 1:  # the run's first new line is stored
                break
            time.sleep(0.02)
        assert proc.poll() is None, f"the scan ended before the signal: {proc.stderr.read()}"
        os.killpg(proc.pid, signal.SIGINT)
        _, err = proc.communicate(timeout=60)
    finally:
        with contextlib.suppress(ProcessLookupError):
            os.killpg(proc.pid, signal.SIGKILL)
    assert proc.returncode == 1 and err.strip().endswith("Error: interrupted"), err
    lines = _lines(out)
    # every video keeps one line: the new answers where the run got to, the old lines elsewhere
    assert sorted(Path(d["input"]).name for d in lines) == names
    new = [d for d in lines if d["error"] is None]
    assert 1 <= len(new) < len(names) and all(d["snr"]["frames"] == 315 for d in new)
    assert [p.name for p in res.iterdir()] == ["r.jsonl"]  # no temporary left beside it


def test_force_that_ends_well_replaces_the_old_results(tmp_path, video, run_cli):
    out = tmp_path / "r.jsonl"
    out.write_text(json.dumps({"input": "elsewhere/x.mp4", "tasks": ["snr"], "error": "old"}) + "\n")
    code, _, err = run_cli("scan", video, "-o", out, "--task", "snr", "--force", "--workers", "1")
    assert code == 0, err
    assert [d["input"] for d in _lines(out)] == [str(video)]
    assert [p.name for p in tmp_path.iterdir()] == ["r.jsonl"]


# 7 --------------------------------------------------------------------------------- a full disk
def _no_bigger_than(limit: int):
    def apply():
        import resource

        signal.signal(signal.SIGXFSZ, signal.SIG_IGN)  # a write past the limit fails (EFBIG), as on a full disk
        resource.setrlimit(resource.RLIMIT_FSIZE, (limit, limit))
    return apply


@pytest.mark.skipif(not hasattr(signal, "SIGXFSZ"), reason="needs RLIMIT_FSIZE")
def test_a_write_that_fails_part_way_leaves_whole_lines(tmp_path):
    folder = tmp_path / "v"
    folder.mkdir()
    for i in range(3):  # not videos: each gets its error line at once
        (folder / f"broken{i}.mp4").write_bytes(b"not a video " * 40)
    free = tmp_path / "free.jsonl"
    res = subprocess.run([*WALLCLI, "scan", str(folder), "-o", str(free), "--task", "snr", "--workers", "1"],
                         capture_output=True, text=True, timeout=300)
    assert res.returncode == 0, res.stderr
    sizes = [len(s) + 1 for s in free.read_bytes().split(b"\n")[:-1]]
    assert len(sizes) == 3
    out = tmp_path / "r.jsonl"
    # the first line fits, the second is cut part way by the limit
    res = subprocess.run([*WALLCLI, "scan", str(folder), "-o", str(out), "--task", "snr", "--workers", "1"],
                         capture_output=True, text=True, timeout=300,
                         preexec_fn=_no_bigger_than(max(sizes) + min(sizes) // 2))
    errors = [s for s in res.stderr.splitlines() if s.startswith("Error:")]
    assert res.returncode == 1 and "Traceback" not in res.stderr, res.stderr
    assert len(errors) == 1 and errors[0] == res.stderr.splitlines()[-1] and "cannot write" in errors[0]
    text = out.read_text(encoding="utf-8")
    assert text.endswith("\n") and len(_lines(out)) == 1  # cut back to the last whole line


# 8 --------------------------------------------------------------------------- copies in a report
def _totals(page: str) -> dict[str, int]:
    return {k: int(v) for k, v in re.findall(r'id="total-(\w+)"[^>]*>(\d+)<', page)}


def test_a_report_of_copies_has_a_row_per_file_marked_as_copies(tmp_path, run_cli):
    from wallcli.cli.output import to_json

    lines = []
    for clip in range(2):
        for copy in range(4):
            lines.append(to_json({"input": f"cam{copy}/clip{clip}.mp4", "size": 10, "sha256": str(clip) * 64,
                                  "duration": 10.0, "frames": 300, "tasks": ["snr"], "error": None,
                                  "snr": {"snr_db": [1.0, 2.0, 3.0], "channels": ["r", "g", "b"]}}))
    lines.append(to_json({"input": "junk/a.mp4", "size": 3, "sha256": "f" * 64, "tasks": ["snr"], "error": "bad"}))
    lines.append(to_json({"input": "junk/b.mp4", "size": 3, "sha256": "f" * 64, "tasks": ["snr"], "error": "bad"}))
    results = tmp_path / "r.jsonl"
    results.write_text("\n".join(lines) + "\n")
    code, _, err = run_cli("report", results, "-o", tmp_path / "index.html")
    assert code == 0, err
    page = (tmp_path / "index.html").read_text(encoding="utf-8")
    totals = _totals(page)
    assert totals["videos"] == 10 and totals["failed"] == 2 and totals["copies"] == 7
    assert all(f"cam{c}/<wbr>clip{k}.mp4" in page for c in range(4) for k in range(2))
    assert page.count("(copy of cam0/<wbr>clip0.mp4)") == 3 and page.count("(copy of junk/<wbr>a.mp4)") == 1
    assert "7 of the videos are copies" in " ".join(err.split())


# 9 ------------------------------------------------------------------ impossible values refused
GOOD = {"input": "a.mp4", "size": 10, "sha256": "0" * 64, "duration": 10.0, "frames": 300,
        "tasks": ["count", "snr"], "error": None,
        "count": {"task": "count", "classes": [0, 1, 2], "label": 1, "probabilities": [0.1, 0.8, 0.1],
                  "confident": False, "signal_db": -3.0},
        "snr": {"channels": ["r", "g", "b"], "snr_db": [1.0, 2.0, 3.0], "signal_power": [1.0, 1.0, 1.0],
                "noise_power": [1.0, 1.0, 1.0]}}
EDITS = {
    "duration -1e308": ('"duration": 10.0', '"duration": -1e308'),
    "duration 1e308": ('"duration": 10.0', '"duration": 1e308'),
    "NaN probabilities": ('"probabilities": [0.1, 0.8, 0.1]', '"probabilities": [NaN, 0.8, 0.1]'),
    "probabilities over 1": ('"probabilities": [0.1, 0.8, 0.1]', '"probabilities": [0.1, 8.0, 0.1]'),
    "snr null": ('"snr": {', '"snr": null, "x": {'),
    "negative size": ('"size": 10', '"size": -5'),
    "Infinity signal": ('"signal_db": -3.0', '"signal_db": -Infinity'),
}


@pytest.mark.parametrize("edit", list(EDITS))
def test_report_and_resume_refuse_hand_edited_values(tmp_path, run_cli, edit):
    old, new = EDITS[edit]
    good = json.dumps(GOOD)
    assert old in good
    results = tmp_path / "r.jsonl"
    results.write_text(good.replace('"a.mp4"', '"b.mp4"') + "\n" + good.replace(old, new) + "\n")
    code, _, err = run_cli("report", results, "-o", tmp_path / "index.html")
    assert code == 1 and "line 2 is not a wallcli scan result" in one_error(err)
    assert not (tmp_path / "index.html").exists()
    # a resume refuses the same line with the same words, and leaves the file as it was
    before = results.read_bytes()
    clip = tiny_clip(tmp_path / "c.mkv")
    code, _, err = run_cli("scan", clip, "-o", results, "--task", "count,snr", "--workers", "1")
    assert code == 1 and "line 2 is not a wallcli scan result" in one_error(err)
    assert results.read_bytes() == before


def test_the_good_line_is_read_by_both(tmp_path):
    from wallcli.batch.results import read
    from wallcli.report.scan import read_results

    results = tmp_path / "r.jsonl"
    results.write_text(json.dumps(GOOD) + "\n")
    assert [e.input for e in read(results, None)[0]] == ["a.mp4"]
    assert [r["input"] for r in read_results(results)[0]] == ["a.mp4"]


# 10 ------------------------------------------------------------------------ CSV formula cells
FORMULAS = ['=1+2,"q".mp4', "@SUM(A1).mp4", "+1.mp4", "-1.mp4", "\tx.mp4", "'quoted.mp4", "plain.mp4"]


def test_csv_cells_that_a_spreadsheet_would_run_are_text_and_read_back(tmp_path):
    from wallcli.batch.results import csv_columns, csv_record, flatten, read

    columns = csv_columns(("count", "snr"), {"count": [0, 1, 2]})
    lines = [{"input": n, "size": 7, "sha256": "0" * 64, "tasks": ["count", "snr"], "error": f"{n} is not a video",
              "count": {"classes": [0, 1, 2], "label": 1, "probabilities": [0.1, 0.8, 0.1], "signal_db": -3.5}}
             for n in FORMULAS]
    path = tmp_path / "r.csv"
    path.write_text(csv_record(columns) + "".join(csv_record(flatten(d, columns)) for d in lines), encoding="utf-8")
    with open(path, newline="", encoding="utf-8") as fh:
        rows = list(csv.DictReader(fh))
    for row, name in zip(rows, FORMULAS):
        for cell in (row["input"], row["error"]):
            assert not cell.startswith(("=", "+", "-", "@", "\t", "\r")), cell
        assert row["input"] == (name if name == "plain.mp4" else "'" + name)
        assert row["count.signal_db"] == "-3.5"  # a number stays a number
    entries, torn = read(path, columns)  # a resume reads the names as they were
    assert [e.input for e in entries] == FORMULAS and [e.error for e in entries] == [d["error"] for d in lines]


def test_scan_csv_of_a_formula_name(tmp_path, run_cli, monkeypatch):
    monkeypatch.chdir(tmp_path)
    for name in ('=1+2,"q".mp4', "@SUM(A1).mp4"):
        Path(name).write_bytes(b"not a video")
    Path("list.txt").write_text("@SUM(A1).mp4\n")  # on the command line, @NAME is a list file
    code, _, err = run_cli("scan", '=1+2,"q".mp4', "@list.txt", "-o", "cs3.csv", "--task", "snr", "--workers", "1")
    assert code == 0, err
    with open("cs3.csv", newline="", encoding="utf-8") as fh:
        rows = list(csv.reader(fh))[1:]
    assert sorted(r[0] for r in rows) == ["'=1+2,\"q\".mp4", "'@SUM(A1).mp4"]
    assert all(not cell.startswith(("=", "@", "+", "-")) for r in rows for cell in r)
