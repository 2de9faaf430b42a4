"""``wallcli amplify``: video -> the amplified-signal video (as in the paper's Figure 1), in one streaming pass."""

from __future__ import annotations

from pathlib import Path
from typing import Optional

import typer

from wallcli.cli.common import stream_option, stall_option, ROI_HELP, THREADS_HELP, force_help, input_argument, number_option, parse_roi, threads_option

VIDEO_SUFFIXES = (".mp4", ".mov", ".m4v", ".mkv")
# Frames held back while the automatic gain calibrates are kept whole only with --side-by-side
# (the original panel); cap that buffer so 4K input cannot blow the memory budget.
PRESETS = ("ultrafast", "superfast", "veryfast", "faster", "fast", "medium", "slow", "slower", "veryslow")
SIDE_BUFFER_BYTES = 64 * 1024 * 1024
# The largest output frame: two 4K UHD panels side by side. Memory grows with the output's pixels
# (measured here: 420 MB at 2560x1920; --scale 100 of a 64x48 ROI, 6400x4800, reached 7.5 GB as
# the encoder's threads each held frames), and a block grid blown up further shows nothing more.
MAX_OUTPUT_PIXELS = 2 * 3840 * 2160
MAX_SIDE = 16384  # pixels on either side of a panel (H.264 levels end there)


def parse_scale(text: str, width: int, height: int, panels: int = 1) -> tuple[int, int]:
    """'0.5' (factor) or '640x360' (pixels) -> even (width, height) for H.264 4:2:0. A factor's
    size is rounded to even numbers (at least 2); a size given in pixels is written as given or
    refused, never silently changed. ``panels``: 2 with --side-by-side. The limits come first, so
    that a refusal never suggests a size that is refused in turn (99999x99999 suggested 100000x100000)."""
    from wallcli.errors import UsageError

    t = text.strip().lower()
    try:
        if "x" in t:
            w_s, h_s = t.split("x", 1)
            w, h = float(int(w_s)), float(int(h_s))
        else:
            f = float(t)
            w, h = width * f, height * f
    except ValueError:
        raise UsageError(f"--scale must be a factor like 0.5 or a size like 640x360 (got {text!r})") from None
    if not (w > 0 and h > 0) or w > MAX_SIDE or h > MAX_SIDE:
        raise UsageError(f"--scale gives an unusable output size {w:.0f}x{h:.0f} (each side from 2 to {MAX_SIDE} "
                         "pixels)")
    pw, ph = _even(w), _even(h)
    if panels * pw * ph > MAX_OUTPUT_PIXELS:
        raise UsageError(f"--scale {text} makes {panels * pw}x{ph} output frames ({panels * pw * ph / 1e6:.1f} "
                         f"megapixels); amplify writes at most {MAX_OUTPUT_PIXELS / 1e6:.1f} (two 3840x2160 panels): "
                         "use a smaller --scale")
    if "x" in t and (w % 2 or h % 2):
        raise UsageError(f"--scale {text}: H.264 (4:2:0) needs an even width and height, of 2 or more "
                         f"(e.g. {pw}x{ph})")
    return pw, ph


def _even(x: float) -> int:
    """The even size nearest ``x``, from 2 to MAX_SIDE (a suggestion is never one that is refused)."""
    return min(MAX_SIDE, max(2, 2 * round(x / 2)))


