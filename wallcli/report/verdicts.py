"""Clip and window answers as a page states them: the label, or ``undetermined (reason)``.

``confident`` and ``reason`` (docs/contract.md) are read with ``.get``: results written before they
existed carry neither, and then the answer is shown as it is, with its confidence unknown.
"""
from __future__ import annotations

import re
from pathlib import Path
from typing import Any

# FFmpeg's demuxer names as a reader knows the containers
CONTAINERS = {"matroska,webm": "Matroska (MKV/WebM)", "mpegts": "MPEG-TS", "nut": "NUT", "yuv4mpegpipe": "Y4M",
              "avi": "AVI", "flv": "FLV", "image2": "image sequence", "rawvideo": "raw video"}


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


def container_name(fmt: str | None, path: str | None = None) -> str:
    """'MP4' for FFmpeg's 'mov,mp4,m4a,3gp,3g2,mj2' (QuickTime for a .mov), the others by name."""
    if not fmt:
        return "\u2014"
    if "mp4" in fmt.split(","):
        suffix = Path(path or "").suffix.lower()
        return {".mov": "QuickTime (MOV)", ".3gp": "3GP", ".m4v": "MP4"}.get(suffix, "MP4")
    return CONTAINERS.get(fmt, fmt.upper())


def plain_why(reason: str | None, obj: dict[str, Any]) -> str:
    """Why an answer is undetermined, as a reader with no knowledge of the JSON says it; the
    reason itself (confidence.judge's and the view check's wording) stays in the task's section."""
    if not reason:
        return "the model is not confident here"
    if reason.startswith("not a static view"):
        view = obj.get("view") if isinstance(obj.get("view"), dict) else {}
        issues = [str(i) for i in view.get("issues") or []]
        return "the video is not a still view of a wall" + (f" ({', '.join(issues)})" if issues else "")
    m = re.match(r"^(?:no movement above the camera's noise|'.+?' is never decided) \(signal (\S+) dB\)", reason)
    if m:
        return ("nobody moving is never decided, since an empty room and a person too faint to show give "
                f"the same plot (signal {m.group(1)} dB)")
    # confidence.judge's reasons, worded by wallcli.wording (not_often_enough, under_threshold)
    m = re.match(r"^'(.+?)' at signal (\S+) dB: answers like this were not right often enough in validation "
                 r"to be relied on \(([\d.]+ %) needed", reason)
    if m:
        return (f"this model's '{m.group(1)}' answers at a signal like this one ({m.group(2)} dB) were not right "
                f"often enough in validation to be relied on ({m.group(3)} needed)")
    m = re.match(r"^p=(\S+) for '(.+?)' at signal (\S+) dB: answers like this were right ([\d.]+ %) of the time "
                 r"in validation only from p=(\S+)", reason)
    if m:
        return (f"its probability ({float(m.group(1)):.2f}) is under the {float(m.group(5)):.2f} from which "
                f"'{m.group(2)}' answers were right {m.group(4)} of the time in validation")
    if reason.startswith("the model card states no validated"):
        return "the model's card gives no thresholds to decide by"
    return reason


def finding(task: str, obj: Any) -> str:
    """The page's headline for one task, in plain words: 'Count: 1 person (decided; probability
    0.97, signal_db 12.3 dB)' or 'Count: undetermined, most likely 1 person; <why>'."""
    from wallcli.wording import format_db

    name = task.capitalize()
    if not isinstance(obj, dict):
        return f"{name}: no answer"
    a = answer(task, obj)
    signal = obj.get("signal_db")
    # named as count's table heads it: not the headline column SNR, which the page says first
    at = f", signal_db {format_db(signal)} dB" if isinstance(signal, (int, float)) else ""
    p = f"probability {a['p']:.2f}" if a["p"] is not None else "probability unknown"
    if a["confident"] is False:
        return f"{name}: undetermined, most likely {a['label']} ({p}); {plain_why(a['reason'], obj)}"
    how = "decided" if a["confident"] else "confidence not assessed"
    return f"{name}: {a['label']} ({how}; {p}{at})"
