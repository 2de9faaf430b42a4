"""What a report says about a model, read from its card (the card is the only source of figures).

Cards written by older or newer wallcli versions differ in what they carry, so every field is
read with ``.get`` and a missing figure is reported as missing, never invented.
"""
from __future__ import annotations

from pathlib import Path
from typing import Any

# What the shipped models learnt from, as the report's Limits and docs/adapt.md say it (models/README.md);
# a model of the user's own learnt from what its card names, which may be camera footage
LEARNT = ("It learnt from simulated rooms and from labelled rendered clips of other rooms (an independent "
          "renderer's), never from camera footage; a room unlike them (other lights, other walls, a real "
          "camera) can mislead it.")
LEARNT_OWN = ("It learnt from what its card's training_data and recordings name; a room unlike those can "
              "mislead it.")

# Said of every shipped model of the task; a card's own "limitations" are listed after these.
LIMITS = {
    "count": [
        "It counts people who move: 0, 1 or 2. It cannot count more than two, and it cannot tell who they are.",
        "One against two people is its weakest distinction: two people are often counted as one.",
        "A faint or distant mover (beyond about 3.5 m from the wall, or under heavy video compression) reads as nobody.",
        "A person standing still may be counted when their sway shows on the wall.",
    ],
    "activity": [
        "It names one activity of one person: none, walking, crouching, waving or jumping; anything else is "
        "forced into one of these.",
        "With two or more people its answer is not defined (it learnt from scenes of at most one person).",
        "A faint or distant mover reads as 'none'.",
    ],
}


def _num(x) -> float | None:
    return float(x) if isinstance(x, (int, float)) and not isinstance(x, bool) else None


def _ci(x) -> list[float] | None:
    if isinstance(x, (list, tuple)) and len(x) == 2 and all(_num(v) is not None for v in x):
        return [float(x[0]), float(x[1])]
    return None


def _figure(block: dict, name: str) -> dict[str, Any]:
    """Accuracy on one simulated validation set: visible windows and all windows."""
    vis = block.get("visible") if isinstance(block.get("visible"), dict) else {}
    return {
        "set": name,
        "windows": block.get("windows"),
        "accuracy": _num(block.get("accuracy")), "ci": _ci(block.get("accuracy_95ci")),
        "visible_accuracy": _num(vis.get("accuracy")), "visible_ci": _ci(vis.get("accuracy_95ci")),
        "visible_windows": vis.get("windows"), "min_snr_db": _num(vis.get("min_snr_db")),
    }


def set_name(block: dict, fallback: str) -> str:
    """A data set as a reader knows it: the card's description, else what its recipe says (domain,
    windows), never the folder it sat in on the machine that trained the model."""
    if isinstance(block.get("description"), str) and block["description"].strip():
        return block["description"]
    recipe = block.get("recipe") if isinstance(block.get("recipe"), dict) else {}
    domain, windows = recipe.get("domain"), block.get("windows") or recipe.get("windows")
    if isinstance(domain, str) and isinstance(windows, int) and not isinstance(windows, bool):
        return f"{fallback}: {domain} rooms, {windows:,} windows"
    return fallback


_TRANSFER_KNOWN = ("dir", "dataset", "set", "description", "accuracy", "ci95", "accuracy_95ci", "clips", "scored", "coverage",
                   "accuracy_decided", "decided", "command", "note")


# a card's own field names, as a page says them: (label, {value: words})
_OTHER_WORDS = {
    "errors": ("clips that failed", {}),
    "snr_source": ("clips put in SNR bands by", {"labels": "the SNR their labels give",
                                                 "measured": "the SNR wallcli measured"}),
    "source": ("clips made by", {}),
}
_FIELD_WORDS = {"by_band": "the SNR bands", "snr_source": "the SNR source"}


def _no_field_names(text: str) -> str:
    """A card's description with the JSON field names it cites said in words."""
    for field, words in _FIELD_WORDS.items():
        text = text.replace(field, words)
    return text