def amplify(
    input: str = input_argument(),
    output: Path = typer.Argument(..., help="Output video (.mp4, .mov, .m4v or .mkv; H.264).", show_default=False),
    gain: Optional[float] = number_option(None, "--gain", lo=0, hi=1e8, lo_open=True, help="Display levels per code value of signal "
                                         "(output = 128 + gain x signal, bent smoothly towards 1 and 255 beyond the range: "
                                         "128 + 127 tanh(gain x signal / 127)). Default: automatic, +-3 robust sigma of "
                                         "the first --gain-seconds (after the automatic --cells and --smooth) fill the range, then fixed."),
    gain_seconds: float = number_option(2.0, "--gain-seconds", lo=0.05, hi=600, help="Video at the start used to measure the automatic "
                                       "gain, --cells and --smooth (those frames are held back as small grids and written once they are known)."),
    cells: Optional[int] = number_option(None, "--cells", lo=1, hi=4096, integer=True, help="Blocks along the longer side of the ROI; each "
                              "block is averaged exactly (noise falls as 1/sqrt(pixels)). Fewer = less noise, coarser. "
                              "Default: automatic (64, 32, 16 or 8, with --smooth; see below)."),
    mean: str = typer.Option("ema", "--mean", help="Running temporal mean removed per block: 'ema' (exponential) "
                             "or 'window' (trailing moving average). Both start as an expanding average."),
    mean_seconds: float = number_option(10.0, "--mean-seconds", lo=0.01, hi=3600, help="Time constant of 'ema' / span of 'window'."),
    smooth: Optional[float] = number_option(None, "--smooth", lo=0, hi=3600, help="Temporal smoothing time constant in seconds "
                                 "(causal one-pole low-pass; 0 = off). Lowers noise, blurs fast motion. "
                                 "Default: automatic (0 to 0.5, with --cells; see below)."),
    scale: str = typer.Option("1", "--scale", help="Output panel size: a factor of the ROI size (0.5; rounded to even sizes, at least 2x2) or "
                       "WIDTHxHEIGHT in pixels (even numbers: H.264 4:2:0). The output frame is at most 2x3840x2160 pixels."),
    side_by_side: bool = typer.Option(False, "--side-by-side", help="Original on the left, amplified on the right."),
    colour: bool = typer.Option(False, "--colour", help="Amplify each colour channel (red, green, blue) instead of "
                                "showing the luminance change in grey (the default: a shade darkens every colour, "
                                "and the chroma's own noise paints coloured blobs)."),
    roi: Optional[str] = typer.Option(None, "--roi", help=ROI_HELP + " Output shows the ROI only."),
    crf: int = number_option(18, "--crf", lo=0, hi=51, integer=True, help="H.264 quality (lower = better, bigger)."),
    preset: str = typer.Option("superfast", "--preset", help="x264 speed preset, ultrafast ... veryslow. superfast: 2x faster than veryfast, same size here; ultrafast: 2x faster again, 2x bigger."),
    json_out: bool = typer.Option(False, "--json", help="Print a summary (gain, frames, fps, size) as JSON on stdout."),
    force: bool = typer.Option(False, "--force", help=force_help("OUTPUT")),
    threads: int = threads_option(THREADS_HELP),
    stream: Optional[int] = stream_option(),
    stall_timeout: Optional[float] = stall_option(follow=False),
) -> None:
    """Make the invisible visible: a video of the wall's tiny light changes, amplified.

    Each pixel's temporal mean (the static room) is removed, the wall is area-averaged into
    blocks (the noise falls, the broad shadows of people stay), and the rest is shown as
    128 + gain x signal in grey (the luminance change; --colour: each channel): mid-grey where
    nothing changes, darker where someone blocks light, lighter where they reflect it. Beyond
    the display range the scale bends smoothly (128 + 127 tanh(gain x signal / 127)), so a strong
    shade keeps its shape instead of being cut flat to white or black. One streaming pass; memory
    does not grow with the video's length.

    Nothing above the noise: the same frames are measured as `wallcli snr` measures them, and
    where its verdict finds no wall signal (an empty room, or a person too faint for this video),
    a warning says that the video shows amplified camera and codec noise. The headline figure,
    column SNR (column_snr_db, as count, activity and snr give it), is printed first.

    Defaults chosen from the clip: on the first --gain-seconds (2 s) of video, the signal and
    noise of the blocks are measured as `wallcli snr` does (noise from frame-to-frame
    differences, signal = the rest), for these --cells/--smooth pairs, sharpest first: 64/0,
    32/0, 32/0.1, 16/0.1, 16/0.2, 16/0.3, 8/0.3, 8/0.5. The first whose measured SNR reaches
    12 dB is used, else the one with the highest SNR; then the gain maps +-3 robust sigma of
    that signal onto the display range. A --cells, --smooth or --gain given is used as given
    (the others are still chosen). The choice is printed with --json (cells, smooth, and
    display_snr_db: the display's own SNR, neither the headline column SNR, count's signal_db nor snr's
    pixel SNR).
    The video is still decoded once: those first seconds are held back as small block grids only.

    \b
    Examples:
      wallcli amplify clip.mp4 amp.mp4
      wallcli amplify clip.mp4 amp.mp4 --side-by-side --scale 0.5 --smooth 0.1
      wallcli amplify clip.mp4 amp.mp4 --roi 100,50,640,360 --gain 200 --cells 32
    """
    from wallcli.cli.common import use_stream

    use_stream(stream, stall_timeout)
    from wallcli.errors import UsageError

    if mean not in ("ema", "window"):
        raise UsageError(f"--mean must be ema or window (got {mean!r})")
    if preset not in PRESETS:
        raise UsageError(f"--preset must be one of {', '.join(PRESETS)} (got {preset!r})")
    if output.suffix.lower() not in VIDEO_SUFFIXES:
        raise UsageError(f"OUTPUT must end in {', '.join(VIDEO_SUFFIXES)} (got {output})")
    roi_t = parse_roi(roi)

    from wallcli.io.writer import check_output, committed_together

    check_output(output, force=force, inputs=[input])
    with committed_together():  # the video and the JSON summary: both or neither
        _render(input, output, roi_t, gain, gain_seconds, cells, mean, mean_seconds, smooth, scale, side_by_side, crf,
                preset, json_out, force, threads, colour=colour)


