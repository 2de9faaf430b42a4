"""One decoded frame with the analysed region drawn on it (``wallcli report``)."""

from __future__ import annotations

import numpy as np

from wallcli.plots.figure import new_figure, save_figure


def save_frame_png(path, rgb: np.ndarray, roi, *, title: str = "", force: bool = False) -> None:
    """``rgb``: (H, W, 3) float on the 0-255 scale; ``roi``: x, y, w, h in its pixels."""
    from matplotlib.patches import Rectangle

    h, w = rgb.shape[:2]
    from wallcli.plots.figure import picture_aspect, picture_height

    fig, ax = new_figure(figsize=(8, picture_height(8, w, h) + 0.8), constrained_layout=True)
    # display only: the analysis never sees these rounded, clipped values
    ax.imshow(np.clip(rgb / 255.0, 0.0, 1.0), extent=(0, w, h, 0), interpolation="nearest", aspect=picture_aspect(w, h))
    x, y, rw, rh = roi
    ax.add_patch(Rectangle((x, y), rw, rh, fill=False, edgecolor="cyan", lw=2, label=f"ROI {x},{y},{rw},{rh}"))
    ax.legend(loc="upper right", fontsize=8)
    ax.set_xlabel("x (px)")
    ax.set_ylabel("y (px)")
    if title:
        ax.set_title(title, fontsize=10, loc="left")
    save_figure(fig, path, force=force)
