"""Draw the space-time plots of every bundled example into one figure (examples/gallery.png).

    .venv/bin/python examples/gallery.py
"""
from __future__ import annotations

import json
from pathlib import Path

from wallcli.io.video import open_video
from wallcli.plots.figure import new_figure, save_figure
from wallcli.plots.stplot import draw_stplot
from wallcli.signal.stplot import compute_stplot

HERE = Path(__file__).resolve().parent
ORDER = ["empty", "standing", "walking", "crouching", "waving", "jumping", "two-walking", "two-mixed"]


def main() -> None:
    fig, axes = new_figure(4, 4, figsize=(18, 12), constrained_layout=True)
    for k, name in enumerate(ORDER):
        truth = json.loads((HERE / f"{name}.json").read_text())
        with open_video(HERE / f"{name}.mp4") as reader:
            plot = compute_stplot(reader)
        col, row = (k % 2) * 2, k // 2
        pair = [axes[row, col], axes[row, col + 1]]
        gain, _ = draw_stplot(pair, plot)
        acts = ", ".join(truth["activities"]) or "nobody"
        pair[0].set_title(f"{name}.mp4: {truth['people']} people ({acts}); ±{0.5 / gain:.2g} codes", fontsize=9, loc="left")
        pair[1].set_ylabel("vertical")
        pair[0].set_ylabel("horizontal")
        for ax in pair:
            ax.set_xlabel("time (s)")
    save_figure(fig, HERE / "gallery.png", force=True, dpi=80)


if __name__ == "__main__":
    main()
