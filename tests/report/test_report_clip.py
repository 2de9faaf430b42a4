"""`wallcli report VIDEO`: every section, read back from the HTML, against the other commands."""
from __future__ import annotations

import base64
import hashlib
import json
import re
import struct

import pytest
from clips import write_clip
from report_clips import FRAMES, HOSTILE, run_main, wall_frame
from pagetree import parse, table_rows

SECTIONS = ("evidence", "frame", "snr", "plots", "tracks", "count", "activity", "models", "method", "limits")


def _facts(page) -> dict[str, str]:
    return {row[0]: row[1] for row in table_rows(page.by_id("evidence").find_all("table")[0])}


def _png_size(uri: str) -> tuple[int, int]:
    assert uri.startswith("data:image/png;base64,")
    data = base64.b64decode(uri.split(",", 1)[1], validate=True)
    assert data[:8] == b"\x89PNG\r\n\x1a\n" and data[12:16] == b"IHDR"
    return struct.unpack(">II", data[16:24])


def test_every_section_is_there_and_self_contained(clip_report):
    html = clip_report.read_text(encoding="utf-8")
    page = parse(html)
    for section in SECTIONS:
        assert page.by_id(section).tag == "section"
    # nothing is fetched: images are data: URIs, no stylesheet or script comes from a file or URL
    assert not page.find_all("link")
    for node in page.iter():
        for attr in ("src", "href", "action", "srcset", "poster", "data"):
            value = node.attrs.get(attr)
            if value is not None:
                assert value.startswith(("data:image/png;base64,", "#")), (node.tag, attr, value[:60])
    assert not re.search(r"url\(|@import|https?://", html.split("<body>")[0])
    csp = page.find_all("meta", http_equiv="Content-Security-Policy")[0].attrs["content"]
    assert "default-src 'none'" in csp and "img-src data:" in csp and "script-src 'none'" in csp
    imgs = page.find_all("img")
    assert len(imgs) == 6  # frame, heatmap, plots, tracks, two timelines
    for img in imgs:
        w, h = _png_size(img.attrs["src"])
        assert w > 200 and h > 100
        assert img.attrs.get("alt")


def test_a_hostile_file_name_is_text(clip_report):
    html = clip_report.read_text(encoding="utf-8")
    page = parse(html)
    # the name is shown, as text, in the title, the header and the evidence table
    assert HOSTILE in page.find_all("title")[0].text()
    assert HOSTILE in _facts(page)["File"]
    assert html.count("&lt;img src=x onerror=alert(1)&gt;") >= 3
    assert "<img src=x" not in html
    assert not any("onerror" in n.attrs for n in page.iter())
    assert all(n.attrs.get("src", "").startswith("data:") for n in page.find_all("img"))


def test_evidence_identity(clip_report, hostile_clip):
    facts = _facts(parse(clip_report.read_text(encoding="utf-8")))
    data = hostile_clip.read_bytes()
    assert facts["SHA-256"] == hashlib.sha256(data).hexdigest()
    assert f"({len(data):,} bytes)" in facts["Size"] or facts["Size"] == f"{len(data):,} bytes"
    assert facts["Resolution"] == "64 × 48 pixels"
    assert facts["Frames decoded"].startswith(str(FRAMES))
    assert facts["Frame rate"].startswith("30 fps")
    assert facts["Duration"].startswith("9.000 s decoded")
    assert "h264" in facts["Codec, pixel format"] and "yuv420p" in facts["Codec, pixel format"]
    assert facts["Container"] == "MP4"  # not FFmpeg's 'mov,mp4,m4a,3gp,3g2,mj2'
    assert facts["Decode warnings"] == "none"
    assert facts["Region analysed (ROI)"] == "x 0, y 0, 64 × 48 pixels"
    assert facts["Command"].startswith("wallcli report ") and "-o " in facts["Command"]
    assert re.fullmatch(r"\d{4}-\d\d-\d\dT\d\d:\d\d:\d\d\+00:00", facts["Report made (UTC)"])


def test_snr_table_is_what_wallcli_snr_measures(clip_report, hostile_clip, run_cli):
    page = parse(clip_report.read_text(encoding="utf-8"))
    rows = table_rows(page.by_id("snr-table"))
    code, out, err = run_cli("snr", hostile_clip, "--json")
    assert code == 0, err
    ref = json.loads(out)
    assert [r[0] for r in rows] == [f"{s['block']}×{s['block']}" for s in ref["scales"]]
    for row, s in zip(rows, ref["scales"]):
        assert [float(x) for x in row[7:10]] == pytest.approx(s["snr_db"], abs=0.051)
        assert [float(x) for x in row[1:4]] == pytest.approx(s["signal_power"], rel=5e-3, abs=1e-9)  # 3 digits
    # the shadow is broad: averaging blocks raises the SNR, as the white-noise law says
    assert float(rows[-1][8]) > float(rows[0][8]) + 10
    assert page.by_id("snr").text().count(".") >= 2  # each figure is explained


