"""``wallcli evaluate``: a model against a folder of labelled clips, as CONTRACT.md lays it out."""
from __future__ import annotations

import os
from contextlib import closing
from dataclasses import dataclass
from pathlib import Path
from typing import Any, Callable

from wallcli.errors import WallcliError
from wallcli.evaluate import score
from wallcli.evaluate.clip import init_worker, run_clip
from wallcli.evaluate.labels import Clip, Labels, read_labels
from wallcli.evaluate.pool import imap_isolated

TWO_PEOPLE = "more than one person (activity is defined for one)"


@dataclass(frozen=True)
class Plan:
    """What a run will analyse, known before any decode (the CLI sizes its progress bar on it)."""
    task: str
    labels: Labels
    kept: list[Clip]
    skipped: list[tuple[str, str]]  # (file, why): not scored at all
    excluded: list[str]  # under --min-snr by the labels' SNR: not analysed
    min_snr: float | None


def plan_folder(folder: str | Path, task: str, *, min_snr: float | None = None) -> Plan:
    labels = read_labels(folder)
    kept, skipped, excluded = [], [], []
    for c in labels.clips:
        if task == "activity" and c.persons > 1:
            skipped.append((c.file, TWO_PEOPLE))
        elif min_snr is not None and labels.has_snr and not c.empty(task) and not _at_least(c.snr_db, min_snr):
            excluded.append(c.file)
        else:
            kept.append(c)
    return Plan(task, labels, kept, skipped + labels.damaged, excluded, min_snr)


def _at_least(snr_db: float | None, min_snr: float) -> bool:
    return snr_db is not None and snr_db >= min_snr  # an unknown SNR is not known to be high enough


def default_jobs() -> int:
    try:
        return len(os.sched_getaffinity(0))
    except AttributeError:  # not Linux
        return os.cpu_count() or 1


def evaluate_folder(folder: str | Path, task: str, *, model_path: str | Path | None = None, roi=None,
                    jobs: int = 0, progress: Callable[[int], None] | None = None, min_snr: float | None = None,
                    plan: Plan | None = None, corrections=None, activity_path: str | Path | None = None,
                    single: bool = False) -> dict[str, Any]:
    """Run ``task``'s model (the shipped one, or ``model_path``) on every labelled clip of ``folder``
    in ``jobs`` processes (0: one per core) and score it. A clip that fails is a row with its
    error (and a wrong answer); labels that cannot be read raise WallcliError. ``min_snr``: score
    only empty rooms and clips whose SNR (the labels', else the measured one) is at least that;
    a clip whose SNR is unknown (it failed) is left out too. ``plan``: :func:`plan_folder`'s, when
    the caller has made it already (its min_snr then holds)."""
    from wallcli.infer.twostage import load_classifier

    plan = plan or plan_folder(folder, task, min_snr=min_snr)
    # checked here once: a bad model fails before any worker starts; count is two-stage unless single
    model = load_classifier(task, model_path, activity_path=activity_path, single=single)
    classes = model.classes
    kept = plan.kept
    for c in kept:
        if c.truth(task) not in classes:
            raise WallcliError(f"{c.file}: its label {c.truth(task)!r} is not one of the {task} model's classes "
                               f"({', '.join(map(str, classes))})")

    stride = int(model.card["stride"])
    outcome: dict[int, dict] = {}
    todo = []
    for i, c in enumerate(kept):
        if c.path.exists():
            todo.append(i)
        else:
            outcome[i] = {"error": f"no such file: {c.file}"}
            if progress:
                progress(1)
    if todo:
        n = jobs or default_jobs()
        initargs = (task, str(model.path), stride, tuple(roi) if roi else None, corrections,
                    str(model.activity.path) if not model.single else None, model.single)
        with closing(imap_isolated(run_clip, [str(kept[i].path) for i in todo], jobs=n,
                                   initializer=init_worker, initargs=initargs)) as results:
            for k, value in results:
                outcome[todo[k]] = value
                if progress:
                    progress(1)
    has_snr = plan.labels.has_snr
    rows = [_row(c, outcome[i], task, has_snr) for i, c in enumerate(kept)]
    if rows and all(r["error"] is not None for r in rows):
        # nothing was analysed: a wrong folder, an ROI outside every frame. The work failed.
        raise WallcliError(f"none of the {len(rows)} clips could be analysed (first, {rows[0]['file']}: "
                           f"{rows[0]['error']})")
    excluded = list(plan.excluded)
    if plan.min_snr is not None and not has_snr:  # only now is the measured SNR known
        keep = [r["band"] == "empty" or _at_least(r["column_snr_db"], plan.min_snr) for r in rows]
        excluded += [r["file"] for r, k in zip(rows, keep) if not k]
        rows = [r for r, k in zip(rows, keep) if k]
    if not rows:
        why = [f"{len(plan.skipped)} skipped"] + ([f"{len(excluded)} under --min-snr {plan.min_snr:g} dB"]
                                                  if plan.min_snr is not None else [])
        raise WallcliError(f"{folder}: no clip to score ({', '.join(why)})")
    from wallcli.infer.twostage import stages_info

    out = report(rows, task=task, model=model.info(), classes=classes, folder=str(folder), labels=plan.labels.source,
                 skipped=plan.skipped, stride=stride, roi=roi, snr_source="labels" if has_snr else "measured",
                 min_snr=plan.min_snr, excluded=excluded)
    if stages_info(model) is not None:  # count in two stages: with which activity model
        out["stages"] = stages_info(model)
    return out