def _warn_small(rw: int, rh: int) -> None:
    """The tiny-ROI warning snr, count and track give (their view check's 'too small to check'),
    said for amplify's output: a 2x2 ROI became a 2x2 video, without a word."""
    from wallcli.cli.output import warn
    from wallcli.view.limits import MIN_REGISTER_SIDE as side

    if rw < side or rh < side:
        warn(f"the ROI ({rw}x{rh} px) is too small to check for camera motion (it needs {side}x{side} pixels or "
             f"more), and the amplified video shows at most {rw}x{rh} independent blocks: use a larger ROI")


def _above_noise(acc, source: str, fps: float):
    """(snr's verdict, the headline figure) of the frames amplify read; the headline is said first
    on stderr, and a warning where the verdict finds no wall signal."""
    from wallcli.cli.output import log, warn
    from wallcli.snr.column import column_text
    from wallcli.snr.estimate import MIN_FRAMES, snr_report

    if acc.frames < MIN_FRAMES:
        return None, None
    report = snr_report(acc, source=source, fps=fps, roi_mode="given")
    verdict, db = report["verdict"], report.get("column_snr_db")
    log(f"{column_text(db)}.")
    if not verdict["signal"]:
        warn(f"nothing stands above the noise here ({verdict['text']}, as `wallcli snr` says): the amplified "
             "video shows the camera's and the codec's noise, not a person's shade")
    return verdict, db


