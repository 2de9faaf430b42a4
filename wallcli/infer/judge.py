"""The judge stage: may an answer be relied upon? The model card's validated accuracy at this
probability and signal (:mod:`wallcli.infer.confidence`), the two-people gate of an activity
answer, and the view check's verdict, each able to leave an answer undetermined, with its reason."""
from __future__ import annotations

from typing import Any

import numpy as np

from wallcli.infer import confidence


def judge_answer(model, raw, probs: np.ndarray, signal_db: float) -> tuple[bool, str | None]:
    """(confident, reason) of the answer ``probs`` that ``model`` made of its nets' ``raw`` output."""
    return _gate(model, raw, probs, *_judge(model, probs, signal_db))


def _judge(model, probs: np.ndarray, signal_db: float) -> tuple[bool, str | None]:
    if getattr(model, "unvalidated", None):  # its thresholds are not the ones measured: none are quoted
        return False, model.unvalidated
    block = model.card.get("confidence")
    confident, reason = confidence.judge(block, probs, signal_db, model.classes)
    if not block and model.no_block_reason():
        reason = model.no_block_reason()
    return confident, reason


def _gate(model, raw, probs, confident: bool, reason):
    """An activity answer where two people may be moving is not decided, whatever the net says
    (:class:`wallcli.infer.twostage.OnePersonActivity`). Its reason is the one that decided: the
    two-people check's where the card's thresholds would have decided the answer; else theirs,
    with the check after it (a one-person clip read "two people possible (p=0.05 ...)" alone,
    while no band has a threshold and nothing would have been decided anyway)."""
    if not hasattr(model, "gate"):
        return confident, reason
    p_two, why = model.gate(raw, model.classes[int(np.argmax(probs))])
    if not why:
        return confident, reason
    if confident:
        return False, why
    from wallcli.infer.twostage import two_people_aside

    return False, f"{reason}; {two_people_aside(p_two)}"


def judge_view(rec: dict[str, Any], view: dict) -> dict[str, Any]:
    """``rec`` (a window or clip answer) with ``view``: where the view is not a static wall, the
    answer cannot be relied upon whatever the model says, and the view's reason replaces the model's."""
    rec["view"] = view
    if not view["usable"]:
        rec["confident"], rec["reason"] = False, view["reason"]
    return rec


def with_view(result: dict[str, Any], check) -> dict[str, Any]:
    """``result`` with the verdict of the view check (:class:`wallcli.view.check.ViewCheck`, fed
    the same decode) on each window and on the clip."""
    for w in result.get("windows", []):
        judge_view(w, check.view(w["start"], w["end"]))
    return judge_view(result, check.summary())
