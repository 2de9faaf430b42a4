"""evaluate's table and --plot say the same bands (issue 61 point 5): "nobody moving" (the contract's
"empty" band holds a person standing still too), under 0 dB, 0-10 dB, 10 dB and over, on the same
figure; and the figure's "ECE" is explained where it appears."""
from __future__ import annotations

import numpy as np

from test_pool_and_report import _row


def _result():
    from wallcli.evaluate.run import report

    rows = [_row("empty.mp4", 0, 0), _row("standing.mp4", 0, 0), _row("faint.mp4", 1, 0, confident=False),
            _row("mid.mp4", 1, 1), _row("loud.mp4", 1, 1), _row("bad.mp4", 1, None, error="bad clip")]
    # the block SNR (snr_db), the answers' signal_db and the column SNR (what the bands are on) differ
    for r, snr, column in zip(rows, (-3, -2, 7.0, 8.0, 30.0, None), (-20, -15, -4.0, 5.0, 12.0, None)):
        r["snr_db"], r["signal_db"], r["column_snr_db"] = snr, (None if snr is None else snr - 9), column
    return report(rows, task="count", model={"name": "m", "version": "1", "sha256": "0"}, classes=[0, 1, 2],
                  folder="d", labels="labels.csv", skipped=[], stride=64, roi=None)


def _drawn(monkeypatch, tmp_path):
    import wallcli.plots.reliability as rel

    figs = []
    monkeypatch.setattr(rel, "save_figure", lambda fig, path, force=False: figs.append(fig))
    res = _result()
    rel.save_reliability_png(tmp_path / "r.png", res)
    return res, figs[0].axes


def test_the_table_says_nobody_moving_and_the_json_keeps_empty(capsys):
    from wallcli.cli._evaluate_table import print_evaluation

    res = _result()
    assert [b["band"] for b in res["by_band"]][:4] == ["empty", "<0 dB", "0-10 dB", ">=10 dB"]
    print_evaluation(res)
    out = " ".join(capsys.readouterr().out.split())
    assert "nobody moving 2" in out and "empty rooms" not in out


def test_the_plot_draws_the_tables_bands_on_the_tables_figure(monkeypatch, tmp_path):
    res, (ax_r, ax_s) = _drawn(monkeypatch, tmp_path)
    words = [t.get_text() for t in ax_s.texts]
    for name in ("nobody moving", "under 0 dB", "0-10 dB", "10 dB and over"):
        assert name in words
    # each band's bar spans that band: edges at 0 and 10 dB only (not the -5/5 dB of by_snr)
    spans = {tuple(np.round(seg[:, 0], 3)) for c in ax_s.collections if hasattr(c, "get_segments")
             for seg in c.get_segments()}
    inner = {x for lo_hi in spans for x in lo_hi if -30 < x < 20}
    assert 0.0 in inner and 10.0 in inner and not inner & {-5.0, 5.0}
    # the clips are placed by column_snr_db (-4, 5, 12), as the table's figure, not by snr_db (7, 8, 30)
    # nor signal_db (-2, -1, 21)
    xs = sorted(float(x) for c in ax_s.collections if hasattr(c, "get_offsets") and len(c.get_offsets())
                and c.get_label() in ("right", "wrong") for x in c.get_offsets()[:, 0])
    from wallcli.plots.reliability import NOBODY_X

    assert xs == [NOBODY_X, NOBODY_X, -4.0, 5.0, 12.0]
    assert "as in the terminal's table" in ax_s.get_xlabel() and "1 clip(s) without a figure" in ax_s.get_xlabel()


def test_the_plot_explains_its_ece(monkeypatch, tmp_path):
    res, (ax_r, ax_s) = _drawn(monkeypatch, tmp_path)
    title = ax_r.get_title("left")
    assert f"calibration error (ECE) {res['reliability']['ece']:.2f}" in title
    assert "ECE, the calibration error" in ax_r.get_xlabel() and "0 = " in ax_r.get_xlabel()
