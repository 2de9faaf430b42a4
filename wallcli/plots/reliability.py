"""``wallcli evaluate --plot``: is the model's confidence worth anything, and where does it stop
seeing? Left, a reliability diagram: the clip answers binned by their probability, each bin's
accuracy against its mean confidence (on the diagonal = calibrated), with its clip count. Right,
each clip's measured SNR against whether its answer was right, with the accuracy per SNR band."""
from __future__ import annotations

import numpy as np

from wallcli.plots.figure import new_figure, save_figure


def save_reliability_png(path, result: dict, *, force: bool = False) -> None:
    fig, (ax_r, ax_s) = new_figure(1, 2, figsize=(11, 4.6), constrained_layout=True)
    rel = result["reliability"]
    ax_r.plot([0, 1], [0, 1], color="0.6", lw=1, ls="--", label="calibrated")
    for b in rel["bins"]:
        lo, hi = b["confidence"]
        ax_r.bar((lo + hi) / 2, b["accuracy"], width=hi - lo, color="C0", alpha=0.35, edgecolor="C0")
        ax_r.plot(b["mean_confidence"], b["accuracy"], "o", color="C0")
        ax_r.annotate(str(b["clips"]), ((lo + hi) / 2, b["accuracy"]), textcoords="offset points", xytext=(0, 3),
                      ha="center", fontsize=8)
    ax_r.set_xlim(0, 1)
    ax_r.set_ylim(0, 1.08)
    ax_r.set_xlabel("confidence of the clip answer (its probability)")
    ax_r.set_ylabel("accuracy (clips per bin above the bars)")
    ece = rel["ece"]
    m = result["model"]
    ax_r.set_title(f"{result['task']} {m['name']} {m['version']} on {result['dir']}: "
                   f"{_pct(result['accuracy'])} right" + (f", ECE {ece:.2f}" if ece is not None else ""),
                   fontsize=9, loc="left")
    ax_r.legend(loc="upper left", fontsize=8)

    head = [r for r in result["rows"] if r["detectable"] is not False] if "all" in result else result["rows"]
    pts = [(r["snr_db"], r["correct"], r["confident"]) for r in head if r["snr_db"] is not None]
    if pts:
        snr = np.array([p[0] for p in pts], np.float64)
        shown = np.clip(snr, -30, None)  # -99 dB (nothing measured) drawn at the axis' left end
        ok = np.array([p[1] for p in pts], bool)
        undecided = np.array([p[2] is False for p in pts], bool)
        jitter = np.random.default_rng(0).uniform(-0.04, 0.04, len(pts))
        for sel, colour, label in ((ok, "C2", "right"), (~ok, "C3", "wrong")):
            ax_s.scatter(shown[sel], ok[sel] + jitter[sel], s=18, color=colour, label=label, zorder=3)
        if undecided.any():
            ax_s.scatter(shown[undecided], ok[undecided] + jitter[undecided], s=60, facecolors="none",
                         edgecolors="0.2", label="undetermined", zorder=4)
    for b in result["by_snr"]:
        if b["snr_db"] is None:
            continue
        lo, hi = b["snr_db"]
        lo = -30 if lo is None else lo
        hi = (max(35.0, lo + 5) if not pts else max(float(np.max(shown)) + 1, lo + 5)) if hi is None else hi
        ax_s.hlines(b["accuracy"], lo, hi, color="C0", lw=2.5)
        ax_s.annotate(f"{b['correct']}/{b['clips']}", ((lo + hi) / 2, b["accuracy"]), textcoords="offset points",
                      xytext=(0, 4), ha="center", fontsize=8, color="C0")
    ax_s.set_ylim(-0.1, 1.12)
    ax_s.set_yticks([0, 0.25, 0.5, 0.75, 1])
    ax_s.set_xlabel("measured SNR (dB, green, block of one plot bin; <= -30 at the left edge)")
    ax_s.set_ylabel("right (1) / wrong (0); bars: accuracy per band")
    ax_s.set_title(f"accuracy against measured SNR ({result['scored_on']})", fontsize=9, loc="left")
    if pts:
        ax_s.legend(loc="upper center", bbox_to_anchor=(0.5, -0.14), ncol=3, fontsize=8)
    save_figure(fig, path, force=force)


def _pct(x) -> str:
    return "-" if x is None else f"{100 * x:.0f} %"
