"""``wallcli scan INPUT... -o results.jsonl``: many videos, one decode each, on this machine or a
Dask cluster, resumable."""
from __future__ import annotations

from pathlib import Path
from typing import List, Optional

import typer

from wallcli.cli.common import (MAX_THREADS, deflicker_option, exposure_option, number_option, shake_option,
                                strict_option)


def scan(
    inputs: List[str] = typer.Argument(..., help="Video files, folders (searched recursively, see --glob), http(s)/rtsp "
                                       "URLs, or @list.txt (one path or URL a line, # comments).", show_default=False,
                                       metavar="INPUT"),
    output: Path = typer.Option(..., "-o", "--output", help="Results: JSON Lines (one object per video, see docs/contract.md), "
                                "or flattened CSV when the name ends in .csv. An existing file is resumed; one scan "
                                "at a time writes it (a second one exits 1). Never a video's name, nor a file the "
                                "inputs name or a folder's --glob picks up, --force or not.",
                                show_default=False),
    task: str = typer.Option("count,activity,snr", "--task", help="Comma list of count, activity, snr: what each video is "
                             "asked. All come from one decode of the video."),
    workers: Optional[int] = number_option(None, "--workers", lo=1, hi=MAX_THREADS, integer=True, help="Worker "
                                           "processes on this machine (one core each). Default: the number of cores."),
    scheduler: Optional[str] = typer.Option(None, "--scheduler", help="Run on an existing Dask cluster instead, e.g. "
                                            "tcp://10.0.0.5:8786 (its workers need this wallcli version installed). "
                                            "Reaching it and Dask's handshake time out after 20 s (exit 1)."),
    glob: Optional[List[str]] = typer.Option(None, "--glob", help="File names to take from folders, e.g. '*.mp4' "
                                             "(repeatable). Default: the usual video extensions, any case."),
    force: bool = typer.Option(False, "--force", help="Start the results file again (every video redone) instead of "
                               "resuming it. The old results stay whole until the run ends (the new lines go to a "
                               "hidden file beside them); a run interrupted or failed after some new lines merges "
                               "them into the old results."),
    windows: bool = typer.Option(False, "--windows", help="Keep every window's answer in count and activity "
                                 "(the lines grow by a few hundred bytes per 2 s of video)."),
    timeout: float = number_option(300.0, "--timeout", lo=0, hi=86400, help="Give a video up (an error line) when its decoder "
                                  "produces no frame for this many seconds. 0: wait forever."),
    json_out: bool = typer.Option(False, "--json", help="Print the run's summary as one JSON object on stdout."),
    strict: bool = strict_option(),
    no_deflicker: bool = deflicker_option(),
    no_exposure: bool = exposure_option(),
    no_shake: bool = shake_option(),
) -> None:
    """Analyse many videos into one results file: one line per video, as each finishes.

    Each video is decoded once; its frames feed the space-time plots (for count and activity)
    and the SNR estimate together, and the answers equal those of 'wallcli count/activity/snr
    --json' on that video. Videos run in parallel on a Dask LocalCluster of worker processes
    on this machine, or on an existing Dask cluster (--scheduler). A video that cannot be read,
    is too short, hangs its decoder (--timeout) or kills its worker twice gets a line with
    "error" and the scan goes on.

    Re-running the same command resumes: videos already in the output with the same sha256,
    tasks, options (--no-deflicker, --no-exposure, --no-shake, --windows) and models are skipped;
    failed ones, and ones made with other options or models, are analysed again (the new line
    replaces the old); --force redoes everything. With --strict, the skipped videos' views count. The exit code is
    0 when every video has its line, failed or not: count failures in the summary (--json).

    \b
    Examples:
      wallcli scan recordings/ -o results.jsonl
      wallcli scan cam1/ cam2/ --glob '*.mkv' --task count,snr -o day.csv
      wallcli scan @todo.txt -o results.jsonl --scheduler tcp://10.0.0.5:8786
      jq -r 'select(.error == null) | [.input, (.count | if .confident
        then .label else "undetermined, most likely \\(.label)" end)]
        | @tsv' results.jsonl
    """
    import os

    from wallcli.batch.scan import parse_tasks, run_scan
    from wallcli.cli.output import emit_json, log, to_json

    tasks = parse_tasks(task)
    if workers is not None and scheduler is not None:
        from wallcli.errors import UsageError

        raise UsageError("--workers sizes the cluster on this machine; a --scheduler has its own workers")
    debug = os.environ.get("WALLCLI_DEBUG", "") not in ("", "0")
    state = {"hours": 0.0, "failed": 0, "unusable": []}

    def on_line(line: dict) -> None:
        view = line.get("view") or {}
        if not view.get("usable", True):
            state["unusable"].append((line["input"], view.get("reason")))
        if line.get("error") is None:
            state["hours"] += float(line.get("duration") or 0.0) / 3600.0
        else:
            state["failed"] += 1
            # named as they happen: the bar only counts them
            err = line["error"]
            log(f"failed: {err}" if line["input"] in err else f"failed: {line['input']}: {err}", wrap=False)
        bar.update(state["hours"], state["failed"])

    def on_skip(entries) -> None:  # a resumed run's kept lines are its answers too (--strict)
        state["unusable"] += [(e.input, (e.view or {}).get("reason")) for e in entries
                              if (e.view or {}).get("usable") is False]

    with _Bar() as bar:
        summary = run_scan(inputs, output, tasks=tasks, workers=workers, scheduler=scheduler, globs=glob,
                           force=force, windows=windows, timeout=timeout, encode=to_json, log=lambda m: log(m, wrap=False),
                           on_start=bar.start, on_line=on_line, debug=debug, on_skip=on_skip,
                           deflicker=not no_deflicker, exposure=not no_exposure, shake=not no_shake)
    from wallcli.wording import plural

    log(f"scan: {plural(summary['videos'], 'video')}: {summary['ok']} done, {summary['failed']} failed, "
        f"{summary['skipped']} already done; {summary['hours']:.2f} h of video in {summary['seconds']:.1f} s "
        f"({summary['videos_per_second']:.2f} videos/s) -> {summary['output']}", wrap=False)
    if json_out:
        emit_json(summary)
    if strict and state["unusable"]:
        from wallcli.errors import WallcliError

        first, why = state["unusable"][0]
        raise WallcliError(f"{plural(len(state['unusable']), 'video')} of this run (kept lines of a resume "
                           f"included) not a static view of a wall (--strict; every line is written), "
                           f"first {first}: {why}")


class _Bar:
    """The progress bar, opened once the number of videos to do is known."""

    def __init__(self):
        self._cm = None
        self.update = lambda hours, failed: None

    def start(self, todo: int, skipped: int) -> None:
        from wallcli.cli.output import batch_progress

        if todo:
            self._cm = batch_progress("scan", todo)
            self.update = self._cm.__enter__()

    def __enter__(self) -> "_Bar":
        return self

    def __exit__(self, *exc) -> None:
        if self._cm is not None:
            self._cm.__exit__(*exc)
