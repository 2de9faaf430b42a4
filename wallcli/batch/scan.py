"""``wallcli scan`` as a function: inputs in, a results file out, a summary back."""
from __future__ import annotations

import os
import time
from pathlib import Path
from typing import Any, Callable

from wallcli.batch.analyse import CLASSIFY, TASKS
from wallcli.errors import UsageError, WallcliError


def parse_tasks(text: str) -> tuple[str, ...]:
    """'count,snr' -> ('count', 'snr'), in the canonical order (so resuming compares like with like)."""
    asked = [t.strip().lower() for t in text.split(",") if t.strip()]
    unknown = [t for t in asked if t not in TASKS]
    if unknown or not asked:
        raise UsageError(f"--task takes a comma list of {', '.join(TASKS)} (got {text!r})")
    return tuple(t for t in TASKS if t in asked)


def _classes(tasks) -> dict[str, list]:
    from wallcli.infer.card import read_card
    from wallcli.infer.model import shipped_model_path

    return {t: read_card(shipped_model_path(t))["classes"] for t in CLASSIFY if t in tasks}


def _unchanged(source: str, entry) -> bool:
    """Is ``source`` the video that ``entry`` answered for? Size first (free), then the sha256."""
    from wallcli.batch.inputs import is_url
    from wallcli.infer.card import sha256_file

    if is_url(source):
        return True  # a stream has no content to compare; its name is all there is
    try:
        if os.path.getsize(source) != entry.size:
            return False
        return sha256_file(Path(source)) == entry.sha256
    except OSError:
        return False


def _holds_results(path: Path, columns) -> bool:
    """Is ``path`` (found in a scanned folder) a results file of scan's, resumable or empty?"""
    from wallcli.batch.results import read

    try:
        return path.stat().st_size == 0 or read(path, columns) is not None
    except (OSError, WallcliError):
        return False


def same_making(entry, options: dict | None, models: dict | None) -> bool:
    """Was ``entry``'s line made as this run would make it: the same options (a line that does not
    record them is from an older wallcli: made again) and, per classification task, the same model?"""
    if options is not None and entry.options != options:
        return False
    if models:
        return all((entry.models or {}).get(t) == sha for t, sha in models.items())
    return True


def plan(sources: list[str], out: Path, tasks, *, force: bool, columns, options: dict | None = None,
         models: dict | None = None, stale: list | None = None,
         skipped: list | None = None) -> tuple[list[str], int, list | None]:
    """(videos to do, videos skipped, the earlier lines to keep or None to keep the file as it is).

    A line made with other ``options`` or ``models`` ({task: sha256}) is not this run's answer:
    its video is analysed again and the new line replaces it (``stale`` collects their inputs).
    ``skipped`` collects the entries of the videos skipped (their lines are this run's answers)."""
    from wallcli.batch.results import key, read

    if force:
        return list(sources), 0, []
    entries, torn = read(out, columns)
    header_missing = columns is not None and out.stat().st_size == 0
    other = sorted({",".join(e.tasks) for e in entries if tuple(e.tasks) != tuple(tasks)})
    if other:
        raise WallcliError(f"{out} holds results of --task {other[0]}; this run asks for --task {','.join(tasks)}",
                           hint="use the same --task to resume, another -o, or --force to start it again")
    wanted = {key(s): s for s in sources}
    done: dict[str, object] = {}  # video -> its one valid line
    for e in entries:
        k = key(e.input)
        if e.error is None and k in wanted and k not in done and _unchanged(wanted[k], e):
            if not same_making(e, options, models):
                if stale is not None:
                    stale.append(e.input)
                continue
            done[k] = e
    # this run's videos keep only the lines just found valid; failed or changed ones are done again
    kept = [e for e in entries if key(e.input) not in wanted or done.get(key(e.input)) is e]
    dropped = len(entries) - len(kept)
    todo = [s for s in sources if key(s) not in done]
    if skipped is not None:
        skipped.extend(done.values())
    return todo, len(done), (kept if (dropped or torn or header_missing) else None)