@pytest.mark.parametrize("task", ["count", "activity"])
def test_verdicts_are_what_the_commands_answer(clip_report, hostile_clip, run_cli, task):
    code, out, err = run_cli(task, hostile_clip, "--json")
    assert code == 0, err
    ref = json.loads(out)
    section = parse(clip_report.read_text(encoding="utf-8")).by_id(task)
    label = f"{ref['label']} {'person' if ref['label'] == 1 else 'people'}" if task == "count" else ref["label"]
    verdict = section.find_all("p", class_="verdict")[0].text()
    if ref["confident"]:
        assert verdict.startswith(f"Clip: {label} ")
    else:  # the page never states an answer the model cannot back
        assert verdict.startswith(f"Clip: undetermined ({ref['reason']})") and f"answer {label}," in verdict
    assert f"probability {max(ref['probabilities']):.2f}" in verdict
    probs = table_rows(section.find_all("table", class_="probs")[0])[0]
    assert [float(p) for p in probs] == pytest.approx(ref["probabilities"], abs=6e-4)
    windows = table_rows(section.find_all("table", class_="windows")[0])
    assert [float(w[0]) for w in windows] == pytest.approx([w["start"] for w in ref["windows"]], abs=0.006)
    # the figure each answer was judged on, as the JSON and the terminal write it
    assert [w[3] for w in windows] == [f"{w['signal_db']:.1f}".replace("-0.0", "0.0") for w in ref["windows"]]
    assert f"signal_db {ref['signal_db']:.1f} dB".replace("-0.0", "0.0") in verdict
    assert len(section.find_all("img")) == 1


def test_the_column_snr_is_said_first_by_its_name(clip_report, hostile_clip, run_cli):
    """Issue 61.1: the headline figure every command prints first leads the page's verdicts and
    names the Signal and noise section, as snr --json gives it; the other figures are named apart."""
    from wallcli.snr.column import column_text
    from wallcli.wording import format_db

    code, out, err = run_cli("snr", hostile_clip, "--json")
    assert code == 0, err
    db = json.loads(out)["column_snr_db"]
    assert isinstance(db, float)
    page = parse(clip_report.read_text(encoding="utf-8"))
    head = page.by_id("verdicts").find_all("p")
    assert head[0].attrs.get("id") == "column-snr" and head[0].text() == column_text(db)
    assert head[0].text().startswith(f"column SNR {format_db(db)} dB")
    snr = page.by_id("snr")
    assert snr.find_all("h2")[0].text() == f"Signal and noise: column SNR {format_db(db)} dB"
    paras = snr.find_all("p")
    assert paras[0].attrs.get("id") == "column-snr-line" and "column_snr_db" in paras[0].text()
    assert paras[1].attrs.get("id") == "snr-verdict" and paras[1].text().startswith("Block SNR verdict: ")
    heads = [th.text() for th in page.by_id("snr-table").find_all("th")]
    assert "block SNR G (dB)" in heads and "SNR G (dB)" not in heads
    for task in ("count", "activity"):
        windows = page.by_id(task).find_all("table", class_="windows")[0]
        assert "signal_db (dB)" in [th.text() for th in windows.find_all("th")]


def test_models_come_from_their_cards(clip_report):
    from wallcli.infer.model import load_model

    models = parse(clip_report.read_text(encoding="utf-8")).by_id("models")
    text = models.text()
    for task in ("count", "activity"):
        card = load_model(task).card
        assert f"{card['name']} {card['version']}" in text
        assert card["sha256"] in text
        vis = card["validation"]["visible"]["accuracy"]
        assert f"{100 * vis:.1f} %" in text
        tr = card["transfer"]
        assert f"{100 * tr['accuracy']:.1f} %" in text  # the independent renderer's figure beside
    assert "What it cannot do" in text
    # the cards' own field names are said in words ('by_band', 'snr_source', 'errors: 0' were shown)
    assert "by_band" not in text and "snr_source" not in text and "errors: 0" not in text


