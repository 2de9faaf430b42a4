"""``wallcli report``: one self-contained HTML page for a clip, or for a whole scan."""
from __future__ import annotations

import shlex
from pathlib import Path
from typing import Optional

import typer

from wallcli.cli.common import (stream_option, stall_option, ROI_HELP, THREADS_HELP, corrections_of, deflicker_option, exposure_option, shake_option, force_help,
                                parse_roi, refuse_view, strict_option, threads_option)

RESULTS_SUFFIXES = (".jsonl", ".ndjson")
# what report reads, said in every error about an input it cannot read (as the INPUT help says it)
ACCEPTS = ("report reads a video (file, http(s)/rtsp URL, or '-' for a stream on stdin) or the .jsonl "
           "results of 'wallcli scan'")


def _not_readable(input: str) -> str:
    """The one error line for an input that is neither a video nor scan's .jsonl."""
    if str(input).lower().endswith((".csv", ".tsv")):  # scan -o day.csv: for spreadsheets, not read back
        return (f"{input} is a table, not a video: {ACCEPTS} (scan's .csv is for spreadsheets; "
                "write its results with -o results.jsonl for a report)")
    return f"{input} is not a video: {ACCEPTS}"


def report(
    input: str = typer.Argument(..., show_default=False, help="A video (file, http(s)/rtsp URL, or '-' for a stream on "
                                "stdin), or the .jsonl results of 'wallcli scan'."),
    output: Path = typer.Option(..., "--output", "-o", show_default=False, help="The HTML file to write (.html)."),
    roi: Optional[str] = typer.Option(None, "--roi", help=ROI_HELP),
    count_model: Optional[Path] = typer.Option(None, "--count-model", help="Your own count .onnx (its card beside it). Default: the shipped model."),
    activity_model: Optional[Path] = typer.Option(None, "--activity-model", help="Your own activity .onnx (its card beside it). Default: the shipped model."),
    force: bool = typer.Option(False, "--force", help=force_help("the -o file")),
    threads: int = threads_option(THREADS_HELP),
    stream: Optional[int] = stream_option(),
    stall_timeout: Optional[float] = stall_option(follow=False),
    strict: bool = strict_option(),
    no_deflicker: bool = deflicker_option(),
    no_exposure: bool = exposure_option(),
    no_shake: bool = shake_option(),
) -> None:
    """Write one HTML page that opens offline in any browser and can be handed over as it is.

    For a video: the evidence's identity (size, sha256, container, codec, resolution, frame
    rate, frames decoded, decode warnings), a frame with the region analysed, signal and noise
    per block size and where on the wall the signal is (Sharma et al., What You Can Learn by
    Staring at a Blank Wall, ICCV 2021, supplementary §3.2), both space-time plots, the
    count and activity answers with their per-window probabilities (or 'undetermined' and why),
    the models with their validated accuracy and what they cannot do, and the method and its
    limits in plain words. The video is decoded once. A clip too short for one 8.5 s window
    still gets its page, whose answers say why there are none.

    For the .jsonl of 'wallcli scan': one row per video (name, duration, pixel SNR, count and
    activity with the signal each was judged on, error), sortable by any column and filterable
    by text, with totals on top (how many answers each task decided).

    Images are embedded and the page loads nothing from anywhere: no network, scripts or fonts
    from outside. Every name and value from the input is shown as text, never as markup.

    \b
    Examples:
      wallcli report clip.mp4 -o clip.html
      wallcli report clip.mp4 --roi 100,50,640,360 -o clip.html --force
      wallcli scan cam1/*.mp4 -o results.jsonl
      wallcli report results.jsonl -o index.html
    """
    from wallcli.cli.common import use_stream

    use_stream(stream, stall_timeout)
    from wallcli.errors import UsageError

    if output.suffix.lower() not in (".html", ".htm"):
        raise UsageError(f"-o must end in .html (got {output})")
    roi_t = parse_roi(roi)
    results = str(input).lower().endswith(RESULTS_SUFFIXES)
    if str(input).lower().endswith((".csv", ".tsv")) and Path(input).is_file():
        from wallcli.errors import WallcliError

        raise WallcliError(_not_readable(input))
    if results and (roi_t or count_model or activity_model or no_deflicker or no_exposure or no_shake
                    or stream is not None):
        raise UsageError("--roi, --count-model, --activity-model, --stream and --no-deflicker/--no-exposure/--no-shake apply "
                         "to a video; scan results are already analysed (scan records its options in each line)")

    from wallcli.cli.output import progress, warn
    from wallcli.io.writer import check_outputs, write_text_atomic

    from wallcli.infer.model import shipped_model_path

    check_outputs([output], force=force, inputs=[input, count_model or shipped_model_path("count"),
                                                 activity_model or shipped_model_path("activity")])
    command = _command_line(input, output, roi, count_model, activity_model, force, threads,
                            strict=strict, no_deflicker=no_deflicker, no_exposure=no_exposure, no_shake=no_shake,
                            stream=stream)
    if results:
        from wallcli.report.pages import scan_page
        from wallcli.report.scan import read_results, summarise

        records, problems = read_results(input)
        for p in problems:
            warn(p)
        if strict:  # as for a video: an unusable view is the input's error, before any page is written
            bad = [r for r in records if isinstance(r.get("view"), dict) and r["view"].get("usable") is False]
            if bad:
                from wallcli.errors import WallcliError

                raise WallcliError(f"{len(bad)} video(s) in {input} not a static view of a wall (--strict), first "
                                   f"{bad[0].get('input')}: {bad[0]['view'].get('reason') or 'not a static view'}")
        html = scan_page(str(input), summarise(records), problems, command=command)
    else:
        from wallcli.report.analysis import analyse, load_models
        from wallcli.report.pages import clip_page

        from wallcli.errors import WallcliError
        from wallcli.io.video import NotAVideo

        models = load_models(count_model, activity_model)
        try:
            with progress("report", None) as advance:
                analysis = analyse(input, roi=roi_t, models=models, threads=threads, progress=advance,
                                   corrections=corrections_of(no_deflicker, no_exposure, no_shake))
        except NotAVideo as exc:  # FFmpeg's words alone do not say what report would have read
            raise WallcliError(f"{_not_readable(input)} ({exc.detail})") from None
        if strict:
            refuse_view(input, analysis.view)
        for w in analysis.warnings:
            warn(w)
        for task, why in analysis.failures.items():
            warn(f"no {task} verdict: {why}")
        html = clip_page(analysis, command=command)
    write_text_atomic(output, html, force=force)
    from wallcli.cli.output import wrote

    size = len(html.encode("utf-8"))
    what = "scan summary" if results else "report"
    shown = f"{size / 1e6:.1f} MB" if size >= 1e6 else f"{max(size / 1e3, 1):.0f} kB"
    wrote((output, f"{what}, {shown}, self-contained: open it in any browser"))


def _command_line(input, output, roi, count_model, activity_model, force, threads, *, strict=False,
                  no_deflicker=False, no_exposure=False, no_shake=False, stream=None) -> str:
    """The command as given, in canonical form (options in a fixed order; the same in-process):
    every option that changes an answer (or the exit status) is in it, so running it again gives
    this page's answers."""
    args = ["wallcli", "report", str(input), "-o", str(output)]
    for flag, value in (("--roi", roi), ("--count-model", count_model), ("--activity-model", activity_model),
                        ("--stream", stream)):
        if value is not None:
            args += [flag, str(value)]
    for flag, on in (("--no-deflicker", no_deflicker), ("--no-exposure", no_exposure), ("--no-shake", no_shake),
                     ("--strict", strict)):
        if on:
            args.append(flag)
    if threads:
        args += ["--threads", str(threads)]
    if force:
        args.append("--force")
    return shlex.join(args)
