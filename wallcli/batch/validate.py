"""What a line of scan's results may hold: one check, run by a resume and by ``wallcli report``.

Both read lines that a person may have edited or another program written. A line scan could not
have written (a duration of -1e308, NaN probabilities, a task's object replaced by null) is
refused by both with the same words ("not a wallcli scan result") instead of being resumed as
an answer or shown on a page as one. Fields scan does not write are left alone (fields may be
added), and so are the older lines that lack "tasks" or "options".
"""
from __future__ import annotations

import math
import re
from typing import Any

TASK_NAMES = ("count", "activity", "snr")
CLASSIFY = ("count", "activity")
# longer than any recording (about 32 years), far below the values an edit makes impossible
MAX_SECONDS = 1e9
_SHA256 = re.compile(r"[0-9a-fA-F]{64}\Z")
_TOLERANCE = 1e-3  # probabilities are float32 softmax outputs, rounded by nobody


def _is_number(x: Any) -> bool:
    return isinstance(x, (int, float)) and not isinstance(x, bool)


def _non_finite(obj: Any) -> bool:
    """Is a NaN or an infinity anywhere in ``obj``? Scan writes those as null (its JSON is strict)."""
    stack = [obj]
    while stack:  # iterative: the parser already bounds the depth, this walk must not recurse either
        o = stack.pop()
        if isinstance(o, float) and not math.isfinite(o):
            return True
        if isinstance(o, dict):
            stack.extend(o.values())
        elif isinstance(o, list):
            stack.extend(o)
    return False


def _count(d: dict, k: str) -> str | None:
    v = d.get(k)
    if v is not None and not (isinstance(v, int) and not isinstance(v, bool) and v >= 0):
        return f'"{k}" is {v!r}, not a count'
    return None


def _seconds(d: dict, k: str) -> str | None:
    v = d.get(k)
    if v is not None and not (_is_number(v) and 0 <= v <= MAX_SECONDS):
        return f'"{k}" is {v!r}, not a number of seconds'
    return None


def _answer(task: str, obj: dict) -> str | None:
    probs = obj.get("probabilities")
    if probs is not None:
        if not isinstance(probs, list) or not all(_is_number(p) and -_TOLERANCE <= p <= 1 + _TOLERANCE
                                                   for p in probs):
            return f'"{task}.probabilities" is not a list of probabilities'
        if probs and abs(sum(probs) - 1.0) > 0.01:
            return f'"{task}.probabilities" sum to {sum(probs):.4g}, not 1'
    classes = obj.get("classes")
    if isinstance(classes, list) and "label" in obj and obj["label"] not in classes:
        return f'"{task}.label" {obj["label"]!r} is not one of its classes'
    if obj.get("confident") is not None and not isinstance(obj["confident"], bool):
        return f'"{task}.confident" is {obj["confident"]!r}, not true or false'
    if obj.get("signal_db") is not None and not _is_number(obj["signal_db"]):
        return f'"{task}.signal_db" is {obj["signal_db"]!r}, not a number'
    return None


def _snr(obj: dict) -> str | None:
    for k in ("snr_db", "signal_power", "noise_power"):
        v = obj.get(k)
        if v is not None and not (isinstance(v, list) and all(x is None or _is_number(x) for x in v)):
            return f'"snr.{k}" is not a list of numbers'
    if any(_is_number(x) and x < 0 for x in obj.get("noise_power") or []):
        return '"snr.noise_power" holds a negative power'
    why = _count(obj, "frames")
    return f"snr: {why}" if why else None


def line_problem(d: Any) -> str | None:
    """Why ``d`` (a parsed results line) cannot be a line that scan wrote; None if it can be."""
    if not isinstance(d, dict):
        return "not a JSON object"
    if not isinstance(d.get("input"), str) or not d["input"]:
        return 'no "input" named'
    if _non_finite(d):
        return "a number that is NaN or infinite (scan writes null)"
    for why in (_count(d, "size"), _count(d, "frames"), _seconds(d, "duration"), _seconds(d, "seconds")):
        if why:
            return why
    sha = d.get("sha256")
    if sha is not None and not (isinstance(sha, str) and _SHA256.match(sha)):
        return '"sha256" is not 64 hexadecimal digits'
    if d.get("error") is not None and not isinstance(d["error"], str):
        return '"error" is neither null nor a message'
    tasks = d.get("tasks")
    if tasks is not None and not (isinstance(tasks, list) and all(t in TASK_NAMES for t in tasks)):
        return f'"tasks" is {tasks!r}, not a list of {", ".join(TASK_NAMES)}'
    if d.get("view") is not None and not isinstance(d["view"], dict):
        return '"view" is not an object'
    for task in TASK_NAMES:
        if task in d:
            obj = d[task]
            if not isinstance(obj, dict):
                return f'"{task}" is {"null" if obj is None else type(obj).__name__}, not its analysis'
            why = _answer(task, obj) if task in CLASSIFY else _snr(obj)
            if why:
                return why
    return None