def test_the_headline_says_each_undetermined_answer_in_plain_words():
    """Every reason confidence.judge and the view check write is said in words on the headline,
    with the answer most likely; a decided answer is stated with its probability and signal."""
    from wallcli.infer.confidence import judge
    from wallcli.report.verdicts import finding

    block = {"level": 0.97, "signal_edges_db": [0.0], "thresholds": [[None, None, None], [0.9, None, 0.95]]}
    cases = {
        "nobody moving is never decided": ([0.99, 0.005, 0.005], 5.0),
        "'1 person' answers at a signal like this one (4.7 dB) were not right often enough in validation to be "
        "relied on (97 % needed)": ([0.2, 0.7, 0.1], 4.7),
        "its probability (0.80) is under the 0.95 from which '2 people' answers were right 97 %": ([0.1, 0.1, 0.8], 3.0),
    }
    for words, (probs, snr) in cases.items():
        ok, reason = judge(block, probs, snr, [0, 1, 2])
        assert not ok
        head = finding("count", {"label": int(max(range(3), key=probs.__getitem__)), "probabilities": probs,
                                 "confident": False, "reason": reason, "signal_db": snr})
        assert head.startswith("Count: undetermined, most likely ") and words in head and reason not in head, head
    view = {"usable": False, "issues": ["camera motion"], "reason": "not a static view of the wall: camera motion at 0.6 s"}
    head = finding("activity", {"label": "walking", "probabilities": [0, 1, 0, 0, 0], "confident": False,
                                "reason": view["reason"], "view": view})
    assert head.endswith("the video is not a still view of a wall (camera motion)")
    head = finding("activity", {"label": "walking", "probabilities": [0, 0.97, 0.03, 0, 0], "confident": True,
                                "reason": None, "signal_db": 12.34})
    assert head == "Activity: walking (decided; probability 0.97, signal_db 12.3 dB)"


def test_undetermined_answers_and_a_transfer_block(hostile_clip, tmp_path, monkeypatch):
    """Results that carry confident=false show `undetermined (reason)`; a card's transfer block
    is shown beside its simulated figures (both written by other code, read with .get)."""
    import shutil

    from wallcli.report.analysis import analyse, load_models
    from wallcli.report.pages import clip_page

    for ext in ("onnx", "json"):
        shutil.copy(f"{_models_dir()}/count.{ext}", tmp_path / f"count.{ext}")
    card = json.loads((tmp_path / "count.json").read_text())
    card["transfer"] = {"description": "clips of another renderer", "scored": 52, "accuracy": 0.9231, "ci95": [0.85, 0.97], "coverage": 0.8,
                        "accuracy_decided": 0.98, "command": "wallcli evaluate DIR --task count --json",
                        "renderer": "<b>path tracer</b>"}
    from wallcli.infer.card import card_text

    (tmp_path / "count.json").write_text(card_text(card))  # sealed, as a program that measured it writes it
    import wallcli.io.video as video

    opened = []
    real_open = video.open_video
    monkeypatch.setattr(video, "open_video", lambda *a, **k: opened.append(a) or real_open(*a, **k))
    a = analyse(str(hostile_clip), models=load_models(tmp_path / "count.onnx"))
    assert len(opened) == 1  # one decode for the frame, SNR, heatmap, plots and both models
    reason = "signal 3 dB under the model's validated range <script>"
    a.results["count"] = dict(a.results["count"], confident=False, reason=reason)
    a.results["count"]["windows"] = [dict(w, confident=False, reason=reason) for w in a.results["count"]["windows"]]
    a.results["activity"] = dict(a.results["activity"], confident=True, reason=None)
    page = parse(clip_page(a, command="wallcli report x"))

    count = page.by_id("count")
    assert count.find_all("p", class_="verdict")[0].text().startswith(f"Clip: undetermined ({reason})")
    assert all(w[2] == f"undetermined ({reason})" for w in table_rows(count.find_all("table", class_="windows")[0]))
    # the headline is a finding: the answer most likely, then why (a reason it has no words for, as it is)
    findings = page.by_id("verdicts").find_all("p")  # the column SNR first, then one per task
    assert findings[1].text().startswith(f"Count: undetermined, most likely 1 person (probability")
    assert reason in page.by_id("verdicts").text()
    activity = page.by_id("activity")
    assert "decided (within the model's validated range)" in activity.text()
    assert "undetermined" not in activity.find_all("p", class_="verdict")[0].text()

    models = page.by_id("models").text()
    assert ("clips of another renderer: right on 92.3 % (95 % interval 85–97 %) of 52 clips; 80.0 % of clips "
            "decided, 98.0 %") in models
    assert "wallcli evaluate DIR --task count --json" in models
    assert "renderer: <b>path tracer</b>" in models  # unknown fields shown as they are, as text
    assert not page.find_all("script")
    assert all("path tracer" not in b.text() for b in page.find_all("b"))  # the page's own <b> only


