"""The README as a newcomer reads it: the two quick-start commands on top, one-liners that print
an answer only when it is decided, figures that agree with its own tables, links that lead
somewhere, and the test suite's stated wall time."""
from __future__ import annotations

import json
import re

import pytest
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
    """The models table's decided columns are the cards' out-of-fold figures, and the text says
    what they mean: 'decides nothing' when both are 0."""
    import json

    row = next(line for line in README.splitlines() if line.startswith("| **detectable** |"))
    cells = [c.strip() for c in row.strip("|").split("|")]
    decided = {"count": cells[2], "activity": cells[4]}
    for task, shown in decided.items():
        card = json.loads((ROOT / "models" / f"{task}.json").read_text())
        det = card["recordings"]["out_of_fold"]["detectable"]
        want = "0" if det["decided"] == 0 else f"{det['decided']} ({det['decided_right']})"
        assert shown == want, task
    if set(decided.values()) == {"0"}:
        assert "decides nothing" in " ".join(README.split())


def test_links_lead_somewhere():
    for doc in [ROOT / "README.md", *DOCS]:
        for target in re.findall(r"\]\(([^)#\s]+)(?:#[^)]*)?\)", doc.read_text(encoding="utf-8")):
            if target.startswith(("http://", "https://")):
                continue
            assert (doc.parent / target).exists(), f"{doc.name}: {target}"


def test_the_suites_figures_agree_and_the_split_is_explicit():
    """The quick start and the development section state the same size, time and install of the
    suite, and the split is a command a reader can copy (`-m 'not slow'`)."""
    quick = README.split("## Quick start", 1)[1].split("\n## ", 1)[0]
    dev = README.split("## Development", 1)[1].split("\n## ", 1)[0]
    tests = re.search(r"≈ (\d+) tests", quick).group(1)
    minutes = re.search(r"~(\d+) min in CI", quick).group(1)
    gb = re.search(r"(\d+\.\d) GB", quick).group(1)
    flat = " ".join(dev.split())
    assert f"about {tests} tests" in flat and f"about {minutes} minutes" in flat and f"about {gb} GB" in flat
    assert "bash tests/run.sh -m 'not slow'" in dev and "bash tests/run.sh -m slow" in dev


def _pipeline_lines() -> list[str]:
    """The lines of the code block under 'Pipelines'."""
    block = README.split("\nPipelines", 1)[1]
    return [line for line in re.search(r"```bash\n(.*?)```", block, re.S).group(1).splitlines() if line.strip()]


def test_every_pipeline_line_runs_as_written_on_a_bundled_clip(tmp_path):
    """The README's pipelines, line after line as a reader types them, by bash (pipefail) in one
    folder beside a link to examples/: each exits 0 with an answer or a file written, no 'Error:'.
    A line whose tool (jq, ffmpeg) is not installed here is left out, saying so."""
    import os
    import shutil
    import subprocess
    import sys
    import warnings

    (tmp_path / "examples").symlink_to(ROOT / "examples")
    env = dict(os.environ, PATH=f"{Path(sys.executable).parent}{os.pathsep}{os.environ['PATH']}")
    lines = _pipeline_lines()
    assert len(lines) >= 4
    for line in lines:
        missing = [t for t in ("jq", "ffmpeg") if t in line.split("#")[0] and shutil.which(t) is None]
        if missing:
            warnings.warn(f"not run, {' and '.join(missing)} not installed here: {line}")
            continue
        p = subprocess.run(["bash", "-o", "pipefail", "-c", line], cwd=tmp_path, env=env, capture_output=True,
                           text=True, timeout=120)
        assert p.returncode == 0 and "Error:" not in p.stderr, (line, p.stderr[-2000:])
        assert p.stdout.strip() or "wrote " in p.stderr, line  # data on stdout, or a file it says it wrote


def test_the_pipelines_chain():
    """The region the first line finds is the one the second line reads, and the count line
    prints the most likely answer where it is undetermined (count decides nothing yet)."""
    import json
    import subprocess
    import sys

    first, second, third, *_ = _pipeline_lines()
    out = subprocess.run([sys.executable, "-m", "wallcli", "snr", "examples/walking.mp4", "--roi", "auto", "--json"],
                         cwd=ROOT, capture_output=True, text=True, check=True).stdout
    roi = ",".join(map(str, json.loads(out)["roi"]))
    assert "join(\",\")" in first and f"--roi {roi} " in second
    assert "most likely" in third and "confident" in third


def test_the_named_test_files_exist():
    for name in re.findall(r"\b(test_\w+\.py|report/test_\w+\.py)\b", README):
        assert (ROOT / "tests" / name).exists() or list((ROOT / "tests").rglob(Path(name).name)), name


def _strings(node) -> list[str]:
    if isinstance(node, str):
        return [node]
    if isinstance(node, dict):
        node = list(node.values())
    return [s for item in node for s in _strings(item)] if isinstance(node, list) else []


def test_user_facing_text_has_no_words_from_inside_the_project(run_cli):
    """No 'issue 35', 'session 20', 'session-4 rows' or 'this session' where users read: README,
    docs, models/README.md and the cards' text (both ship in the wheel), the report's templates,
    --help. A model's version or a date says when. The paper's design is `--arch paper` (`seed`
    stays accepted), a seed a random seed."""
    inside = re.compile(r"\b(issues?|sessions?)[ -]#?\d+|\b(this|that|previous|earlier|later|next) sessions?\b",
                        re.I)
    templates = sorted((ROOT / "wallcli" / "report" / "templates").glob("*"))
    for doc in [ROOT / "README.md", *DOCS, ROOT / "models" / "README.md", *templates]:
        found = inside.findall(doc.read_text(encoding="utf-8"))
        assert not found, (doc.name, found)
    cards = sorted((ROOT / "models").glob("*.json"))
    assert {c.stem for c in cards} >= {"count", "activity"}
    for card in cards:
        found = [s for s in _strings(json.loads(card.read_text(encoding="utf-8"))) if inside.search(s)]
        assert not found, (card.name, found)
    for name in ("count", "activity", "snr", "stplot", "amplify", "simulate", "train", "evaluate", "report", "scan"):
        code, out, _ = run_cli(name, "--help")
        assert code == 0 and not inside.search(out), name
    code, out, _ = run_cli("train", "--help")
    assert "'paper'" in " ".join(out.split()) and "--arch paper" in README


def test_the_contract_says_each_thing_once_in_paragraphs_a_reader_can_hold():
    text = (ROOT / "docs" / "contract.md").read_text(encoding="utf-8")
    for para in re.split(r"\n\n|\n- ", text):  # paragraphs and list items
        assert len(para.split()) < 450, para[:80]
        sentences = [s.strip() for s in re.split(r"(?<=[.!?])\s+", para) if len(s.split()) > 5]
        assert len(sentences) == len(set(sentences)), para[:80]
