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


def who(truth: dict) -> str:
    """Who is in the clip, by count's rule (it counts the people who move): '1 person (walking)',
    '0 moving (one standing still)', '0 people (empty room)'."""
    from wallcli.wording import label_text

    moving = [a for a in truth["activities"] if a != "none"]
    still = len(truth["activities"]) - len(moving)
    if not truth["activities"]:
        return "0 people (empty room)"
    if not moving:
        return f"0 moving ({'one' if still == 1 else still} standing still)"
    return f"{label_text(len(moving))} ({', '.join(moving)})" + (f", {still} standing still" if still else "")


def column_db(path: Path) -> str:
    """The clip's headline figure, as count and snr print it."""
    from wallcli.snr.column import ColumnSnr
    from wallcli.wording import format_db

    with open_video(path) as reader:
        tap = ColumnSnr(fps=float(reader.info.fps))
        for frame in reader.frames():
            tap(frame)
    return format_db(tap.db())


def main() -> None:
    fig, axes = new_figure(4, 4, figsize=(18, 12), constrained_layout=True)
    for k, name in enumerate(ORDER):
        truth = json.loads((HERE / f"{name}.json").read_text())
        with open_video(HERE / f"{name}.mp4") as reader:
            plot = compute_stplot(reader)
        col, row = (k % 2) * 2, k // 2
        pair = [axes[row, col], axes[row, col + 1]]
        gain, _ = draw_stplot(pair, plot)
        pair[0].set_title(f"{name}.mp4: {who(truth)}; column SNR {column_db(HERE / f'{name}.mp4')} dB; "
                          f"±{0.5 / gain:.2g} codes", fontsize=9, loc="left")
        pair[1].set_ylabel("vertical\n(0 = top, 1 = bottom)", fontsize=8)
        pair[0].set_ylabel("horizontal\n(0 = left, 1 = right)", fontsize=8)
        for ax in pair:
            ax.set_xlabel("time (s)")
    save_figure(fig, HERE / "gallery.png", force=True, dpi=80)


if __name__ == "__main__":
    main()