def run_scan(inputs: list[str], output: str | os.PathLike, *, tasks=TASKS, workers: int | None = None,
             scheduler: str | None = None, globs: list[str] | None = None, force: bool = False,
             windows: bool = False, timeout: float = 300.0, encode: Callable[[dict], str],
             log: Callable[[str], None] = lambda m: None,
             on_start: Callable[[int, int], None] = lambda todo, skipped: None,
             on_line: Callable[[dict], None] = lambda line: None, debug: bool = False,
             on_skip: Callable[[list], None] = lambda entries: None,
             deflicker: bool = True, exposure: bool = True, shake: bool = True) -> dict[str, Any]:
    """Scan every video named by ``inputs`` into ``output``; the summary of the run.

    ``on_start(todo, skipped)`` once the work is known; ``on_line(line)`` after each line is
    stored; ``on_skip(entries)`` with the :class:`~wallcli.batch.results.Entry` of each video skipped
    (its earlier line kept as this run's answer). Exceptions are for the run as a whole (no video, bad output, unreachable cluster,
    mismatched workers, interruption); a video's own failure is its error line.
    """
    from wallcli.batch.engine import Engine
    from wallcli.batch.inputs import VIDEO_EXTENSIONS, expand_inputs, is_url
    from wallcli.batch.results import csv_columns, is_csv
    from wallcli.batch.resultsfile import ResultsFile
    from wallcli.batch.task import ScanConfig, identity, scan_video
    from wallcli.io.writer import check_output

    tasks = tuple(t for t in TASKS if t in tasks)
    if Path(output).name.lower().endswith(VIDEO_EXTENSIONS):  # a slip that would put JSON over a video
        raise UsageError(f"-o {output} is named as a video; scan writes its results to a .jsonl or .csv file, "
                         "never to a video name, --force or not")
    # the results file inside a scanned folder is not a video: running the command again resumes
    picked: list[str] = []
    sources = expand_inputs([str(i) for i in inputs], globs, skip=Path(output), skipped_as=picked)
    from wallcli.infer.model import shipped_model_path

    out = check_output(output, force=True, inputs=[*(s for s in sources if not is_url(s)),
                                                   *(shipped_model_path(t) for t in CLASSIFY if t in tasks)])
    columns = csv_columns(tasks, _classes(tasks), windows) if is_csv(out) else None
    if picked and not _holds_results(out, columns):  # what --glob picks up is a video to scan, not to overwrite
        raise WallcliError(f"output {out} is one of the inputs (found as {picked[0]}); wallcli never overwrites "
                           "an input, --force or not", hint="write the results elsewhere, or narrow --glob")
    results = ResultsFile(out, encode, columns)
    results.open()  # and locked: from here to the end, no other scan writes it
    ok = failed = 0
    seconds_of_video = 0.0
    engine_workers = 0
    try:
        options = ScanConfig(tasks=tasks, windows=windows, deflicker=deflicker, exposure=exposure,
                             shake=shake).options()
        models = {t: sha for t, sha in identity()["models"].items() if t in tasks}
        stale: list = []
        skipped_entries: list = []
        todo, skipped, kept = plan(sources, out, tasks, force=force, columns=columns, options=options,
                                   models=models, stale=stale, skipped=skipped_entries)
        if skipped:
            log(f"{skipped} of {len(sources)} videos already in {out} (same sha256, tasks, options and models): "
                "skipped; --force redoes them")
        if stale:
            log(f"{len(stale)} video(s) in {out} were analysed with other options or models (e.g. {stale[0]}): "
                "analysed again, their lines replaced")
        # this run's answers include the lines it kept: --strict must see their views too
        on_skip(skipped_entries)
        on_start(len(todo), skipped)
        config = ScanConfig(tasks=tasks, windows=windows, timeout=timeout, expected=identity(),
                            deflicker=deflicker, exposure=exposure, shake=shake)
        results.start(kept, force=force)
        t0 = time.perf_counter()
        if todo:
            def failed_line(source: str, message: str) -> dict:
                return {"input": source, "size": None, "sha256": None, "duration": None, "frames": None,
                        "tasks": list(tasks), "error": " ".join(message.split())}

            from wallcli.batch.engine import default_workers

            # no more local workers than videos: each costs a process start and the models' load
            local = min(workers or default_workers(), len(todo))
            with Engine(workers=local, scheduler=scheduler, log=log, debug=debug) as engine:
                engine_workers = engine.workers
                for _, line in engine.map(scan_video, todo, config, failed=failed_line):
                    results.append(line)
                    if line.get("error") is None:
                        ok += 1
                        seconds_of_video += float(line.get("duration") or 0.0)
                    else:
                        failed += 1
                    on_line(line)
    except BaseException:
        results.abandon()  # a run that failed before its first line leaves no file it created
        if results.note:  # what became of --force's new lines
            log(results.note)
        raise
    results.close()
    wall = time.perf_counter() - t0
    return {
        "output": str(out),
        "tasks": list(tasks),
        "videos": len(sources),
        "skipped": skipped,
        "processed": ok + failed,
        "ok": ok,
        "failed": failed,
        "hours": round(seconds_of_video / 3600.0, 6),
        "seconds": round(wall, 3),
        "videos_per_second": round((ok + failed) / wall, 4) if wall > 0 and (ok + failed) else 0.0,
        "engine": scheduler or "local",
        "workers": engine_workers,
    }
