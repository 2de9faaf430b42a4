"""``wallcli evaluate DIR --task count|activity``: how right is a model on your own labelled clips?"""
from __future__ import annotations

from pathlib import Path
from typing import Optional

import typer

from wallcli.cli.common import (MAX_THREADS, PNG_NAME, ROI_HELP, check_png_names, corrections_of, deflicker_option, exposure_option, shake_option, force_help,
                                number_option, strict_option)

PROGRESS_DELAY = 2.0  # seconds before the progress bar appears


def evaluate(
    folder: Path = typer.Argument(..., metavar="DIR", show_default=False,
                                  help="Folder of clips with labels.csv (columns file, people, activity; optional "
                                       "detectable 0/1 and snr_db) or the .json sidecars 'wallcli simulate' writes."),
    task: str = typer.Option(..., "--task", "-t", help="count or activity."),
    model: Optional[Path] = typer.Option(None, "--model", help="Your own .onnx model (its .json card beside it). "
                                         "Default: the shipped model for --task."),
    json_out: bool = typer.Option(False, "--json", help="Print one JSON object on stdout (docs/contract.md), rows included."),
    plot: Optional[Path] = typer.Option(None, "--plot", help="Draw a reliability diagram (confidence of the clip "
                                        "answers against how often they are right; ECE, the calibration error, is "
                                        "their mean gap, 0 = calibrated) and the clips right by band (the table's "
                                        "bands, on its figure) to this PNG. " + PNG_NAME),
    jobs: int = number_option(0, "--jobs", "-j", lo=0, hi=MAX_THREADS, integer=True,
                              help="Clips analysed at once, one process each (0 = one per core; at most 4 per core)."),
    min_snr: Optional[float] = number_option(None, "--min-snr", lo=-99, hi=99, help="Score only clips where nobody "
                                             "moves and clips whose SNR in dB (labels.csv's snr_db, else the measured column "
                                             "SNR, column_snr_db) is at least this; the others are left out of every figure and counted."),
    roi: Optional[str] = typer.Option(None, "--roi", help=ROI_HELP + " Applies to every clip."),
    force: bool = typer.Option(False, "--force", help=force_help("the --plot PNG (the only file evaluate writes)")),
    strict: bool = strict_option(),
    no_deflicker: bool = deflicker_option(),
    no_exposure: bool = exposure_option(),
    no_shake: bool = shake_option(),
    activity_model: Optional[Path] = typer.Option(None, "--activity-model", help="--task count: the activity model "
                                                  "of the two-stage count's presence stage (default: the shipped one)."),
    single_stage: bool = typer.Option(False, "--single-stage", help="--task count: score the count net alone, not "
                                      "the two-stage count that 'wallcli count' answers with."),
) -> None:
    """Score a model on labelled clips: the check to run before relying on it for a room.

    Each clip is decoded once, classified exactly as 'wallcli count' / 'activity' would
    (same model, windows and stride; the answer's signal_db is the figure its reason
    quotes) and its figures measured from the same decode: the column SNR (column_snr_db,
    the headline every command prints first) and the block SNR (snr_db: green channel,
    wallcli snr's estimator at the block size of one space-time plot bin). Prints first the clips right by band
    (nobody moving, under 0 dB, 0-10 dB, 10 dB and over: on labels.csv's snr_db column where
    there is one, else on the measured column SNR, column_snr_db, the figure every
    command prints first, on the labels' scale), accuracy with its exact 95 %
    interval (Clopper-Pearson, over clips), how many answers were decided (not
    'undetermined') and how often those were right, and the confusion matrix with accuracy per class; then one line per
    clip: the answer ('?' after it when undetermined; why: --json), the truth, right or
    not, and the figure its band is on. With a 'detectable' column, the headline figures are on
    detectable clips and the same on all clips follow; the bands count every clip. For
    activity, clips with more than one person are skipped; so is a clip whose sidecar is
    damaged, with a warning. A clip that cannot be analysed (missing, corrupt, too short)
    is a row with its error and counts as wrong.

    \b
    labels.csv (other columns are ignored; snr_db is empty for an empty room):
      file,people,activity,detectable,snr_db
      kitchen-01.mp4,1,walking,1,12.5
      kitchen-02.mp4,0,none,1,

    \b
    Examples:
      wallcli evaluate recordings/ --task count
      wallcli evaluate recordings/ --task activity --json | jq '.accuracy, .ci95'
      wallcli evaluate recordings/ --task count --model new.onnx --jobs 4
      wallcli evaluate recordings/ --task count --plot reliability.png
      wallcli evaluate recordings/ --task count --min-snr 0 --json | jq '.by_band'
    """
    from wallcli.errors import UsageError

    if task not in ("count", "activity"):
        raise UsageError(f"--task must be count or activity (got {task!r})")
    from wallcli.cli.common import parse_roi

    roi_t = parse_roi(roi)

    from wallcli.cli.output import emit_json, progress, warn
    from wallcli.evaluate import evaluate_folder
    from wallcli.evaluate.run import plan_folder
    from wallcli.io.writer import check_outputs

    check_png_names(("--plot", plot))
    plan = plan_folder(folder, task, min_snr=min_snr)  # fails early (exit 1) on a folder without labels
    for file, why in plan.labels.damaged:
        warn(f"{file} skipped: {why}")
    from wallcli.infer.model import shipped_model_path

    # everything read is an input: the models and their cards, the clips, labels.csv or the sidecars
    models = [model or shipped_model_path(task)]
    if task == "count" and not single_stage:
        models.append(activity_model or shipped_model_path("activity"))
    check_outputs([plot], force=force, inputs=[*models, *(c.path for c in plan.labels.clips), *plan.labels.files])
    # delayed: on a small folder a bar would only flash; on a large one it shows the minutes left
    with progress(f"evaluate {task}", len(plan.kept), delay=PROGRESS_DELAY) as advance:
        result = evaluate_folder(folder, task, model_path=model, roi=roi_t, jobs=jobs, progress=advance, plan=plan,
                                 corrections=corrections_of(no_deflicker, no_exposure, no_shake),
                                 activity_path=activity_model, single=single_stage)
    if plot is not None:
        from wallcli.plots.reliability import save_reliability_png

        save_reliability_png(plot, result, force=force)
    if json_out:
        emit_json(result)
    else:
        from wallcli.cli._evaluate_table import print_evaluation

        print_evaluation(result)
    bad = [r for r in result["rows"] if not (r.get("view") or {}).get("usable", True)]
    if strict and bad:
        from wallcli.errors import WallcliError

        raise WallcliError(f"{len(bad)} clip(s) not a static view of a wall (--strict; the figures above include "
                           f"them as undetermined): {bad[0]['file']}: {bad[0]['view']['reason']}")
