"""``wallcli evaluate --plot``: is the model's confidence worth anything, and where does it stop
seeing? Left, a reliability diagram: the clip answers binned by their probability, each bin's
accuracy against its mean confidence (on the diagonal = calibrated), with its clip count, and
the calibration error (ECE) explained under it. Right, the clips right or wrong by band: the
terminal table's bands (nobody moving, under 0 dB, 0-10 dB, 10 dB and over) on the table's own
figure (labels.csv's snr_db, else the measured column SNR, column_snr_db), each band's share right drawn over it.
The right panel used to draw other bands (-5, 0, 5, 10 dB edges) on another figure (the block SNR),
so the figure and the table disagreed about the same clips."""
from __future__ import annotations

import numpy as np

from wallcli.plots.figure import new_figure, save_figure
from wallcli.wording import BAND_TEXT

LEFT = -30.0  # dB: lower figures (and -99, nothing measured) are drawn at this edge
NOBODY_X = -38.0  # where the clips with nobody moving are drawn: apart from every dB value
SPAN = {"<0 dB": (LEFT, 0.0), "0-10 dB": (0.0, 10.0)}  # ">=10 dB" runs to the right edge
ECE_NOTE = ("ECE, the calibration error: the clips' mean gap between a bin's confidence\n"
            "and its accuracy (0 = a probability of 0.8 is right 80 % of the time)")


def save_reliability_png(path, result: dict, *, force: bool = False) -> None:
    fig, (ax_r, ax_s) = new_figure(1, 2, figsize=(11, 4.8), constrained_layout=True)
    _reliability(ax_r, result)
    _bands(ax_s, result)
    save_figure(fig, path, force=force)


def _reliability(ax, result: dict) -> None:
    rel = result["reliability"]
    ax.plot([0, 1], [0, 1], color="0.6", lw=1, ls="--", label="calibrated")
    for b in rel["bins"]:
        lo, hi = b["confidence"]
        ax.bar((lo + hi) / 2, b["accuracy"], width=hi - lo, color="C0", alpha=0.35, edgecolor="C0")
        ax.plot(b["mean_confidence"], b["accuracy"], "o", color="C0")
        ax.annotate(str(b["clips"]), ((lo + hi) / 2, b["accuracy"]), textcoords="offset points", xytext=(0, 3),
                    ha="center", fontsize=8)
    ax.set_xlim(0, 1)
    ax.set_ylim(0, 1.08)
    ax.set_xlabel("confidence of the clip answer (its probability)\n" + ECE_NOTE, fontsize=9)
    ax.set_ylabel("accuracy (clips per bin above the bars)")
    ece = rel["ece"]
    m = result["model"]
    ax.set_title(f"{result['task']} {m['name']} {m['version']} on {result['dir']}: "
                 f"{_pct(result['accuracy'])} right"
                 + (f", calibration error (ECE) {ece:.2f}" if ece is not None else ""), fontsize=9, loc="left")
    ax.legend(loc="upper left", fontsize=8)


def _figure(row: dict, labels: bool):
    """The figure a row's band is on, as the terminal's table shows it (cli/_evaluate_table._snr)."""
    return row.get("snr_db_labels", row.get("snr_db")) if labels else row.get("column_snr_db")


def _bands(ax, result: dict) -> None:
    labels = result.get("snr_source") == "labels"
    rows = [r for r in result["rows"] if "band" in r]
    xs, ok, undecided, unplaced = [], [], [], 0
    for r in rows:
        if r["band"] == "empty":
            x = NOBODY_X
        else:
            value = _figure(r, labels)
            if value is None:  # failed, or a plot file without a measured figure: counted, not placed
                unplaced += 1
                continue
            x = max(float(value), LEFT)
        xs.append(x)
        ok.append(r.get("error") is None and r.get("label") == r.get("truth"))
        undecided.append(r.get("confident") is not True)
    right_edge = max([20.0, *(x + 2 for x in xs)])
    if xs:
        x, hit, und = np.array(xs), np.array(ok, bool), np.array(undecided, bool)
        jitter = np.random.default_rng(0).uniform(-0.04, 0.04, len(x))
        for sel, colour, label in ((hit, "C2", "right"), (~hit, "C3", "wrong")):
            ax.scatter(x[sel], hit[sel] + jitter[sel], s=18, color=colour, label=label, zorder=3)
        if und.any():
            ax.scatter(x[und], hit[und] + jitter[und], s=60, facecolors="none", edgecolors="0.2",
                       label="undetermined", zorder=4)
    for b in result["by_band"]:
        if not b["clips"] or b["band"] not in (*SPAN, "empty", ">=10 dB"):
            continue
        lo, hi = ((NOBODY_X - 3, NOBODY_X + 3) if b["band"] == "empty"
                  else SPAN.get(b["band"], (10.0, right_edge)))
        acc = b["correct"] / b["clips"]
        ax.hlines(acc, lo, hi, color="C0", lw=2.5)
        ax.annotate(f"{b['correct']}/{b['clips']}", ((lo + hi) / 2, acc), textcoords="offset points",
                    xytext=(0, 4), ha="center", fontsize=8, color="C0")
    for edge in (0.0, 10.0):  # the bands' edges, named above the panel
        ax.axvline(edge, color="0.75", lw=0.8, ls=":")
    ax.axvline((NOBODY_X + LEFT) / 2 - 0.5, color="0.4", lw=0.8)
    for name, (lo, hi) in ({"empty": (NOBODY_X - 3, NOBODY_X + 3), **SPAN, ">=10 dB": (10.0, right_edge)}).items():
        ax.text((lo + hi) / 2, 1.13, BAND_TEXT[name], ha="center", va="bottom", fontsize=8, color="0.3")
    ticks = [t for t in range(-30, int(right_edge) + 1, 10)]
    ax.set_xticks([NOBODY_X, *ticks])
    ax.set_xticklabels(["nobody\nmoving", *(f"<={t}" if t == LEFT else str(t) for t in ticks)], fontsize=8)
    ax.set_xlim(NOBODY_X - 4, right_edge)
    ax.set_ylim(-0.1, 1.22)
    ax.set_yticks([0, 0.25, 0.5, 0.75, 1])
    what = ("SNR from labels.csv's snr_db (dB)" if labels else
            "measured column SNR (column_snr_db, dB: the figure every command prints first)")
    ax.set_xlabel(what + "\nbands and figure as in the terminal's table" +
                  (f"; {unplaced} clip(s) without a figure not drawn" if unplaced else ""), fontsize=9)
    ax.set_ylabel("right (1) / wrong (0); bars: share right per band")
    n = len(rows)
    ax.set_title(f"clips right by band (all {n} scored clip{'' if n == 1 else 's'})", fontsize=9, loc="left")
    if xs:
        ax.legend(loc="upper center", bbox_to_anchor=(0.5, -0.22), ncol=3, fontsize=8)


def _pct(x) -> str:
    return "-" if x is None else f"{100 * x:.0f} %"