def test_data_sets_are_named_by_what_they_are_not_where_they_were():
    """Cards name their sets by a description; a card that only has its author's folder (dir,
    dataset) is described from its recipe, and neither that folder nor a command naming it shows."""
    from wallcli.report.cards import _transfer, set_name

    for task in ("count", "activity"):
        card = json.loads((_models_dir() / f"{task}.json").read_text())
        v = card["validation"]
        assert set_name(v["source"], "x").startswith("simulated validation set")
        assert "independent path-traced transfer set" in _transfer(card["transfer"])[0]["set"]
    old = {"dir": "../shared/transfer", "command": "wallcli evaluate ../shared/transfer --task count --json",
           "accuracy": 0.5, "scored": 60}
    shown = _transfer(old)[0]
    assert shown["set"] == "transfer set" and shown["command"] is None and "../shared" not in json.dumps(shown)
    assert set_name({"dataset": "data/val_count6", "recipe": {"domain": "shifted"}, "windows": 1024},
                    "simulated validation set") == "simulated validation set: shifted rooms, 1,024 windows"


def test_the_page_names_no_folder_of_the_models_author(clip_report):
    text = clip_report.read_text(encoding="utf-8")
    assert "../shared" not in text and "data/val_" not in text and "seed §" not in text


def _models_dir():
    from wallcli.infer.model import shipped_model_path

    return shipped_model_path("count").parent


def test_roi_is_drawn_measured_and_checked(hostile_clip, tmp_path, run_cli):
    out = tmp_path / "roi.html"
    code, _, err = run_cli("report", hostile_clip, "-o", out, "--roi", "8,8,32,24")
    assert code == 0, err
    page = parse(out.read_text(encoding="utf-8"))
    assert _facts(page)["Region analysed (ROI)"] == "x 8, y 8, 32 × 24 pixels"
    assert "Measured on ROI 8,8,32,24" in page.by_id("snr").text()
    assert "--roi 8,8,32,24" in _facts(page)["Command"]

    code, _, err = run_cli("report", hostile_clip, "-o", tmp_path / "bad.html", "--roi", "40,8,32,24")
    assert code == 1 and err.startswith("Error:") and "64x48" in err and len(err.strip().splitlines()) == 1
    assert sorted(p.name for p in tmp_path.iterdir()) == ["roi.html"]  # nothing half-written
    code, _, err = run_cli("report", hostile_clip, "-o", tmp_path / "bad.html", "--roi", "1,2,3")
    assert code == 2 and "--roi" in err


