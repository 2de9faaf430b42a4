"""``wallcli count INPUT``: how many people (0, 1, 2) move in the hidden part of the room."""
from __future__ import annotations

from pathlib import Path
from typing import Optional

from wallcli.cli.common import stream_option
from wallcli.cli._classify import (FOLLOW_OPT, FORCE_OPT, INPUT_ARG, JSON_OPT, MODEL_OPT, PLOT_OPT, ROI_OPT,
                                   STRICT_OPT, STRIDE_OPT, THREADS_OPT, NO_DEFLICKER_OPT, NO_EXPOSURE_OPT, NO_SHAKE_OPT, run)


def count(
    input: str = INPUT_ARG,
    stride: Optional[int] = STRIDE_OPT,
    json_out: bool = JSON_OPT,
    plot: Optional[Path] = PLOT_OPT,
    model: Optional[Path] = MODEL_OPT,
    threads: int = THREADS_OPT,
    stream: Optional[int] = stream_option(),
    follow: bool = FOLLOW_OPT,
    roi: Optional[str] = ROI_OPT,
    force: bool = FORCE_OPT,
    strict: bool = STRICT_OPT,
    no_deflicker: bool = NO_DEFLICKER_OPT,
    no_exposure: bool = NO_EXPOSURE_OPT,
    no_shake: bool = NO_SHAKE_OPT,
) -> None:
    """Count the people (0, 1 or 2) moving out of view, from the light on a blank wall.

    The horizontal space-time plot is cut into 256-frame windows (8.5 s at 30 fps, any
    input frame rate is resampled); the paper's CNN classifies each (Sharma et al., What You
    Can Learn by Staring at a Blank Wall, ICCV 2021, supplementary §2); the clip's answer is
    the mean of the window probabilities.

    \b
    Examples:
      wallcli count clip.mp4
      wallcli count plots.npz --json
      wallcli count clip.mp4 --plot timeline.png --stride 32
      ffmpeg -i rtsp://cam/stream -f nut - | wallcli count - --follow
    """
    run("count", input, stride=stride, json_out=json_out, plot=plot, model_path=model, threads=threads,
        follow=follow, roi=roi, force=force, strict=strict,
        no_deflicker=no_deflicker, no_exposure=no_exposure, no_shake=no_shake, stream=stream)
