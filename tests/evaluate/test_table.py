"""evaluate's terminal view: 80 columns with long reasons in footnotes, plurals, a late progress bar."""
from __future__ import annotations

import io
import time

import pytest

from wallcli.cli import output

ACTS = ["none", "walking", "crouching", "waving", "jumping"]


def _result(n: int, skipped: int) -> dict:
    from wallcli.evaluate.run import report

    rows = []
    for i in range(n):
        truth, label = ACTS[i % 5], ACTS[(i // 2) % 5]
        p = [0.05] * 5
        p[ACTS.index(label)] = 0.8
        err = f"cannot decode t{i:03d}_p1_{truth}.mp4: Invalid data found when processing input" if i % 17 == 5 else None
        rows.append({"file": f"t{i:03d}_p1_{truth}.mp4", "truth": truth, "label": None if err else label,
                     "confident": None if err else i % 3 == 0, "probabilities": None if err else p,
                     "snr_db": None if err else -20.0 + i, "detectable": i % 4 != 1, "error": err,
                     "reason": f"p=0.{i:03d} for '{label}' at {i - 20} dB; 97% right only from p=0.994"})
    return report(rows, task="activity", model={"name": "wallcli-activity", "version": "0.3.1", "sha256": "0"},
                  classes=ACTS, folder="transfer", labels="labels.csv",
                  skipped=[(f"s{k}.mp4", "more than one person (activity is defined for one)") for k in range(skipped)],
                  stride=64, roi=None)


def test_sixty_clips_fit_80_columns_one_line_each(monkeypatch, capsys):
    from wallcli.cli._evaluate_table import print_evaluation

    monkeypatch.setattr(output.console_out, "width", 80)
    print_evaluation(_result(60, 1))
    lines = capsys.readouterr().out.splitlines()
    assert max(len(x) for x in lines) <= 80
    top = lines.index(next(x for x in lines if x.startswith("─")))  # the rule under the header
    bottom = lines.index(next(x for x in lines[top:] if x.startswith("[1] ")))  # the footnotes follow the rows
    assert bottom - top - 1 == 60  # no row wraps
    res = _result(60, 1)
    assert all(r["file"] in x for r, x in zip(res["rows"], lines[top + 1:bottom]))  # whole names, not cut
    text = "\n".join(lines)
    assert "undetermined [1]" in text and "\n[1] p=0.001 for 'none' at -19 dB; 97% right only from p=0.994" in text
    assert "error [" in text and "Invalid data found" in "\n".join(lines[bottom:])
    assert lines[:2] == ["transfer (labels: labels.csv)", "activity by wallcli-activity 0.3.1, 60 clips"] and "\n1 clip skipped: more than one person" in text
    assert len(lines) < 2 * 60 + 40  # footnotes: a line or two each, not five lines a row as before


def test_plurals():
    from wallcli.cli._evaluate_table import plural

    assert [plural(1, "person"), plural(2, "person"), plural(0, "clip"), plural(1, "clip")] == \
        ["1 person", "2 people", "0 clips", "1 clip"]


@pytest.mark.parametrize("work,shown", [(0.0, False), (1.5, True)])
def test_the_progress_bar_waits_before_it_appears(monkeypatch, work, shown):
    from rich.console import Console

    buf = io.StringIO()
    monkeypatch.setattr(output, "console_err", Console(file=buf, force_terminal=True, width=80))
    with output.progress("evaluate count", 3, delay=0.3) as advance:
        time.sleep(work)
        advance(1)
    assert ("evaluate count" in buf.getvalue()) is shown
