"""`wallcli report results.jsonl`: the summary page of a scan, read back from the HTML."""
from __future__ import annotations

import base64
import hashlib
import json
import math

import pytest
from report_clips import HOSTILE
from pagetree import parse, table_rows
from scan_fixtures import RECORDS, write_results


@pytest.fixture
def index(tmp_path, run_cli):
    out = tmp_path / "index.html"
    code, _, err = run_cli("report", write_results(tmp_path / "results.jsonl"), "-o", out)
    assert code == 0, err
    assert "line 5 is not JSON" in " ".join(err.split())  # the cut line is reported, not fatal
    return out.read_text(encoding="utf-8")


def test_one_row_per_video_with_its_answers(index):
    rows = [[cell.replace("/ ", "/") for cell in r] for r in table_rows(parse(index).by_id("results"))]
    assert [r[0] for r in rows] == ["cam1/0001.mp4", f"cam1/{HOSTILE}.mp4", "cam2/old.mp4", "cam2/broken.mp4", "(line 5)"]
    name, duration, column, count, count_db, activity, activity_db, snr, error = zip(*rows)
    assert duration == ("12.00", "30.50", "9.00", "", "")
    # the headline column SNR first: the snr object's, else count's/activity's; blank when absent
    assert column == ("19.1", "-4.8", "", "", "")
    # figures as the results hold them: snr.snr_db of green, each task's signal_db; never "-0.0"
    assert snr == tuple(f"{r['snr']['snr_db'][1]:.1f}" for r in RECORDS[:3]) + ("", "") == ("3.0", "-20.0", "-99.0", "", "")
    assert count_db == ("12.5", "-30.0", "", "", "") and activity_db == ("0.0", "-28.5", "", "", "")
    assert count == ("1 person (p 0.93)", "undetermined, most likely 2 people signal 3 dB under the model's validated range",
                     "0 people (p 0.80)", "", "")
    assert activity == ("walking (p 0.90)", "none (p 0.90)", "none (p 0.70)", "", "")
    assert error[:3] == ("", "", "") and error[3].startswith("cam2/broken.mp4 is not a readable video")
    assert error[4].startswith("line 5 is not JSON")


def test_names_break_at_slashes_and_reasons_fold(index):
    """A long path breaks after a '/', not inside a name (<wbr>); an undetermined answer shows
    the answer most likely and keeps its reason, and a long error, behind a disclosure."""
    body = parse(index).by_id("results").find_all("tbody")[0]
    cells = [tr.find_all("td") for tr in body.find_all("tr")]
    assert "cam1/<wbr>0001.mp4" in index and len(cells[0][0].find_all("wbr")) == 1
    folded = cells[1][3].find_all("details")
    assert len(folded) == 1 and folded[0].find_all("summary")[0].text() == "undetermined, most likely 2 people"
    assert "validated range" in folded[0].text()
    assert not cells[0][3].find_all("details")  # a decided answer is short: nothing to fold
    error = cells[3][8].find_all("details")
    assert len(error) == 1 and error[0].text().startswith(error[0].find_all("summary")[0].text()[:40])


def test_sort_keys_are_numbers_and_blanks(index):
    body = parse(index).by_id("results").find_all("tbody")[0]
    keys = [[td.attrs.get("data-sort") for td in tr.find_all("td")] for tr in body.find_all("tr")]
    assert [k[1] for k in keys] == ["12.0", "30.5", "9.0", "", ""]
    assert [k[2] for k in keys] == ["19.12", "-4.75", "", "", ""]
    assert float(keys[0][7]) == pytest.approx(10 * math.log10(0.4 / 0.2))
    assert [k[4] for k in keys] == ["12.46", "-30.0", "", "", ""]