def _render(input, output, roi_t, gain, gain_seconds, cells, mean, mean_seconds, smooth, scale, side_by_side, crf,
            preset, json_out, force, threads, colour: bool = False) -> None:
    import itertools
    from fractions import Fraction

    import numpy as np

    from wallcli.cli.output import emit_json, progress, wrote
    from wallcli.errors import UsageError, WallcliError
    from wallcli.io.video import open_video
    from wallcli.io.writer import VideoWriter, atomic_path
    from wallcli.signal.amplify import AutoAmplifier, grid_shape, original_panel, quantisation_sigma, render_panel
    from wallcli.signal.blocks import check_roi, rgb_grid

    with open_video(input, threads=threads) as reader:
        info = reader.info
        frames_in = reader.frames()
        first = next(frames_in, None)
        # the decoded frame decides the size, not the container's (wrong or unknown in some
        # streams), as in compute_stplot
        size = (first.planes.width, first.planes.height) if first is not None else (info.width, info.height)
        roi_t = check_roi(roi_t, *size)
        _, _, rw, rh = roi_t
        pw, ph = parse_scale(scale, rw, rh, 2 if side_by_side else 1)
        calib = max(2, round(gain_seconds * float(info.fps)))
        if side_by_side:
            calib = max(2, min(calib, SIDE_BUFFER_BYTES // (pw * ph * 3)))
        depth = 8
        amp = None
        # is anything above the noise? the same frames, measured as `wallcli snr` measures them
        from wallcli.snr.estimate import SnrAccumulator

        acc = SnrAccumulator(roi_t, fps=float(info.fps))
        out_w = 2 * pw if side_by_side else pw
        if out_w * ph > MAX_OUTPUT_PIXELS:
            raise UsageError(f"--scale {scale} makes {out_w}x{ph} output frames ({out_w * ph / 1e6:.1f} megapixels); "
                             f"amplify writes at most {MAX_OUTPUT_PIXELS / 1e6:.1f} (two 3840x2160 panels): "
                             "use a smaller --scale")
        frames = 0
        with atomic_path(output, force=force) as tmp:
            # timed: each output frame keeps its source frame's time (frames lost, variable rates)
            with VideoWriter(tmp, info.fps, out_w, ph, crf=crf, preset=preset, timed=True) as writer:

                def write(pairs) -> None:
                    for (t, left), display in pairs:
                        right = render_panel(display, pw, ph)
                        writer.write(right if left is None else np.concatenate([left, right], axis=1), t)

                with progress("amplify", info.frame_count) as advance:
                    for frame in itertools.chain([first] if first is not None else [], frames_in):
                        planes = frame.planes
                        if amp is None:
                            depth = planes.depth

                            def floor(c, depth=depth):
                                r, k = grid_shape(rw, rh, c)
                                return quantisation_sigma(rw * rh / (r * k), depth)

                            amp = AutoAmplifier(cells=cells, smooth_seconds=smooth, mean=mean, mean_seconds=mean_seconds,
                                                gain=gain, calib_frames=calib, sigma_floor=floor, colour=colour)
                        acc.update(planes)
                        # the grids of every block count still in question, from this one decode
                        grids = {c: rgb_grid(planes, roi_t, *grid_shape(rw, rh, c)) for c in amp.wanted}
                        left = original_panel(planes, roi_t, pw, ph) if side_by_side else None
                        write(amp.push(frame.time, grids, (frame.time, left)))
                        frames += 1
                        advance()
                if frames < 2:  # before the flush, which cannot measure one frame (an internal error)
                    raise WallcliError(f"{input}: only {frames} frame(s); amplify needs at least 2")
                write(amp.flush() if amp is not None else [])
    _warn_small(rw, rh)  # once the video is written: a run that fails says one line, its error
    verdict, column_db = _above_noise(acc, input, float(info.fps))
    rows, cols = grid_shape(rw, rh, amp.cells)
    rate = reader.fps  # the frames' own rate where it contradicts the container's
    rate_f = info.fps if rate == float(info.fps) else Fraction(rate).limit_denominator(1001)
    measured = amp.measured.get((amp.cells, amp.smooth_seconds))
    summary = {
        "input": input, "output": str(output), "frames": frames, "fps": rate,
        "fps_fraction": f"{rate_f.numerator}/{rate_f.denominator}", "width": out_w, "height": ph,
        "roi": list(roi_t), "grid": [rows, cols], "mean": mean, "mean_seconds": mean_seconds,
        "cells": amp.cells, "cells_mode": "auto" if amp.auto_cells else "given",
        "smooth": amp.smooth_seconds, "smooth_mode": "auto" if amp.auto_smooth else "given",
        # the SNR (dB) measured on the first --gain-seconds for each pair tried, and the chosen one's:
        # the display's own figure, named so (snr_db, its older name, stays for scripts); neither
        # count's signal_db nor snr's pixel SNR
        "snr_db": None if measured is None or not np.isfinite(measured) else round(measured, 2),
        "display_snr_db": None if measured is None or not np.isfinite(measured) else round(measured, 2),
        "snr_measure": (f"display SNR: the amplified blocks ({amp.cells} across, smoothed over {amp.smooth_seconds:g} s) "
                        "over their frame-to-frame noise on the first --gain-seconds; not count's signal_db, "
                        "nor snr's pixel SNR"),
        "tried": [{"cells": c, "smooth": t, "snr_db": round(v, 2) if np.isfinite(v) else None}
                  for (c, t), v in amp.measured.items()],
        "gain": amp.gain, "gain_mode": "auto" if amp.auto_gain else "fixed", "sigma": amp.sigma,
        "display": "colour" if colour else "luminance", "column_snr_db": column_db, "verdict": verdict,
    }
    # the grid in the order of the JSON's "grid": [rows, cols]
    wrote((output, f"{frames} frames of {out_w}x{ph} pixels; gain {amp.gain:.4g} "
                   f"({'automatic' if amp.auto_gain else 'given'}); the wall averaged in {rows} rows x {cols} columns of blocks "
                   f"({'chosen' if amp.auto_cells else 'given'}), smoothed over {amp.smooth_seconds:g} s "
                   f"({'chosen' if amp.auto_smooth else 'given'})"))
    if json_out:
        emit_json(summary)
