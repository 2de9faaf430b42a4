"""``wallcli train --clips DIR [--folds K]``: the recordings' windows, the out-of-fold table, the card's block."""
from __future__ import annotations

from dataclasses import replace
from pathlib import Path
from typing import Any

import numpy as np


def default_cache() -> Path:
    from wallcli.datagen.ptcache import cache_base

    return cache_base() / "recordings"


def prepare(cfg, task: str, clips: list[Path], sim_data: list[Path], folds: int, cache: Path | None, out: Path,
            bars, level: float, split: list | None = None) -> tuple[Any, dict[str, Any]]:
    """(the final run's config: every recording plus ``sim_data``, the card's ``recordings`` block)."""
    from wallcli.cli.output import log, progress
    from wallcli.infer.twostage import load_classifier
    from wallcli.train import folds as fl
    from wallcli.train.recordings import FOLD_RULE, HARVEST_STRIDE, count_clips, load_recordings

    with progress("cutting recordings into windows", count_clips(clips, task)) as advance:
        recs = load_recordings(clips, cache or default_cache(), task=task, progress=lambda name: advance(1))
    work = out.parent / f".{out.name}.recordings"  # fold datasets, fold models and their answers: resumable
    fold_dirs = fl.write_fold_datasets(recs, task, work / "data", folds)
    windows = sum(len(r.starts) for r in recs)
    block: dict[str, Any] = {"clips": len(recs), "windows": windows, "stride": HARVEST_STRIDE,
                             "folders": [str(c) for c in clips], "folds": folds}
    log(f"{len(recs)} labelled clips, {windows} windows (every {HARVEST_STRIDE} samples at 30 fps)")
    split_sim = fl.simulated_split_data(sim_data, split) if split and sim_data else None
    if folds:
        answers = fl.cross_validate(cfg, fold_dirs, sim_data, recs, work, bars=bars, log=log,
                                    load=lambda p: load_classifier(task, p), split=split, split_sim=split_sim)
        classes = [0, 1, 2] if task == "count" else ["none", "walking", "crouching", "waving", "jumping"]
        table, trust = judge_out_of_fold(recs, answers, task, classes, level, folds)
        block.update(fold_rule=FOLD_RULE, out_of_fold=table, confidence=trust)
        for line in [f"out of fold ({folds} folds, each answered by a model that never saw it):",
                     *fl.format_table(table, task)]:
            log(line)
    if split:
        from wallcli.train.folds import fit_split

        block["split"] = fit_split(recs, split, split_sim)
    final = replace(cfg, data=list(fold_dirs) + list(sim_data),
                    val_fraction=0.0 if cfg.val is None else cfg.val_fraction)
    return final, block


def judge_out_of_fold(recs, answers, task, classes, level, k) -> tuple[dict, dict]:
    """The out-of-fold table, whose decided answers are judged by thresholds fitted on the other
    folds' answers only, and the thresholds fitted on every fold's (what the card ships)."""
    from wallcli.infer.confidence import judge
    from wallcli.train import folds as fl
    from wallcli.train.recordings import fold_of

    names = [r.name for r in recs]
    probs = np.array([answers[n]["probs"] for n in names])
    labels = np.array([classes.index(fl.truth(r, task)) for r in recs])
    sig = np.array([answers[n]["signal_db"] for n in names])
    fold = np.array([fold_of(n, k) for n in names])
    graded = {}
    for f in range(k):
        o = fold != f
        block = fl.fit_trust(probs[o], labels[o], sig[o], classes, level=level)
        for i in np.flatnonzero(fold == f):
            graded[names[i]] = {"label": classes[int(np.argmax(probs[i]))],
                                "confident": judge(block, probs[i], float(sig[i]), classes)[0]}
    table = fl.oof_table(recs, graded, task, classes)
    table["decided_by"] = ("thresholds fitted on the other folds' out-of-fold answers (each fold's decisions are "
                           "judged on answers their thresholds never saw)")
    return table, fl.fit_trust(probs, labels, sig, classes, level=level)


def write_block(out: Path, block: dict[str, Any]) -> dict[str, Any]:
    """The card of ``out`` with ``recordings`` and, from its folds, the ``confidence`` thresholds."""
    from wallcli.infer.card import card_path, card_text, read_card
    from wallcli.io.writer import write_text_atomic

    card = read_card(out)
    block = dict(block)
    trust = block.pop("confidence", None)
    if "split" in block:
        card["split"] = block.pop("split")
    card["recordings"] = block
    if block.get("out_of_fold"):
        old = card.get("transfer")
        if isinstance(old, dict) and not old.get("out_of_fold"):
            # figures measured on clips that are now training data: kept, named for what they were
            card["transfer_before_recordings"] = dict(old, note="measured before these clips were trained on; "
                                                                "superseded by the out-of-fold figures")
        card["transfer"] = transfer_block(block, card)
    if trust is not None:
        if isinstance(card.get("two_stage"), dict):
            # a two-stage count's answers, which the thresholds were fitted on, are judged by the pair's
            # block; the count net alone has no answers on the recordings to back a threshold
            card["two_stage"]["confidence"] = trust
            card.pop("confidence", None)
        else:
            card["confidence"] = trust
    write_text_atomic(card_path(out), card_text(card), force=True)
    return read_card(out)


def keep_init(init: Path, out: Path, block: dict[str, Any], *, name, version, force: bool) -> dict[str, Any]:
    """``--epochs 0``: OUT is --init's graph, byte for byte, with a card that says so and carries
    what was fitted on the recordings."""
    from wallcli.infer.card import card_path, card_text, read_card
    from wallcli.io.writer import atomic_path, write_text_atomic

    card = read_card(init)
    base = {"name": card.get("name"), "version": card.get("version"), "sha256": card["sha256"]}
    with atomic_path(out, force=force) as tmp:
        tmp.write_bytes(Path(init).read_bytes())
    if isinstance(card.get("onnx"), dict):
        card["onnx"]["file"] = out.name
    card["name"], card["version"] = name or card.get("name"), version
    fitted = [k for k in ("split",) if k in block] + (["confidence"] if block.get("folds") else [])
    card.setdefault("training", {})["recordings_stage"] = {
        "init": base, "note": "the net is --init's, unchanged; fitted on the recordings: " + ", ".join(fitted)}
    write_text_atomic(card_path(out), card_text(card), force=force)
    return write_block(out, block)


def transfer_block(block: dict[str, Any], card: dict[str, Any]) -> dict[str, Any]:
    """The card's headline figures (what ``-v`` and the report quote) from the out-of-fold table."""
    det = block["out_of_fold"]["detectable"]
    n = det["clips"]
    out = {"description": (f"independent path-traced transfer set, {block['clips']} labelled rendered recordings of "
                           "other rooms, "
                           f"out of fold ({block['folds']} folds: each clip answered by a model fitted without it); the "
                           f"headline figures on the {n} where the people are above the camera's noise or the room is empty"),
           "out_of_fold": True, "clips": block["clips"], "scored": n, "errors": 0,
           "accuracy": det["accuracy"], "ci95": det["ci95"], "decided": det["decided"],
           "coverage": round(det["decided"] / n, 4) if n else None,
           "accuracy_decided": round(det["decided_right"] / det["decided"], 4) if det["decided"] else None,
           "classes": card.get("classes"), "confusion": det["confusion_matrix"],
           "by_band": block["out_of_fold"]["by_band"]}
    old = card.get("transfer") if isinstance(card.get("transfer"), dict) else {}
    if old.get("stages"):
        out["stages"] = old["stages"]
    return out
