"""Issue 61, points 9-14: help and docs say what the tool does (each test failed on the old text)."""
from __future__ import annotations

import re
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]


def _help(run_cli, command: str) -> str:
    code, out, err = run_cli(command, "--help")
    assert code == 0, err
    return " ".join(out.split())  # the help is wrapped to the terminal: compare words, not lines


# 9 ------------------------------------------------------------ help that contradicts the tool
def test_track_help_gives_the_measured_rate_not_about_half(run_cli):
    text = _help(run_cli, "track")
    assert "about half" not in text
    assert "17 of the 28" in text and "61 %" in text
    # the README and research/track/README.md quote the same figure
    assert "61 %" in (ROOT / "README.md").read_text()
    assert "17 of 28 (61 %)" in (ROOT / "research" / "track" / "README.md").read_text()


def test_track_follow_help_names_the_16_s_chunks_and_their_12_s_step(run_cli):
    from wallcli.signal.track import CHUNK_SECONDS, OVERLAP_SECONDS

    text = _help(run_cli, "track")
    assert f"{CHUNK_SECONDS:g} s chunks, one every {CHUNK_SECONDS - OVERLAP_SECONDS:g} s" in text


@pytest.mark.parametrize("command", ["stplot", "snr", "amplify", "report"])
def test_stall_timeout_help_does_not_mention_a_follow_the_command_lacks(run_cli, command):
    text = _help(run_cli, command)
    assert "--stall-timeout" in text and "--follow" not in text


@pytest.mark.parametrize("command", ["count", "activity", "track"])
def test_stall_timeout_help_keeps_the_follow_default_where_follow_exists(run_cli, command):
    assert "for ever with --follow" in _help(run_cli, command)


@pytest.mark.parametrize("command", ["stplot", "snr", "amplify", "report", "count", "activity", "track",
                                     "evaluate", "simulate", "train"])
def test_force_help_reads_as_english(run_cli, command):
    text = _help(run_cli, command)
    assert "--force" in text
    assert "files if it exists" not in text and ",;" not in text and ", if it exists" not in text


@pytest.mark.parametrize("command", ["count", "activity"])
def test_window_starts_are_explained_where_the_user_reads_them(run_cli, tmp_path, command):
    text = _help(run_cli, command)
    assert "0, 2.13 and 3.47 s" in text  # what the table of a 12 s clip shows, explained beside it
    assert "ends where the clip ends" in text


def test_a_12_s_clip_has_the_window_starts_the_help_quotes():
    from wallcli.signal.window import window_starts

    fps_frames = 360  # 12 s at 30 fps, as examples/walking.mp4
    starts = [round(s / 30, 2) for s in window_starts(fps_frames, 256, 64)]
    assert starts == [0.0, 2.13, 3.47]


# 10 ----------------------------------------------------------------------- docs/models.md
def _sections(path: Path) -> list[tuple[str, str]]:
    """(heading, the text up to the next heading) of each heading of a Markdown page."""
    out, head, body = [], None, []
    for line in path.read_text().splitlines():
        if line.startswith("#"):
            if head is not None:
                out.append((head, "\n".join(body)))
            head, body = line, []
        else:
            body.append(line)
    out.append((head, "\n".join(body)))
    return out


def test_models_doc_has_no_empty_heading_and_no_loose_parenthesis():
    for head, body in _sections(ROOT / "docs" / "models.md"):
        paragraphs = [p.strip() for p in body.split("\n\n") if p.strip()]
        assert paragraphs, f"empty section: {head}"
        # a section that opens with an aside in brackets is an aside to a table that is not there
        assert not paragraphs[0].startswith("("), head
    assert "count 10 and 26" not in (ROOT / "docs" / "models.md").read_text()


# 11 ---------------------------------------------------------------------- models/README.md
_BANDS = {"empty rooms": "empty", "under 0 dB (not detectable)": "<0 dB", "0–10 dB": "0-10 dB",
          "10 dB and over": ">=10 dB"}