def test_a_truncated_clip_too_short_for_a_window_still_gets_its_page(tmp_path, run_cli):
    whole = write_clip(tmp_path / "whole.mkv", wall_frame, 90).read_bytes()
    clip = tmp_path / "cut.mkv"
    clip.write_bytes(whole[: len(whole) * 6 // 10])
    out = tmp_path / "cut.html"
    code, _, err = run_cli("report", clip, "-o", out)
    assert code == 0, err
    err = " ".join(err.split())  # rich wraps long lines
    assert "no count verdict" in err and "no activity verdict" in err and "is too short" in err
    page = parse(out.read_text(encoding="utf-8"))
    warning = _facts(page)["Decode warnings"]
    assert "the file looks truncated" in warning and warning in err
    for task in ("count", "activity"):
        assert "No verdict:" in page.by_id(task).text() and "too short" in page.by_id(task).text()
    assert len(page.find_all("img")) == 3
    assert len(table_rows(page.by_id("snr-table"))) == 6


def test_outputs_are_atomic_and_never_overwritten_without_force(clip_report, hostile_clip, tmp_path, run_cli):
    out = tmp_path / "r.html"
    out.write_text("keep me")
    code, _, err = run_cli("report", hostile_clip, "-o", out)
    assert code == 1 and "exists" in err and "--force" in err
    assert out.read_text() == "keep me"
    code, _, err = run_cli("report", tmp_path / "missing.mp4", "-o", tmp_path / "m.html")
    assert code == 1 and err.startswith("Error: no such file")
    code, _, err = run_cli("report", hostile_clip, "-o", tmp_path / "r.txt")
    assert code == 2 and ".html" in err
    code, _, err = run_cli("report", hostile_clip)
    assert code == 2
    assert sorted(p.name for p in tmp_path.iterdir()) == ["r.html"]


def test_force_overwrites(tmp_path, run_cli):
    # the path holds '[/b]', rich's markup, and the warnings (too short) print it
    (tmp_path / "a[").mkdir()
    clip = write_clip(tmp_path / "a[" / "b]c.mp4", wall_frame, 60)
    out = tmp_path / "r.html"
    out.write_text("old")
    code, _, err = run_cli("report", clip, "-o", out, "--force")
    assert code == 0, err
    assert "a[/b]c.mp4 is too short" in " ".join(err.split())
    assert out.read_text(encoding="utf-8").startswith("<!DOCTYPE html>")
    assert sorted(p.name for p in tmp_path.iterdir()) == ["a[", "r.html"]


def test_report_memory_does_not_grow_with_the_clip(tmp_path, monkeypatch):
    """Issue 38 item 8: the report kept the whole plot (350 MB at 10 s, 885 MB at 600 s of 720p);
    it streams as count does. Measured with tracemalloc (numpy's allocations) on 20 s and 60 s,
    with the drawn plot's columns capped below both (its cap, 2048, is what bounds it for real)."""
    import tracemalloc

    import numpy as np

    import wallcli.report.analysis as analysis

    monkeypatch.setattr(analysis, "PLOT_COLUMNS", 256, raising=False)
    models = analysis.load_models()
    peaks = []
    for n in (300, 600, 1800):  # the first warms up (imports, caches): not measured
        clip = write_clip(tmp_path / f"long{n}.mkv", lambda i: np.full((16, 16, 3), 120.0)
                          + np.random.default_rng(i % 97).normal(0, 1, (16, 16, 3)), n, fps=30, codec="ffv1",
                          pix_fmt="yuv444p", options={})
        tracemalloc.start()
        a = analysis.analyse(str(clip), models=models)
        peaks.append(tracemalloc.get_traced_memory()[1])
        tracemalloc.stop()
        assert a.identity["frames"] == n and set(a.results) == {"count", "activity"}
    assert peaks[2] < 1.05 * peaks[1] + 0.5e6, peaks  # the whole plot grew by 14 kB a frame


EXAMPLES = __import__("pathlib").Path(__file__).resolve().parents[2] / "examples"


def test_report_shows_the_views_notes(tmp_path, run_cli, monkeypatch):
    # two-mixed.mp4: a person near the wall casts a sharp shadow; count and activity say so in
    # their JSON's view (no fault: the clip is analysed), and the page says it too, as text
    clip = EXAMPLES / "two-mixed.mp4"
    code, out, err = run_cli("count", clip, "--json")
    assert code == 0, err
    view = json.loads(out)["view"]
    assert view["usable"] and any(n.startswith("sharp shadow or light in view") for n in view["notes"])
    page_path = tmp_path / "two-mixed.html"
    code, _, err = run_cli("report", clip, "-o", page_path)
    assert code == 0, err
    cell = parse(page_path.read_text(encoding="utf-8")).by_id("view")
    assert cell.text().startswith("a static view of the wall; also seen")
    assert [li.text() for li in cell.find_all("li")] == view["notes"]

    # a note is text, never markup (autoescape)
    from wallcli.view import limits as view_limits

    monkeypatch.setitem(view_limits.NOTES, "sharp light", "<b onclick=x>sharp</b> & light")
    page_path = tmp_path / "escaped.html"
    code, _, err = run_cli("report", clip, "-o", page_path)
    assert code == 0, err
    html = page_path.read_text(encoding="utf-8")
    assert "&lt;b onclick=x&gt;sharp&lt;/b&gt; &amp; light (at " in html and "<b onclick" not in html


def test_a_view_with_no_notes_lists_none(clip_report):
    # the session's clip: its view is refused (the sweeping shadow reads as motion), with no notes
    cell = parse(clip_report.read_text(encoding="utf-8")).by_id("view")
    assert cell.text().startswith("not usable: ") and "also seen" not in cell.text() and not cell.find_all("li")


@pytest.mark.parametrize("name,content,words", [
    ("day.csv", "input,error,count.label\ncam1/a.mp4,,1\n", "is a table, not a video"),
    ("notes.txt", "not a video\n" * 20, "is not a video"),
])
def test_report_of_something_it_does_not_read_names_what_it_reads(tmp_path, run_cli, name, content, words):
    bad = tmp_path / name
    bad.write_text(content)
    code, out, err = run_cli("report", bad, "-o", tmp_path / "r.html")
    assert code == 1 and out == ""
    lines = err.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith(f"Error: {bad} {words}: report reads a video"), err
    assert "the .jsonl results of 'wallcli scan'" in lines[0]
    assert "Errno" not in err and "Traceback" not in err  # FFmpeg's words at most, never PyAV's errno
    assert sorted(p.name for p in tmp_path.iterdir()) == [name]
