"""``wallcli simulate --preview``: the room from above with everyone's path, beside the plots."""

from __future__ import annotations

import numpy as np

from wallcli.plots.figure import new_figure, save_figure
from wallcli.plots.stplot import draw_stplot

COLOURS = ["tab:red", "tab:blue", "tab:green"]


def draw_room(ax, truth: dict) -> None:
    """Top view (x along the observed wall, y = distance from it) from a sidecar dict."""
    persons = truth.get("persons", [])
    if "room" in truth:
        W, D, _ = truth["room"]["size_m"]
        x0, x1 = truth["wall_region_m"][:2]
        ax.add_patch(__import__("matplotlib.patches", fromlist=["Rectangle"]).Rectangle((0, 0), W, D, fill=False, lw=1.5))
        ax.plot([x0, x1], [0, 0], color="orange", lw=6, solid_capstyle="butt", label="wall seen by camera")
        lamps = np.array(truth["room"].get("lamp_positions", [])).reshape(-1, 3)
        if len(lamps):
            ax.scatter(lamps[:, 0], lamps[:, 1], marker="*", s=120, color="gold", edgecolor="k", zorder=3, label="lamps")
        ax.set_xlim(-0.3, W + 0.3)
        ax.set_ylim(D + 0.3, -0.5)
    else:  # flatland
        f = truth["flatland"]
        ax.plot([0, f["width_m"]], [0, 0], color="orange", lw=6, label="receiver")
        ax.axhline(f["depth_m"], color="gold", lw=3, label="emitter")
        ax.set_ylim(f["depth_m"] + 0.3, -0.5)
    for k, p in enumerate(persons):
        pos = np.array(p["positions"])
        c = COLOURS[k % len(COLOURS)]
        ax.plot(pos[:, 0], pos[:, 1], color=c, lw=1.2, label=f"person {k + 1}: {p['activity']}")
        ax.scatter(pos[:1, 0], pos[:1, 1], color=c, marker="o", s=30)
        ax.scatter(pos[-1:, 0], pos[-1:, 1], color=c, marker="s", s=30)
    ax.set_aspect("equal")
    ax.set_xlabel("x along the wall (m)")
    ax.set_ylabel("distance from the wall (m)")
    ax.legend(fontsize=7, loc="lower right")
    from wallcli.wording import label_text

    ax.set_title(f"{label_text(truth['people'])}, {truth['activity']}; seed {truth['seed']}\n(o start, \u25a1 end)", fontsize=9)


def save_preview(path, truth: dict, plot, *, force: bool = False) -> None:
    import matplotlib.gridspec as gridspec

    fig, _ = new_figure(figsize=(13, 5.5))
    fig.clf()
    gs = gridspec.GridSpec(2, 2, width_ratios=[1, 1.6], figure=fig)
    draw_room(fig.add_subplot(gs[:, 0]), truth)
    a1 = fig.add_subplot(gs[0, 1])
    a2 = fig.add_subplot(gs[1, 1], sharex=a1)
    g, _ = draw_stplot([a1, a2], plot)
    a1.set_title(f"space-time plots of the rendered video; colour gain {g:.3g} per code value "
                 f"(full scale \u00b1{0.5 / g:.2g} code values)", fontsize=9, loc="left")
    fig.tight_layout()
    save_figure(fig, path, force=force)
