"""evaluate's terminal view: 80 columns, one line a clip under the figures, plurals, a late progress bar."""
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
                     "snr_db": None if err else -20.0 + i, "signal_db": None if err else -30.0 + i / 2,
                     "column_snr_db": None if err else -10.0 + i / 4,
                     "detectable": i % 4 != 1, "error": err,
                     "reason": f"p=0.{i:03d} for '{label}' at signal {i - 20} dB: answers like this were right 97 % of "
                               "the time in validation only from p=0.994"})
    return report(rows, task="activity", model={"name": "wallcli-activity", "version": "0.3.1", "sha256": "0"},
                  classes=ACTS, folder="transfer", labels="labels.csv",
                  skipped=[(f"s{k}.mp4", "more than one person (activity is defined for one)") for k in range(skipped)],
                  stride=64, roi=None)


def test_sixty_clips_fit_80_columns_one_line_each(monkeypatch, capsys):
    """The figures on top (bands, then decided), then one line a clip: the answer with '?' when
    undetermined, the truth, right or not, one SNR named in the header; no footnote per row (120
    clips took 265 lines)."""
    from wallcli.cli._evaluate_table import print_evaluation

    monkeypatch.setattr(output.console_out, "width", 80)
    print_evaluation(_result(60, 1))
    lines = capsys.readouterr().out.splitlines()
    assert max(len(x) for x in lines) <= 80
    assert lines[:2] == ["transfer (labels: labels.csv)", "activity by wallcli-activity 0.3.1, 60 clips"]
    order = [next(i for i, x in enumerate(lines) if x.startswith(t)) for t in ("By column SNR band", "Summary", "Confusion",
                                                                               "activity by wallcli-activity 0.3.1, per clip")]
    assert order == sorted(order)  # bands and decided figures first, the clips last
    head = lines[order[-1] + 1]
    assert head.split() == ["file", "det", "truth", "answer", "p", "%", "right", "column", "SNR", "dB"]
    top = order[-1] + 2  # the rule under the header
    assert lines[top].startswith("─")
    clip_lines = lines[top + 1:top + 61]
    res = _result(60, 1)
    for r, x in zip(res["rows"], clip_lines):  # whole names, not cut; one line each
        cells = x.split()
        assert cells[0] == r["file"]
        if r["error"]:
            assert "error" in cells
        else:
            shown = cells[3:5] if r["confident"] is False else cells[3:4]
            assert shown == ([r["label"], "?"] if r["confident"] is False else [r["label"]])
            assert ("yes" if r["correct"] else "no") in cells and cells[-1] == f"{r['column_snr_db']:.1f}"
    rest = "\n".join(lines[top + 61:])
    above = " ".join(" ".join(lines[order[-2]:order[-1]]).split())  # between the confusion and the clips
    # the columns' meaning heads the table; without the labels' snr_db, the bands are on the column SNR
    assert "?: undetermined" in above and "column SNR dB: the measured column SNR" in above
    assert "only from p=" not in "\n".join(lines) and "[1]" not in "\n".join(lines)
    assert "Invalid data found" in rest and "1 clip skipped: more than one person" in "\n".join(lines)
    assert len(lines) <= 60 + 50  # one line a clip, plus the figures


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
