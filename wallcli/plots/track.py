"""The tracks drawn over the horizontal space-time plot: where each moving person's shade was."""
from __future__ import annotations

import numpy as np

from wallcli.plots.figure import new_figure, save_figure
from wallcli.plots.stplot import LUMA
from wallcli.signal.amplify import robust_sigma

COLOURS = ["#d62728", "#1f77b4", "#2ca02c", "#ff7f0e", "#9467bd", "#8c564b"]


def save_track_png(path, plot, result: dict, *, force: bool = False) -> None:
    fig, ax = new_figure(1, 1, figsize=(10, 3.8), constrained_layout=True)
    lum = plot.horizontal @ LUMA  # (bins, T)
    s = robust_sigma(lum.ravel())
    lim = 3.0 * s if s > 0 else 1.0
    t = np.asarray(plot.time, float)
    t0, t1 = (float(t[0]), float(t[-1])) if len(t) else (0.0, 1.0)
    ax.imshow(lum, aspect="auto", extent=(t0, t1, 1.0, 0.0), cmap="gray", vmin=-lim, vmax=lim, interpolation="nearest")
    import matplotlib.patheffects as pe

    for i, tr in enumerate(result["tracks"]):
        c = COLOURS[i % len(COLOURS)]
        ts = np.array([p["t"] for p in tr["samples"]])
        xs = np.array([p["x"] for p in tr["samples"]])
        sg = np.array([p["sigma"] for p in tr["samples"]])
        # the light band: where the person is (sigma, 68 %); the dark one: where the shade is
        ax.fill_between(ts, xs - sg, xs + sg, color=c, alpha=0.10, linewidth=0)
        if "sigma_shade" in tr["samples"][0]:
            sh = np.array([p["sigma_shade"] for p in tr["samples"]])
            ax.fill_between(ts, xs - sh, xs + sh, color=c, alpha=0.30, linewidth=0)
        # outlined and drawn past the axes, so a track on the view's edge (x 0 or 1) is not hidden by the frame
        ax.plot(ts, xs, color=c, linewidth=2.2, label=f"track {tr['id']}", clip_on=False, zorder=5,
                path_effects=[pe.Stroke(linewidth=4.0, foreground="white"), pe.Normal()])
    ax.set_ylim(1.04, -0.04)
    ax.set_xlim(t0, t1)
    ax.set_xlabel("time (s)")
    ax.set_ylabel("place along the wall\n(0 = view's left, 1 = right)")
    n = len(result["tracks"])
    title = f"{result['input']}: {n} track{'s' if n != 1 else ''} over the horizontal plot (dark = shade)"
    ax.set_title(title if n else f"{result['input']}: no track ({result.get('reason')})", fontsize=10, loc="left")
    if n:
        ax.legend(loc="upper right", fontsize=8, title="dark band: shade; light: person (68 %)", title_fontsize=7)
    save_figure(fig, path, force=force)