def test_the_column_snr_is_the_first_figure_and_each_figure_is_named(index):
    """Issue 61.1: the headline figure first under its one name; pixel SNR a later, named column."""
    heads = [th.text() for th in parse(index).by_id("results").find_all("th")]
    assert heads[2] == "column SNR (dB)"
    assert heads.index("pixel SNR G (dB)") > heads.index("activity")
    assert [h for h in heads if "SNR" in h] == ["column SNR (dB)", "pixel SNR G (dB)"]
    assert heads.count("signal_db (dB)") == 2  # each answer's own figure, by its JSON name
    note = " ".join(parse(index).by_id("videos").text().split())
    assert "Column SNR is the results' column_snr_db" in note


def test_totals_on_top(index):
    page = parse(index)
    assert page.by_id("total-videos").text() == "5"
    assert page.by_id("total-ok").text() == "3"
    assert page.by_id("total-failed").text() == "2"
    assert page.by_id("total-duration").text() == "51.50 s"
    # each task on its own: count left one video undetermined, activity none (old results: decided)
    assert page.by_id("total-count-decided").text() == "2 of 3"
    assert page.by_id("total-activity-decided").text() == "3 of 3"
    assert page.by_id("tally-count").text() == "count: 0 people: 1 · 1 person: 1 · undetermined: 1"
    assert page.by_id("tally-activity").text() == "activity: none: 2 · walking: 1"
    assert "line 5 is not JSON" in page.by_id("problems").text()
    assert "3.7 MB (3,734,577 bytes)" in page.by_id("totals").text()


def test_names_are_text_and_the_script_is_the_only_one(index):
    page = parse(index)
    assert "&lt;img src=x onerror=alert(1)&gt;" in index and "<img" not in index
    assert not any("onerror" in n.attrs or "onclick" in n.attrs for n in page.iter())
    scripts = page.find_all("script")
    assert len(scripts) == 1 and "src" not in scripts[0].attrs
    code = scripts[0].text()
    assert "sort" in code and "filter" in code
    # the Content-Security-Policy allows exactly this script (by its hash), no network at all
    csp = page.find_all("meta", http_equiv="Content-Security-Policy")[0].attrs["content"]
    raw = index.split("<script>", 1)[1].split("</script>", 1)[0]
    digest = base64.b64encode(hashlib.sha256(raw.encode()).digest()).decode()
    assert f"script-src 'sha256-{digest}'" in csp and "default-src 'none'" in csp and "connect-src" not in csp


def test_a_summary_of_only_failures_and_old_results(tmp_path, run_cli):
    src = write_results(tmp_path / "r.jsonl", [RECORDS[3], {"input": "a.mp4", "error": None, "duration": 10.0}], tail=None)
    out = tmp_path / "i.html"
    code, _, err = run_cli("report", src, "-o", out)
    assert code == 0, err
    page = parse(out.read_text(encoding="utf-8"))
    assert page.by_id("tally-count").text() == "count: not run"
    assert len(table_rows(page.by_id("results"))) == 2


@pytest.mark.parametrize("content", ["", "\n\n", "[1, 2]\n"])
def test_no_results_is_an_error(tmp_path, run_cli, content):
    src = tmp_path / "r.jsonl"
    src.write_text(content)
    code, _, err = run_cli("report", src, "-o", tmp_path / "i.html")
    if content.strip():  # a line that is not an object: a row saying so
        assert code == 0, err
        return
    assert code == 1 and err.startswith("Error:") and "holds no results" in err
    assert not (tmp_path / "i.html").exists()


def test_usage_and_input_errors(tmp_path, run_cli):
    src = write_results(tmp_path / "r.jsonl")
    code, _, err = run_cli("report", src, "-o", tmp_path / "i.html", "--roi", "0,0,10,10")
    assert code == 2 and "apply to a video" in err
    code, _, err = run_cli("report", tmp_path / "none.jsonl", "-o", tmp_path / "i.html")
    assert code == 1 and err.startswith("Error: no such file")
    code, _, err = run_cli("report", src, "-o", src.with_suffix(".html"))
    assert code == 0, err
    code, _, err = run_cli("report", src, "-o", src.with_suffix(".html"))
    assert code == 1 and "exists" in err
    assert json.loads(src.read_text().splitlines()[0])["input"] == "cam1/0001.mp4"  # the input is untouched
