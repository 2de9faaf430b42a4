"""Figures of ``wallcli snr``: where the signal is (heatmap), how SNR grows with block size, and
predicted SNR against a swept scene parameter."""

from __future__ import annotations

import numpy as np

from wallcli.plots.figure import new_figure, save_figure

COLOURS = ("tab:red", "tab:green", "tab:blue")


def save_heatmap_png(path, grid, *, of: str = "signal", chosen=None, avoid=None, title: str = "",
                     force: bool = False) -> None:
    """Per-cell signal power (mean over R, G, B) or SNR (dB) over the mean luma of the grid's ROI;
    ``avoid`` ((rows, cols) bool): cells --roi auto left out (the view failed there), hatched."""
    from matplotlib.patches import Rectangle

    sig, noi, lum = grid.maps()
    s, n = sig.mean(axis=2), noi.mean(axis=2)
    x, y, w, h = grid.grid_roi
    extent = (x, x + w, y + h, y)
    from wallcli.plots.figure import picture_aspect, picture_height

    fig, ax = new_figure(figsize=(8, picture_height(8, w, h) + 1.0), constrained_layout=True)
    ax.imshow(lum, cmap="gray", extent=extent, interpolation="bilinear", aspect=picture_aspect(w, h))
    if of == "snr":
        with np.errstate(divide="ignore", invalid="ignore"):
            data = np.where((s > 0) & (n > 0), 10 * np.log10(s / n), np.nan)
        label = "SNR (dB), per cell"
    else:
        data, label = np.clip(s, 0, None), "signal power (8-bit code values$^2$), per cell"
    image = ax.imshow(np.ma.masked_invalid(data), cmap="inferno", alpha=0.65, extent=extent, interpolation="nearest")
    fig.colorbar(image, ax=ax, label=label, shrink=0.8)
    if avoid is not None and avoid.any():
        for i, j in zip(*np.nonzero(avoid)):
            ax.add_patch(Rectangle((x + j * grid.cw, y + i * grid.ch), grid.cw, grid.ch, fill=False, hatch="xx",
                                   edgecolor="white", lw=0, alpha=0.6,
                                   label="view failed here" if (i, j) == tuple(np.argwhere(avoid)[0]) else None))
    if chosen is not None:
        cx, cy, cw, ch = chosen
        ax.add_patch(Rectangle((cx, cy), cw, ch, fill=False, edgecolor="cyan", lw=2, label="--roi auto"))
    if chosen is not None or (avoid is not None and avoid.any()):
        ax.legend(loc="upper right", fontsize=8)
    ax.set_title(f"{title}: {grid.rows}x{grid.cols} cells of {grid.cw}x{grid.ch} px, {grid.frames} frames",
                 fontsize=10, loc="left")
    ax.set_xlabel("x (px)")
    ax.set_ylabel("y (px)")
    save_figure(fig, path, force=force)


def save_scales_png(path, result: dict, *, force: bool = False) -> None:
    """SNR and noise power against block size (log-log), each beside the white-noise law."""
    fig, (ax_s, ax_n) = new_figure(1, 2, figsize=(11, 4.5), constrained_layout=True)
    blocks = np.array([s["block"] for s in result["scales"]], np.float64)
    sig = np.array([s["signal_power"] for s in result["scales"]], np.float64)
    noi = np.array([s["noise_power"] for s in result["scales"]], np.float64)
    for c, (name, colour) in enumerate(zip(result["channels"], COLOURS)):
        # in dB, as every table and JSON field gives SNR (the JSON's scales[].snr_db)
        snr = np.array([s["snr_db"][c] for s in result["scales"]], np.float64)
        snr = np.where(np.abs(snr) < 99, snr, np.nan)  # +-99: nothing measurable
        ax_s.plot(blocks, snr, "o-", color=colour, label=f"{name} measured")
        # White noise law: noise / pixels averaged, signal unchanged -> SNR x N^2, +20 log10 N dB.
        if np.isfinite(snr[0]):
            ax_s.plot(blocks, snr[0] + 20 * np.log10(blocks), ":", color=colour, alpha=0.7,
                      label=f"{name} white-noise law")
        ax_n.plot(blocks, noi[:, c], "o-", color=colour, label=f"{name} measured")
        ax_n.plot(blocks, noi[0, c] / blocks**2, ":", color=colour, alpha=0.7, label=f"{name} noise(1) / N$^2$")
    ax_s.axhline(0.0, color="0.5", ls="--", lw=1)
    for ax, ylabel in ((ax_s, "block SNR (dB)"), (ax_n, "noise power (code values$^2$)")):
        ax.set_xscale("log", base=2)
        if ax is ax_n:
            ax.set_yscale("log")
        ax.set_xlabel("block size N (N x N pixels averaged)")
        ax.set_ylabel(ylabel)
        ax.grid(True, which="both", alpha=0.3)
        ax.legend(fontsize=7)
    ax_s.set_title(f"{result['input']}: ROI {result['roi']}, {result['frames']} frames", fontsize=10, loc="left")
    save_figure(fig, path, force=force)


# units of the swept parameters, for the x axis (the rest are ratios or counts)
UNITS = {"distance": "m", "radius": "m", "area": "m$^2$", "person_radiance": "code values",
         "background_radiance": "code values", "contrast": "code values", "mean_code": "code value",
         "gain": "electrons per code value", "read_noise": "electrons RMS", "bits": "bits"}


def sweep_quantity(rows: list[dict]) -> str:
    """What a sweep's figure plots: SNR where a camera model gave noise, else signal power."""
    return "SNR" if "snr" in rows[0] else "signal power"


def save_sweep_png(path, key: str, rows: list[dict], *, force: bool = False) -> str:
    """Predicted SNR (or signal power without a camera model) against the swept parameter; returns
    what it plotted ('SNR' or 'signal power'), which the caller names, so the two never differ."""
    fig, ax = new_figure(figsize=(7, 4.5), constrained_layout=True)
    x = np.array([r[key] for r in rows], np.float64)
    what = sweep_quantity(rows)
    if what == "SNR":
        y = 10 * np.log10(np.maximum(np.array([r["snr"] for r in rows], np.float64), 1e-30))
        label = "predicted SNR (dB)"
    else:
        y, label = np.array([r["signal_power"] for r in rows]), "predicted signal power (code values$^2$)"
    ax.plot(x, y, "o-")
    if what == "SNR":
        if y.min() < 0 < y.max():
            ax.axhline(0.0, color="0.5", ls="--", lw=1, label="0 dB (signal = noise)")
            ax.legend(fontsize=8)
    elif np.all(y > 0):
        ax.set_yscale("log")
    name = key.replace("_", " ")
    ax.set_xlabel(f"{name} ({UNITS[key]})" if key in UNITS else name)
    ax.set_ylabel(label)
    ax.grid(True, which="both", alpha=0.3)
    note = "" if what == "SNR" else " (no camera model: --mean-code and --gain give SNR)"
    ax.set_title(f"wallcli snr --predict: {what} against {name}{note}", fontsize=10, loc="left")
    save_figure(fig, path, force=force)
    return what
