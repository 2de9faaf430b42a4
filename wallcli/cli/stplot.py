"""``wallcli stplot``: video -> horizontal and vertical space-time plots (.npz, .png)."""

from __future__ import annotations

from pathlib import Path
from typing import Optional

import typer

from wallcli.cli.common import stream_option, stall_option, PNG_NAME, ROI_HELP, check_png_names, THREADS_HELP, force_help, input_argument, number_option, parse_roi, threads_option


def stplot(
    input: str = input_argument(),
    output: Optional[Path] = typer.Option(None, "--output", "-o", help="Write the plots to this .npz (float32 arrays + JSON metadata)."),
    png: Optional[Path] = typer.Option(None, "--png", help="Draw both plots, amplified, to this PNG, with a colour scale in "
                                       "code values and positions as fractions of the view (0 = left or top). Vertical seams every "
                                       "1-2 s in an H.264 file are its key frames (the codec's held noise changes at once), not light. "
                                       + PNG_NAME),
    roi: Optional[str] = typer.Option(None, "--roi", help=ROI_HELP),
    bins: int = number_option(64, "--bins", lo=2, hi=4096, integer=True, help="Positions per plot (the networks use 64)."),
    mean: str = typer.Option("clip", "--mean", help="Temporal mean removal: 'clip' (whole recording; files), "
                             "'window' (trailing moving average) or 'ema' (exponential running mean); the last two are causal, for streams."),
    mean_seconds: float = number_option(10.0, "--mean-seconds", lo=0.01, hi=3600, help="Time span of the 'window' / time constant of the 'ema' mean."),
    style: str = typer.Option("rgb", "--style", help="PNG style: 'rgb' (colour around neutral grey) or 'diverging' (luminance, blue-white-red)."),
    gain: Optional[float] = number_option(None, "--gain", lo=0, hi=1e6, lo_open=True, help="PNG amplification: display "
                                          "range per code value, full scale = +-0.5/gain code values (default: automatic, "
                                          "+-3 robust sigma of the signal fill the range)."),
    json_out: bool = typer.Option(False, "--json", help="Print a metadata summary as JSON on stdout."),
    force: bool = typer.Option(False, "--force", help=force_help("the -o and --png files")),
    threads: int = threads_option(THREADS_HELP),
    stream: Optional[int] = stream_option(),
    stall_timeout: Optional[float] = stall_option(follow=False),
) -> None:
    """Compute space-time plots: the wall, mean-removed and averaged over rows (horizontal plot,
    64 positions x time x RGB) and over columns (vertical plot).

    A person walking in the hidden room draws slanted streaks in the horizontal plot; crouching
    and jumping show in the vertical plot. Sums are exact, so signals far below one code value
    survive. The .npz feeds `wallcli count` and `wallcli activity` directly.

    \b
    Examples:
      wallcli stplot clip.mp4 -o plots.npz --png plots.png
      wallcli stplot clip.mp4 --roi 100,50,640,360 --png w.png --style diverging
      ffmpeg -i rtsp://cam/s -c copy -f nut - |
        wallcli stplot - --mean ema -o live.npz
    """
    from wallcli.cli.common import use_stream

    use_stream(stream, stall_timeout)
    from wallcli.errors import UsageError

    if output is None and png is None and not json_out:
        raise UsageError("nothing to do: give -o plots.npz, --png plots.png and/or --json")
    if mean not in ("clip", "window", "ema"):
        raise UsageError(f"--mean must be clip, window or ema (got {mean!r})")
    if style not in ("rgb", "diverging"):
        raise UsageError(f"--style must be rgb or diverging (got {style!r})")
    if output is not None and output.suffix.lower() != ".npz":
        raise UsageError(f"-o must end in .npz (got {output})")
    check_png_names(("--png", png))
    roi_t = parse_roi(roi)

    from wallcli.api import compute_plot, narrow_roi
    from wallcli.cli.output import progress
    from wallcli.io.writer import check_outputs, committed_together

    check_outputs([output, png], force=force, inputs=[input])
    # the Python API's own path (wallcli.api.compute_plot): one decode, the view check beside it
    plot = compute_plot(input, roi=roi_t, bins=bins, mean=mean, mean_seconds=mean_seconds, threads=threads,
                        progress=progress)
    narrow = narrow_roi(plot.meta["roi"], plot.bins)
    if narrow:
        from wallcli.cli.output import warn

        warn(narrow)  # compute_plot put it in the .npz's warnings
    from wallcli.cli.output import log
    from wallcli.snr.column import column_text, plot_column_snr_db

    column_db = plot_column_snr_db(plot)  # the headline figure, from the plot's bins
    with committed_together():  # the .npz, the PNG and the JSON: all or none
        _write(plot, input, output, png, style, gain, json_out, force, column_db)
    log(f"{column_text(column_db)}.")  # first, as every command says it
    from wallcli.cli.output import wrote
    from wallcli.wording import frames_text

    shape = f"{plot.bins} positions x {frames_text(plot.decoded, plot.meta.get('corrections'))}"
    wrote((output, f"horizontal and vertical space-time plots, {shape}"), (png, "both plots, amplified"))


def check_summary(meta: dict) -> dict | None:
    from wallcli.view.check import ViewCheck

    return ViewCheck.restore(meta["view"]).summary() if isinstance(meta.get("view"), dict) else None


def _write(plot, input, output, png, style, gain, json_out, force, column_db=None) -> None:
    from wallcli.cli.output import emit_json
    from wallcli.io.arrays import save_npz
    from wallcli.signal.stplot import channel_std, to_arrays

    if output is not None:
        save_npz(output, *to_arrays(plot), force=force)
    if png is not None:
        from wallcli.plots.stplot import save_stplot_png

        save_stplot_png(png, plot, style=style, gain=gain, force=force)
    if json_out:
        m = plot.meta
        emit_json({
            "input": input, "column_snr_db": column_db,
            "output": str(output) if output else None, "png": str(png) if png else None,
            "frames": plot.decoded, "corrections": m.get("corrections", []), "duration": float(plot.time[-1] - plot.time[0]), "fps": m["fps"],
            "fps_source": m.get("fps_source", "container"), "roi": m["roi"], "bins": m["bins"], "mean": m["mean"], "frame_size": m["frame_size"],
            "signal_rms": [float(x) for x in channel_std(plot.horizontal)],
            "warnings": m.get("warnings", []),
            "view": check_summary(m),
        })
