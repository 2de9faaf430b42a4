"""``wallcli activity INPUT``: what one person in the hidden part of the room is doing."""
from __future__ import annotations

from pathlib import Path
from typing import Optional

from wallcli.cli.common import stream_option, stall_option
from wallcli.cli._classify import (FOLLOW_OPT, IDLE_OPT, FORCE_OPT, INPUT_ARG, JSON_OPT, MODEL_OPT, PLOT_OPT, ROI_OPT,
                                   STRICT_OPT, STRIDE_OPT, THREADS_OPT, NO_DEFLICKER_OPT, NO_EXPOSURE_OPT, NO_SHAKE_OPT,
                                   VERBOSE_OPT, run, trust_help)


def activity(
    input: str = INPUT_ARG,
    stride: Optional[int] = STRIDE_OPT,
    json_out: bool = JSON_OPT,
    plot: Optional[Path] = PLOT_OPT,
    model: Optional[Path] = MODEL_OPT,
    threads: int = THREADS_OPT,
    stream: Optional[int] = stream_option(),
    stall_timeout: Optional[float] = stall_option(),
    follow: bool = FOLLOW_OPT,
    idle_timeout: float = IDLE_OPT,
    roi: Optional[str] = ROI_OPT,
    force: bool = FORCE_OPT,
    strict: bool = STRICT_OPT,
    no_deflicker: bool = NO_DEFLICKER_OPT,
    no_exposure: bool = NO_EXPOSURE_OPT,
    no_shake: bool = NO_SHAKE_OPT,
    verbose: bool = VERBOSE_OPT,
) -> None:
    """Recognise what a person out of view is doing: none, walking, crouching, waving or jumping.

    Both space-time plots (horizontal and vertical) are cut into 256-frame windows (8.5 s at 30 fps, any
    input frame rate is resampled), one starting every --stride frames (64: 2.13 s), and a last
    one that ends where the clip ends, so that its end is read too: a 12 s clip's windows start
    at 0, 2.13 and 3.47 s. The paper's two-branch CNN classifies each (Sharma et al., What
    You Can Learn by Staring at a Blank Wall, ICCV 2021, supplementary §2); the clip's answer is
    the mean of the window probabilities.

    The table's title states the clip's answer, decided or undetermined, and the line under it
    why; -v (--verbose) adds, on stderr, how often the model was right in validation.
    TRUST_NOW

    \b
    Examples:
      wallcli activity clip.mp4
      wallcli activity clip.mp4 -v
      wallcli activity plots.npz --json
      wallcli activity clip.mp4 --plot timeline.png --stride 32
      ffmpeg -i rtsp://cam/stream -c copy -f nut - | wallcli activity - --follow
    """
    run("activity", input, stride=stride, json_out=json_out, plot=plot, model_path=model, threads=threads,
        follow=follow, roi=roi, force=force, strict=strict,
        no_deflicker=no_deflicker, no_exposure=no_exposure, no_shake=no_shake, stream=stream, verbose=verbose,
        stall_timeout=stall_timeout, idle_timeout=idle_timeout)


# said where the user reads it, for as long as it is true (the shipped card decides)
activity.__doc__ = activity.__doc__.replace("TRUST_NOW", trust_help("activity"))
