"""``wallcli count INPUT``: how many people (0, 1, 2) move in the hidden part of the room."""
from __future__ import annotations

from pathlib import Path
from typing import Optional

from wallcli.cli.common import stream_option, stall_option
from wallcli.cli._classify import (ACTIVITY_MODEL_OPT, SINGLE_STAGE_OPT, FOLLOW_OPT, IDLE_OPT, FORCE_OPT, INPUT_ARG, JSON_OPT,
                                   MODEL_OPT, PLOT_OPT, ROI_OPT,
                                   STRICT_OPT, STRIDE_OPT, THREADS_OPT, NO_DEFLICKER_OPT, NO_EXPOSURE_OPT, NO_SHAKE_OPT,
                                   VERBOSE_OPT, run, trust_help)


def count(
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
    activity_model: Optional[Path] = ACTIVITY_MODEL_OPT,
    single_stage: bool = SINGLE_STAGE_OPT,
    verbose: bool = VERBOSE_OPT,
) -> None:
    """Count the people (0, 1 or 2) moving out of view, from the light on a blank wall.

    count counts the people who move: a person standing still counts 0 (a still person's
    sway can still show on a strong signal, and is then counted; see the README).

    The space-time plots are cut into 256-frame windows (8.5 s at 30 fps, any input frame
    rate is resampled), one starting every --stride frames (64: 2.13 s), and a last one that
    ends where the clip ends, so that its end is read too: a 12 s clip's windows start at
    0, 2.13 and 3.47 s. Two stages answer: is anybody moving (the count net, which reads the
    horizontal plot as the paper's does, and the activity net, which reads both plots, as two
    detectors), then one or two (the count net). The clip's answer combines each net's mean
    window probabilities; the JSON's "stages" says what each stage found. --single-stage
    counts with the count net alone (Sharma et al., ICCV 2021, supplementary §2).

    The table's title states the clip's answer, decided or undetermined, and the line under it
    why; -v (--verbose) adds, on stderr, how often the model was right in validation.
    TRUST_NOW

    \b
    Examples:
      wallcli count clip.mp4
      wallcli count clip.mp4 -v
      wallcli count plots.npz --json
      wallcli count clip.mp4 --plot timeline.png --stride 32
      ffmpeg -i rtsp://cam/stream -c copy -f nut - | wallcli count - --follow
    """
    run("count", input, stride=stride, json_out=json_out, plot=plot, model_path=model, threads=threads,
        follow=follow, roi=roi, force=force, strict=strict,
        no_deflicker=no_deflicker, no_exposure=no_exposure, no_shake=no_shake, stream=stream, stall_timeout=stall_timeout,
        idle_timeout=idle_timeout, activity_model=activity_model, single_stage=single_stage, verbose=verbose)


# said where the user reads it, for as long as it is true (the shipped card decides)
count.__doc__ = count.__doc__.replace("TRUST_NOW", trust_help("count"))