def test_models_page_is_what_ships_and_how_it_does_by_band():
    import json

    page = (ROOT / "models" / "README.md").read_text()
    cards = {t: json.loads((ROOT / "models" / f"{t}.json").read_text()) for t in ("count", "activity")}
    for task, card in cards.items():
        assert f"{task} {card['version']}" in page  # the shipped versions, read from the cards
    assert "count 0.4.1 and activity 0.3.1" not in page  # what it said it shipped before
    rows = {}
    for line in page.splitlines():
        cells = [c.strip() for c in line.strip().strip("|").split("|")]
        if line.startswith("|") and cells[0] in _BANDS:
            rows[_BANDS[cells[0]]] = cells[1:]
    assert set(rows) == set(_BANDS.values())
    for col, task in enumerate(("count", "activity")):
        by_band = cards[task]["recordings"]["out_of_fold"]["by_band"]
        for band, cells in rows.items():
            assert cells[col] == f"{by_band[band]['right']} of {by_band[band]['clips']}", (task, band)
        det = cards[task]["recordings"]["out_of_fold"]["detectable"]
        assert f"{det['right']} of {det['clips']}" in page
    assert f"{cards['count']['recordings']['clips']} labelled clips" in page
    for section in ("## What they learnt from", "## How they do, by signal band", "## Limits"):
        assert section in page
    # the lab notebook lives in research/, not on the page a user reads
    for notebook_word in ("proxy set", "superposition 0.2", "anneal", "120 clips"):
        assert notebook_word not in page
    assert len(page.splitlines()) < 150
    notebook = ROOT / "research" / "models-notebook.md"
    assert "research/models-notebook.md" in page and "anneal" in notebook.read_text()


# 12 ----------------------------------------------------------------- the report's limits
def test_report_says_what_the_shipped_models_learnt_from_as_its_limits_and_adapt_do():
    from wallcli.infer.model import load_model
    from wallcli.report.cards import model_summary

    adapt = " ".join((ROOT / "docs" / "adapt.md").read_text().split())
    assert "simulated rooms and from labelled rendered clips of other rooms" in adapt
    for task in ("count", "activity"):
        limits = " ".join(model_summary(load_model(task))["limits"])
        assert "simulated rooms only" not in limits
        assert "simulated rooms and from labelled rendered clips of other rooms" in limits
        assert "never from camera footage" in limits
    template = (ROOT / "wallcli" / "report" / "templates" / "clip.html.j2").read_text()
    assert "simulated rooms and from labelled rendered clips of other rooms" in template


def test_report_does_not_say_a_users_own_model_never_saw_camera_footage(tmp_path):
    import shutil

    from wallcli.infer.model import load_model, shipped_model_path
    from wallcli.report.cards import model_summary

    src = shipped_model_path("count")
    shutil.copy(src, tmp_path / "mine.onnx")
    shutil.copy(src.with_suffix(".json"), tmp_path / "mine.json")
    limits = " ".join(model_summary(load_model("count", tmp_path / "mine.onnx"))["limits"])
    assert "never from camera footage" not in limits and "its card's training_data" in limits


# 14 ------------------------------------------------------------- docs/adapt.md's --init
def test_every_documented_init_names_a_file_of_the_checkout():
    """`--init "$(python -c ...)"` ran whichever python came first on PATH (not the venv's);
    the README's `--init models/count.onnx` works from the checkout's top folder."""
    pages = [ROOT / "README.md", *sorted((ROOT / "docs").glob("*.md")), ROOT / "models" / "README.md"]
    found = 0
    for page in pages:
        text = page.read_text()
        assert "$(python" not in text, page.name
        for arg in re.findall(r"--init ([^\s`\\]+)", text):
            if arg in ("M0.onnx",):  # the README's synopsis names a placeholder
                continue
            assert (ROOT / arg).is_file(), (page.name, arg)
            found += 1
    assert found >= 3


