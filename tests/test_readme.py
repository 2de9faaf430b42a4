"""The README as a newcomer reads it: the two quick-start commands on top, one-liners that print
an answer only when it is decided, figures that agree with its own tables, links that lead
somewhere, and the test suite's stated wall time."""
from __future__ import annotations

import re
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
README = (ROOT / "README.md").read_text(encoding="utf-8")
DOCS = sorted((ROOT / "docs").glob("*.md"))


def _code_lines(text: str) -> list[str]:
    blocks = re.findall(r"```[a-z]*\n(.*?)```", text, re.S)
    return [line for b in blocks for line in b.splitlines()]


def test_quick_start_is_the_two_commands_on_top():
    quick = README.split("## Quick start", 1)[1].split("\n## ", 1)[0]
    commands = [line.split("#")[0].strip() for line in _code_lines(quick)]
    assert commands == ["bash examples/pipeline.sh", "bash tests/run.sh"]
    assert README.index("## Quick start") < 1500  # the newcomer meets it first


def test_one_liners_print_an_answer_only_when_it_is_decided():
    """A jq filter that prints a count or activity label checks `confident` first (a bare
    `.label` printed an answer for a refused view as if it were one)."""
    lines = [line for doc in [README] + [d.read_text(encoding="utf-8") for d in DOCS] for line in _code_lines(doc)
             if "jq" in line and "label" in line]
    assert lines  # the README shows scripts how to read answers
    for line in lines:
        assert "confident" in line, line


def test_the_decided_figures_in_the_text_are_the_tables():
    """'activity's decided answers X right of Y' beside a table whose detectable row says 'Y (X)'."""
    said = re.search(r"activity's decided answers (\d+) right of (\d+)", " ".join(README.split()))
    assert said, "the README states activity's decided answers"
    row = next(line for line in README.splitlines() if line.startswith("| **detectable** |"))
    decided = row.strip("|").split("|")[-1].strip()
    assert decided == f"{said.group(2)} ({said.group(1)})"


def test_links_lead_somewhere():
    for doc in [ROOT / "README.md", *DOCS]:
        for target in re.findall(r"\]\(([^)#\s]+)(?:#[^)]*)?\)", doc.read_text(encoding="utf-8")):
            if target.startswith(("http://", "https://")):
                continue
            assert (doc.parent / target).exists(), f"{doc.name}: {target}"


def test_the_suites_wall_time_is_stated_and_within_ten_minutes():
    dev = README.split("## Development", 1)[1].split("\n## ", 1)[0]
    minutes = re.search(r"takes about (\d+) minutes", dev)
    assert minutes and int(minutes.group(1)) <= 10
    assert "-m slow" in dev or "not slow" in dev  # the split is explained
