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


# what a viewer asks first about an H.264 plot: the vertical seams
SEAMS = ("Vertical seams at regular times (every 1-2 s in most H.264 files) are the video codec's key "
         "frames, where the encoder starts a fresh picture and the noise it held changes at once: not light.")
# the wall position's unit in every figure (track's too): a fraction of the view's width or height
POSITION_LABELS = {"horizontal": "place along the wall\n(0 = view's left, 1 = right)",
                   "vertical": "height on the wall\n(0 = view's top, 1 = bottom)"}


def draw_stplot(axes, plot, *, style: str = "rgb", gain: float | None = None):
    """Draw both plots into two axes; returns (gain, image): the gain (display units per code
    value) and the image a colour scale is drawn for. Positions are fractions of the region's width
    (horizontal plot) or height (vertical plot), as track's x is."""
    g = gain if gain is not None else auto_gain(plot)
    t0, t1 = float(plot.time[0]), float(plot.time[-1])
    image = None
    for ax, name in zip(axes, ("horizontal", "vertical")):
        data = getattr(plot, name)  # (bins, T, 3)
        extent = (t0, t1, 1.0, 0.0)  # position grows downwards, like the image
        if style == "rgb":
            ax.imshow(np.clip(0.5 + g * data, 0.0, 1.0), aspect="auto", extent=extent, interpolation="nearest")
        else:
            lum = data @ LUMA
            lim = 0.5 / g
            image = ax.imshow(lum, aspect="auto", extent=extent, cmap="RdBu_r", vmin=-lim, vmax=lim, interpolation="nearest")
        ax.set_ylabel(f"{name} plot:\n{POSITION_LABELS[name]}", fontsize=9)
    axes[-1].set_xlabel("time (s)")
    return g, image


def stplot_title(src: str, g: float, *, automatic: bool = True) -> str:
    """The PNG's title, short enough not to widen the figure: the source and what is drawn; the
    gain and full scale are on the colour scale."""
    import textwrap

    # wrapped, long paths broken too: a title wider than the plots widened the whole figure
    return "\n".join(textwrap.wrap(f"{src}: space-time plots, each pixel's mean removed", 100,
                                    break_long_words=True, break_on_hyphens=False))


def scale_label(g: float, *, automatic: bool = True, style: str = "rgb") -> str:
    """The colour scale's label: its unit, what grey means, and how the gain was set."""
    how = "automatic: \u00b13 robust sigma fill it" if automatic else "set with --gain"
    what = "grey = no change; colours: R, G, B each" if style == "rgb" else "luminance"
    return f"change (8-bit code values)\n{what}\nfull scale \u00b1{0.5 / g:.2g} ({how})"


def add_scale(fig, axes, g: float, image=None, *, automatic: bool = True, style: str = "rgb") -> None:
    """A colour scale in code values beside the plots (for the RGB style, the grey ramp each
    channel follows)."""
    if image is None:
        import matplotlib.cm as cm
        from matplotlib.colors import Normalize

        image = cm.ScalarMappable(norm=Normalize(-0.5 / g, 0.5 / g), cmap="gray")
    bar = fig.colorbar(image, ax=list(axes), shrink=0.85, pad=0.015)
    bar.set_label(scale_label(g, automatic=automatic, style=style), fontsize=8)
    bar.ax.tick_params(labelsize=8)


def save_stplot_png(path, plot, *, style: str = "rgb", gain: float | None = None, force: bool = False) -> None:
    fig, axes = new_figure(2, 1, figsize=(10, 5.5), sharex=True, constrained_layout=True)
    g, image = draw_stplot(axes, plot, style=style, gain=gain)
    src = plot.meta.get("source", "")
    axes[0].set_title(stplot_title(src, g, automatic=gain is None), fontsize=10, loc="left")
    add_scale(fig, axes, g, image, automatic=gain is None, style=style)
    import textwrap

    axes[-1].set_xlabel("time (s)\n" + "\n".join(textwrap.wrap(SEAMS, 120)), fontsize=9)
    save_figure(fig, path, force=force)