# 13 ------------------------------------------------------------------------------- README
README = (ROOT / "README.md").read_text()


def _readme_pipeline_lines() -> list[str]:
    block = README.split("\nPipelines", 1)[1]
    return [ln for ln in re.search(r"```bash\n(.*?)```", block, re.S).group(1).splitlines() if ln.strip()]


def test_pipeline_lines_write_under_out_not_the_checkouts_top():
    written = []
    for line in _readme_pipeline_lines():
        code = line.split("  #")[0]
        written += re.findall(r"(?:-o|--png|--plot|--heatmap|--csv)\s+(\S+)", code)
        for m in re.finditer(r"wallcli \w+ (\S+\.npz)", code):
            written.append(m.group(1))
    assert written and all(w.startswith("out/") for w in written), written


def test_quick_start_names_every_command_pipeline_sh_runs():
    script = (ROOT / "examples" / "pipeline.sh").read_text()
    ran = set(re.findall(r"^\$w (\w+)", script, re.M))
    assert "track" in ran
    quick = README.split("## Quick start", 1)[1].split("\n## ", 1)[0]
    assert {c for c in ran if f"`{c}`" not in quick} == set()


def test_the_follow_lines_comment_says_the_last_line_is_the_whole_clip(run_cli):
    import json

    line = next(ln for ln in _readme_pipeline_lines() if "--follow" in ln)
    assert "then one for the whole clip" in line
    code, out, err = run_cli("activity", ROOT / "examples" / "walking.mp4", "--follow")
    records = [json.loads(x) for x in out.splitlines()]
    assert code == 0 and len(records) >= 2, err
    assert "windows" in records[-1] and all("windows" not in r for r in records[:-1])


def test_the_report_pictures_caption_is_the_command_its_script_runs():
    caption = re.search(r"\*`(wallcli report [^`]+)`, top of the page", README).group(1)
    script = (ROOT / "examples" / "report_screenshot.sh").read_text()
    ran = re.search(r"^\$W (report .+)$", script, re.M).group(1)
    assert caption == f"wallcli {ran}"
    assert "out/" in caption  # outside examples/, as every output of the examples


# 16 (second half) ----------------------------------------------------------------- research/
_OTHERS = ("render", "snr")  # folders of work in progress elsewhere, not this page's to judge


def _research_pages() -> list[Path]:
    pages = [ROOT / "research" / "README.md", *sorted((ROOT / "research").glob("*/README*.md")),
             ROOT / "research" / "models-notebook.md"]
    return [p for p in pages if p.parent.name not in _OTHERS]


def test_research_pages_say_when_not_which_ticket_or_work_period():
    inside = re.compile(r"\b(issues?|sessions?)[ -]#?\d+|(?<![\w/])#\d+\b|\bsessions?\b", re.I)
    found = {str(p.relative_to(ROOT)): inside.findall(p.read_text()) for p in _research_pages()}
    assert {k: v for k, v in found.items() if v} == {}
    assert len(found) >= 15


def test_research_keeps_no_stale_patches_and_no_raw_verdict_logs():
    files = [p for p in (ROOT / "research").rglob("*") if p.is_file()
             and not any(part in _OTHERS for part in p.relative_to(ROOT / "research").parts[:1])]
    assert not [p for p in files if p.suffix == ".patch"]  # kept in git history, named by commit
    big_text = [p for p in files if p.suffix in (".jsonl", ".log") and p.stat().st_size > 100_000]
    assert big_text == []
    # the view check's verdicts, which back docs/real-footage.md's figures, are kept compressed
    import gzip
    import json

    for name in ("moving_object", "cuts", "sharp_light"):
        lines = gzip.open(ROOT / "research" / "view" / f"verdicts_{name}.jsonl.gz", "rt").read().splitlines()
        assert len(lines) > 500 and all("file" in json.loads(x) for x in lines)
        assert f"verdicts_{name}.jsonl.gz" in (ROOT / "research" / "view" / "README.md").read_text()