def _row(clip: Clip, out: dict, task: str, has_snr: bool) -> dict[str, Any]:
    res = out.get("result")
    err = out.get("error")
    snr = out.get("snr_db")
    # the measured bands are on the headline column SNR (wallcli.snr.column: the figure every
    # command prints first, on the labels' scale, from the same decode), not on the block SNR in
    # snr_db nor on the answers' signal_db: the README's bands are on that scale (issue 61.1)
    signal = res.get("signal_db") if res else None
    column = res.get("column_snr_db") if res else None
    return {
        "file": clip.file,
        "truth": clip.truth(task),
        "label": res["label"] if res else None,
        # another module adds these to the classifier's result; absent means it was not judged
        "confident": bool(res.get("confident", True)) if res else None,
        "probabilities": res["probabilities"] if res else None,
        "snr_db": snr,
        "signal_db": signal,
        "column_snr_db": column,
        "detectable": clip.detectable,
        "error": err,
        "reason": res.get("reason") if res else None,
        "view": res.get("view") if res else None,  # None for a .npz: no pixels to check
        "corrections": res.get("corrections") if res else None,
        "snr_block": out.get("snr_block"),
        "windows": res.get("windows_n") if res else None,
        "warnings": out.get("warnings", []),
        "snr_db_labels": clip.snr_db,
        "band": score.band_of(clip.empty(task), clip.snr_db if has_snr else column),
    }


def report(rows: list[dict], *, task: str, model: dict, classes: list, folder: str, labels: str,
           skipped: list[tuple[str, str]], stride: int, roi, snr_source: str = "measured",
           min_snr: float | None = None, excluded: list[str] = ()) -> dict[str, Any]:
    """The CONTRACT.md object from finished rows; ``skipped`` holds (file, why) pairs."""
    for r in rows:
        r["correct"] = score.correct(r)
        if "band" not in r:  # rows from elsewhere: the truth says which rooms are empty
            r["band"] = score.band_of(r["truth"] in (0, "none"), r.get("column_snr_db"))
    given = any(r["detectable"] is not None for r in rows)
    # unknown detectability (a blank cell) counts as detectable: only a stated 0 leaves the headline
    head = [r for r in rows if r["detectable"] is not False] if given else rows
    h = score.summary(head, classes)
    out: dict[str, Any] = {
        "task": task,
        "model": model,
        "dir": folder,
        "clips": len(rows),
        "scored": h["scored"],
        "errors": sum(r["error"] is not None for r in rows),
        "accuracy": h["accuracy"],
        "ci95": h["ci95"],
        "decided": h["decided"],
        "coverage": h["coverage"],
        "accuracy_decided": h["accuracy_decided"],
        "classes": classes,
        "confusion": h["confusion"],
    }
    if given:
        out["all"] = score.summary(rows, classes)
    out.update({
        "rows": rows,
        "correct": h["correct"],
        "correct_decided": h["correct_decided"],
        "ci95_decided": h["ci95_decided"],
        "errors_by_class": h["errors_by_class"],
        "scored_on": "detectable clips" if given else "all clips",
        "per_class": score.per_class(head, classes),
        "by_snr": score.by_snr(head),
        # bands over every scored clip, detectable or not: where a model stops working is the point
        "by_band": score.by_band(rows),
        "snr_source": snr_source,
        # the row field the bands (and a measured --min-snr) are on; snr_source keeps its values
        "snr_figure": "snr_db_labels" if snr_source == "labels" else "column_snr_db",
        "band_measure": ("labels.csv's snr_db" if snr_source == "labels" else
                         "column_snr_db, the column SNR (the headline figure every command prints first, on "
                         "the labels' scale), not the block SNR in snr_db nor the answers' signal_db"),
        "min_snr": min_snr,
        "excluded": len(excluded),
        "excluded_files": list(excluded),
        "reliability": score.reliability(head),
        "skipped": [f for f, _ in skipped],
        "skipped_reasons": [{"file": f, "reason": why} for f, why in skipped],
        "labels": labels,
        "stride": stride,
        "roi": list(roi) if roi else None,
        "interval": {"method": "clopper-pearson", "level": 0.95},
        "snr_measure": "green-channel SNR (wallcli snr's estimator) at the block size nearest one space-time "
                       "plot bin's area; see snr_block per row; the measured bands are on column_snr_db, not on it",
    })
    return out
