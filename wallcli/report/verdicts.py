"""Clip and window answers as a page states them: the label, or ``undetermined (reason)``.

``confident`` and ``reason`` (docs/contract.md) are read with ``.get``: results written before they
existed carry neither, and then the answer is shown as it is, with its confidence unknown.
"""
from __future__ import annotations

from typing import Any


def label_text(task: str | None, label: Any) -> str:
    from wallcli.wording import label_text as words

    return words(label) if task == "count" else str(label)


def answer(task: str | None, obj: Any) -> dict[str, Any]:
    """A result (clip-level or window object) -> {text, label, p, confident, reason, decided}."""
    if not isinstance(obj, dict):
        return {"text": "—", "label": None, "p": None, "confident": None, "reason": None, "decided": False}
    probs = obj.get("probabilities")
    p = max(probs) if isinstance(probs, list) and probs and all(isinstance(x, (int, float)) for x in probs) else None
    confident = obj.get("confident")
    confident = confident if isinstance(confident, bool) else None
    reason = obj.get("reason") if isinstance(obj.get("reason"), str) else None
    label = label_text(task, obj.get("label"))
    if confident is False:
        text = f"undetermined ({reason or 'the model is not confident here'})"
    else:
        text = label
    return {"text": text, "label": label, "p": p, "confident": confident, "reason": reason,
            "decided": confident is not False}