def _transfer(block: Any) -> list[dict[str, Any]] | None:
    """The card's "transfer" figures (accuracy on an independent renderer's clips), one or a list."""
    if block is None:
        return None
    out = []
    for b in block if isinstance(block, list) else [block]:
        if not isinstance(b, dict):
            continue
        # figures this page does not know by name are still shown, named in words
        other = {}
        for k, v in b.items():
            if k in _TRANSFER_KNOWN or not isinstance(v, (str, int, float, bool)):
                continue
            if k == "errors" and v == 0:  # 'errors: 0' says nothing a reader needs
                continue
            words = _OTHER_WORDS.get(k)
            if words is None:
                other[str(k).replace("_", " ")] = v
            else:
                other[words[0]] = words[1].get(v, v) if isinstance(v, str) else v
        out.append({
            "set": _no_field_names(set_name(b, "transfer set")),
            "accuracy": _num(b.get("accuracy")), "ci": _ci(b.get("ci95") or b.get("accuracy_95ci")),
            "clips": b.get("scored") if b.get("scored") is not None else b.get("clips"),
            "coverage": _num(b.get("coverage")), "accuracy_decided": _num(b.get("accuracy_decided")),
            # a command naming a folder of the card's author would point the reader at nothing
            "command": b.get("command") if isinstance(b.get("command"), str) and not b.get("dir") else None,
            "note": b.get("note") if isinstance(b.get("note"), str) else None,
            "other": other,
        })
    return out


def _shipped(model) -> bool:
    from wallcli.infer.model import shipped_model_path

    try:
        return Path(model.path).resolve() == shipped_model_path(model.task).resolve()
    except (KeyError, OSError):  # a task without a shipped model, or a path that cannot be resolved
        return False


def model_summary(model) -> dict[str, Any]:
    card = model.card
    v = card.get("validation") if isinstance(card.get("validation"), dict) else {}
    source = v.get("source") if isinstance(v.get("source"), dict) else {}
    sets = []
    if v:
        sets.append(_figure(v, set_name({**source, "windows": v.get("windows")}, "simulated validation set")))
        for o in v.get("other_sets") or []:
            if isinstance(o, dict):
                sets.append(_figure(o, set_name(o, "another simulated validation set")))
    by_snr = []
    for row in v.get("accuracy_by_snr") or []:
        if isinstance(row, dict) and isinstance(row.get("snr_db"), list) and len(row["snr_db"]) == 2:
            by_snr.append({"lo": _num(row["snr_db"][0]), "hi": _num(row["snr_db"][1]),
                           "windows": row.get("windows"), "accuracy": _num(row.get("accuracy"))})
    own = card.get("limitations")
    own = [own] if isinstance(own, str) else [str(x) for x in own] if isinstance(own, list) else []
    onnx = card.get("onnx") if isinstance(card.get("onnx"), dict) else {}
    unvalidated = getattr(model, "unvalidated", None)
    if unvalidated:  # an edited card's figures are not the measured ones: none are shown (infer/trust.py)
        sets, by_snr = [], []
    first = [f"{unvalidated[:1].upper()}{unvalidated[1:]}: its validation figures are not shown and no answer "
             "is decided."] if unvalidated else []
    return {
        "task": model.task, "name": card.get("name"), "version": card.get("version"), "sha256": card.get("sha256"),
        "path": str(model.path), "precision": onnx.get("precision"), "created": card.get("created"),
        "classes": [str(c) for c in model.classes], "window_s": model.window / model.fps,
        "simulated": [s for s in sets if s["accuracy"] is not None or s["visible_accuracy"] is not None],
        "by_snr": by_snr,
        "transfer": None if unvalidated else _transfer(card.get("transfer")),
        "limits": first + LIMITS.get(model.task, []) + [LEARNT if _shipped(model) else LEARNT_OWN] + own,
    }
