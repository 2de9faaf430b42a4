"""The space-time plot figure: horizontal and vertical plots, amplified, time in seconds."""

from __future__ import annotations

import numpy as np

from wallcli.plots.figure import new_figure, save_figure
from wallcli.signal.amplify import robust_sigma

LUMA = np.array([0.2126, 0.7152, 0.0722], np.float32)


def auto_gain(plot) -> float:
    """Gain that maps +-3 robust sigma of the signal onto the full display range."""
    s = robust_sigma(np.concatenate([plot.horizontal.ravel(), plot.vertical.ravel()]))
    g = 1.0 / (6.0 * s) if s > 0 else 1.0
    return g if np.isfinite(g) else 1.0  # a spread of 1e-320 (a constant wall) is no spread


def draw_stplot(axes, plot, *, style: str = "rgb", gain: float | None = None):
    """Draw both plots into two axes; returns the gain used (display units per code value)."""
    g = gain if gain is not None else auto_gain(plot)
    t0, t1 = float(plot.time[0]), float(plot.time[-1])
    roi = plot.meta.get("roi") or [0, 0, plot.bins, plot.bins]
    spans = {"horizontal": (roi[0], roi[0] + roi[2], "x (px)"), "vertical": (roi[1], roi[1] + roi[3], "y (px)")}
    image = None
    for ax, name in zip(axes, ("horizontal", "vertical")):
        data = getattr(plot, name)  # (bins, T, 3)
        lo, hi, label = spans[name]
        extent = (t0, t1, hi, lo)  # position grows downwards, like the image
        if style == "rgb":
            ax.imshow(np.clip(0.5 + g * data, 0.0, 1.0), aspect="auto", extent=extent, interpolation="nearest")
        else:
            lum = data @ LUMA
            lim = 0.5 / g
            image = ax.imshow(lum, aspect="auto", extent=extent, cmap="RdBu_r", vmin=-lim, vmax=lim, interpolation="nearest")
        ax.set_ylabel(f"{name}\n{label}")
    axes[-1].set_xlabel("time (s)")
    return g, image


def stplot_title(src: str, g: float, *, automatic: bool = True) -> str:
    """The PNG's title: the gain named in words (display range per code value of signal; the
    range is 0-1, so full scale is +-0.5/gain code values) and how it was set."""
    how = "automatic: \u00b13 robust sigma of the signal fill the range" if automatic else "given with --gain"
    return (f"{src}: space-time plots, mean removed; colour gain {g:.3g} display range per code value "
            f"({how}; full scale \u00b1{0.5 / g:.2g} code values)")


def save_stplot_png(path, plot, *, style: str = "rgb", gain: float | None = None, force: bool = False) -> None:
    fig, axes = new_figure(2, 1, figsize=(10, 5.5), sharex=True, constrained_layout=True)
    g, image = draw_stplot(axes, plot, style=style, gain=gain)
    src = plot.meta.get("source", "")
    axes[0].set_title(stplot_title(src, g, automatic=gain is None), fontsize=10, loc="left")
    if image is not None:
        fig.colorbar(image, ax=list(axes), label="luminance change (code values)", shrink=0.8)
    save_figure(fig, path, force=force)
