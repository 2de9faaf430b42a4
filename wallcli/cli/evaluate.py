"""``wallcli evaluate DIR --task count|activity``: how right is a model on your own labelled clips?"""
from __future__ import annotations

from pathlib import Path
from typing import Optional

import typer

from wallcli.cli.common import MAX_THREADS, ROI_HELP, force_help, number_option


def evaluate(
    folder: Path = typer.Argument(..., metavar="DIR", show_default=False,
                                  help="Folder of clips with labels.csv (columns file, people, activity; optional "
                                       "detectable 0/1) or the .json sidecars 'wallcli simulate' writes."),
    task: str = typer.Option(..., "--task", "-t", help="count or activity."),
    model: Optional[Path] = typer.Option(None, "--model", help="Your own .onnx model (its .json card beside it). "
                                         "Default: the shipped model for --task."),
    json_out: bool = typer.Option(False, "--json", help="Print one JSON object on stdout (docs/contract.md), rows included."),
    plot: Optional[Path] = typer.Option(None, "--plot", help="Draw a reliability diagram (confidence of the clip "
                                        "answers against how often they are right) and accuracy against measured "
                                        "SNR to this PNG."),
    jobs: int = number_option(0, "--jobs", "-j", lo=0, hi=MAX_THREADS, integer=True,
                              help="Clips analysed at once, one process each (0 = one per core; at most 4 per core)."),
    roi: Optional[str] = typer.Option(None, "--roi", help=ROI_HELP + " Applies to every clip."),
    force: bool = typer.Option(False, "--force", help=force_help("the --plot PNG, the only file evaluate writes,")),
) -> None:
    """Score a model on labelled clips: the check to run before relying on it for a room.

    Each clip is decoded once, classified exactly as 'wallcli count' / 'activity' would
    (same model, windows and stride) and its SNR measured (green channel, wallcli snr's
    estimator at the block size of one space-time plot bin). Prints one row per clip,
    accuracy with a 95 % bootstrap interval over clips, the confusion matrix, accuracy by
    measured SNR and per class, and how many answers were decided (not 'undetermined') and
    how often those were right. With a 'detectable' column, the headline figures are on
    detectable clips and the same on all clips follow. For activity, clips with more than
    one person are skipped. A clip that cannot be analysed (missing, corrupt, too short) is
    a row with its error and counts as wrong.

    \b
    labels.csv (other columns are ignored):
      file,people,activity,detectable
      kitchen-01.mp4,1,walking,1
      kitchen-02.mp4,0,none,1

    \b
    Examples:
      wallcli evaluate recordings/ --task count
      wallcli evaluate recordings/ --task activity --json | jq '.accuracy, .ci95'
      wallcli evaluate recordings/ --task count --model new.onnx --plot reliability.png --jobs 4
    """
    from wallcli.errors import UsageError

    if task not in ("count", "activity"):
        raise UsageError(f"--task must be count or activity (got {task!r})")
    from wallcli.cli.common import parse_roi

    roi_t = parse_roi(roi)

    from wallcli.cli.output import emit_json, progress
    from wallcli.evaluate import evaluate_folder
    from wallcli.evaluate.labels import read_labels
    from wallcli.io.writer import check_outputs

    clips, _ = read_labels(folder)  # fails early (exit 1) on a folder without labels
    check_outputs([plot], force=force, inputs=[model, *(c.path for c in clips)])
    total = sum(task == "count" or c.persons <= 1 for c in clips)  # activity skips clips of two people
    with progress(f"evaluate {task}", total) as advance:
        result = evaluate_folder(folder, task, model_path=model, roi=roi_t, jobs=jobs, progress=advance)
    if plot is not None:
        from wallcli.plots.reliability import save_reliability_png

        save_reliability_png(plot, result, force=force)
    if json_out:
        emit_json(result)
        return
    from wallcli.cli._evaluate_table import print_evaluation

    print_evaluation(result)
