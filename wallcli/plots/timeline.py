"""``--plot timeline.png`` of count/activity: class probabilities over time above the
horizontal space-time plot, on one time axis, so a change of answer can be matched to the
streaks that caused it."""
from __future__ import annotations

import numpy as np

from wallcli.plots.figure import new_figure, save_figure
from wallcli.plots.stplot import POSITION_LABELS, auto_gain


def save_timeline_png(path, result: dict, plot, *, force: bool = False) -> None:
    fig, (ax_p, ax_h) = new_figure(2, 1, figsize=(10, 6), sharex=True, constrained_layout=True,
                                   gridspec_kw={"height_ratios": [1, 1.3]})
    wins = result["windows"]
    # each window's answer is drawn at its centre; the shaded band marks the first window's span
    centres = np.array([(w["start"] + w["end"]) / 2 for w in wins])
    probs = np.array([w["probabilities"] for w in wins])
    for k, cls in enumerate(result["classes"]):
        ax_p.plot(centres, probs[:, k], marker="o", ms=3, lw=1.5, label=str(cls))
    if wins:
        span = wins[0]["end"] - wins[0]["start"]
        ax_p.axvspan(wins[0]["start"], wins[0]["end"], color="0.9", zorder=0,
                     label=f"first window's span:\neach dot is the answer\nfor the {span:.1f} s around it")
    ax_p.set_ylim(-0.02, 1.02)
    ax_p.set_ylabel("probability")
    ax_p.legend(loc="upper left", bbox_to_anchor=(1.0, 1.0), fontsize=8, title=result["task"])
    # the answer as the table and the report state it: an undetermined one is not titled as decided
    from wallcli.wording import answer_text

    ax_p.set_title(f"{result['input']}: {result['task']} = {answer_text(result)}, mean of {len(wins)} "
                   f"window{'' if len(wins) == 1 else 's'}", fontsize=10, loc="left")
    g = auto_gain(plot)
    # positions as fractions of the view's width, as stplot's and track's figures give them
    extent = (float(plot.time[0]), float(plot.time[-1]), 1.0, 0.0)
    ax_h.imshow(np.clip(0.5 + g * plot.horizontal, 0.0, 1.0), aspect="auto", extent=extent, interpolation="nearest")
    ax_h.set_ylabel(f"horizontal plot:\n{POSITION_LABELS['horizontal']}", fontsize=9)
    ax_h.set_xlabel("time (s)")
    save_figure(fig, path, force=force)
