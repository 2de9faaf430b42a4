"""The worker pool's crash isolation, and the figures and table of wallcli evaluate from rows."""
from __future__ import annotations

import pytest

from wallcli.evaluate.pool import DIED, imap_isolated


def test_a_worker_that_dies_is_one_items_error_and_the_rest_finish():
    import crashy

    items = [1, 2, "die", 3, 4, 5]
    got = dict(imap_isolated(crashy.square_or_die, items, jobs=2))
    assert got == {0: 1, 1: 4, 2: {"error": DIED}, 3: 9, 4: 16, 5: 25}


def _row(file, truth, label, confident=True, snr=0.0, error=None, p=0.9, detectable=None):
    probs = None if error else ([p, 1 - p, 0.0] if label == 0 else [0.0, p, 1 - p] if label == 1 else [0.0, 1 - p, p])
    return {"file": file, "truth": truth, "label": None if error else label, "confident": None if error else confident,
            "probabilities": probs, "snr_db": None if error else snr, "detectable": detectable, "error": error,
            "reason": None if confident else "signal 3 dB under the model's validated range"}


def test_decided_coverage_confusion_and_bands_from_rows():
    from wallcli.evaluate.run import report

    rows = [_row("a", 0, 0, snr=-12.0), _row("b", 1, 1, snr=3.0), _row("c", 1, 0, confident=False, snr=-8.0),
            _row("d", 2, 1, snr=12.0), _row("e", 2, 2, snr=14.0, detectable=False), _row("f", 1, None, error="bad clip"),
            _row("g", 0, 0, snr=-30.0, detectable=True)]
    res = report(rows, task="count", model={"name": "m", "version": "1", "sha256": "0"}, classes=[0, 1, 2],
                 folder="d", labels="labels.csv", skipped=[], stride=64, roi=None)
    # headline: every clip not labelled undetectable (e is out); f's error is wrong and undecided
    assert (res["clips"], res["scored"], res["errors"]) == (7, 6, 1)
    assert res["accuracy"] == pytest.approx(3 / 6)
    assert (res["decided"], res["coverage"], res["accuracy_decided"]) == (4, pytest.approx(4 / 6), pytest.approx(3 / 4))
    assert res["confusion"] == [[2, 0, 0], [1, 1, 0], [0, 1, 0]] and res["errors_by_class"] == [0, 1, 0]
    assert res["all"]["scored"] == 7 and res["all"]["accuracy"] == pytest.approx(4 / 7)
    assert res["all"]["confusion"][2] == [0, 1, 1]
    lo, hi = res["ci95"]
    assert lo < 0.5 < hi and res == report(rows, task="count", model=res["model"], classes=[0, 1, 2], folder="d",
                                           labels="labels.csv", skipped=[], stride=64, roi=None)  # the same rows, the same figures
    bands = {tuple(b["snr_db"]) if b["snr_db"] else None: (b["clips"], b["correct"]) for b in res["by_snr"]}
    assert bands == {(None, -5.0): (3, 2), (0.0, 5.0): (1, 1), (10.0, None): (1, 0), None: (1, 0)}
    assert [c["clips"] for c in res["per_class"]] == [2, 3, 1]
    rel = res["reliability"]
    assert rel["bins"] == [{"confidence": [0.9, 1.0], "clips": 5, "mean_confidence": pytest.approx(0.9), "accuracy": 0.6}]
    assert rel["ece"] == pytest.approx(0.3)


def test_the_table_marks_undetermined_answers_and_names_failures(capsys):
    from wallcli.cli._evaluate_table import print_evaluation
    from wallcli.evaluate.run import report

    rows = [_row("a.mp4", 1, 1), _row("b.mp4", 1, 0, confident=False), _row("c.mp4", 0, None, error="no such file: c.mp4")]
    res = report(rows, task="count", model={"name": "m", "version": "1", "sha256": "0"}, classes=[0, 1, 2],
                 folder="d", labels="labels.csv", skipped=[], stride=64, roi=None)
    print_evaluation(res)
    out = " ".join(capsys.readouterr().out.split())
    assert "b.mp4 1 0 ? " in out and "[1]" not in out  # the answer with '?', no footnote
    assert "c.mp4 0 error" in out and "1 clip failed: no such file: c.mp4" in out
    assert "right 1 (33.3 %)" in out and "decided 1 (33 %)" in out  # right; decided (coverage)


def test_the_interval_memory_does_not_grow_with_the_clips():
    """Issue 38 item 7: 100 000 rows (missing clips count as wrong) once took resamples x rows;
    the exact interval (issue 54) holds a few arrays of one row each."""
    import tracemalloc

    import numpy as np

    from wallcli.evaluate.score import exact_ci_of

    hits = np.zeros(100_000, bool)
    hits[:30_000] = True
    tracemalloc.start()
    lo, hi = exact_ci_of(hits)
    peak = tracemalloc.get_traced_memory()[1]
    tracemalloc.stop()
    assert peak < 20e6 and lo < 0.3 < hi and hi - lo < 0.01
