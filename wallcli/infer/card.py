"""Model cards: the JSON file beside every .onnx model (same name, suffix .json).

The card is the model's contract with inference: which task and classes, which inputs in
which layout, which preprocessing, the canonical frame rate and window, and the sha256 of
the .onnx file it describes.  Written by ``wallcli.train.export``, read and enforced by
``wallcli.infer.model``.  No torch and no onnxruntime here.
"""
from __future__ import annotations

import hashlib
import json
from pathlib import Path
from typing import Any

from wallcli.errors import WallcliError
from wallcli.signal.window import NORMALIZATION, NORMALIZATION_TEXT

CARD_FORMAT = "wallcli.model-card"
CARD_VERSION = 1
# Name and version of the preprocessing that training and inference apply by default (defined
# beside normalize_window, so a change there changes what cards must say); a card names its own.
PREPROCESSING = NORMALIZATION
INPUT_LAYOUT = "NCHW"
INPUT_AXES = ["batch", "channel", "space", "time"]
OUTPUT_NAME = "probabilities"
TASK_INPUTS = {"count": ["horizontal"], "activity": ["horizontal", "vertical"]}  # the seed's nets
# what a model of each task may read ('lite' nets read both plots for count too)
ALLOWED_INPUTS = {"count": (["horizontal"], ["horizontal", "vertical"]), "activity": (["horizontal", "vertical"],)}
TASK_CLASSES: dict[str, list[Any]] = {
    "count": [0, 1, 2],
    "activity": ["none", "walking", "crouching", "waving", "jumping"],
}
REQUIRED = ("name", "version", "task", "classes", "inputs", "output", "preprocessing",
            "fps", "window", "bins", "stride", "sha256")


def card_path(model_path: Path) -> Path:
    return Path(model_path).with_suffix(".json")


def sha256_bytes(data: bytes) -> str:
    return hashlib.sha256(data).hexdigest()


def sha256_file(path: Path) -> str:
    h = hashlib.sha256()
    with open(path, "rb") as f:
        for chunk in iter(lambda: f.read(1 << 20), b""):
            h.update(chunk)
    return h.hexdigest()


def input_spec(name: str, bins: int, window: int) -> dict[str, Any]:
    return {"name": name, "plot": name, "layout": INPUT_LAYOUT, "axes": INPUT_AXES,
            "shape": [None, 3, bins, window], "dtype": "float32"}


def read_card(model_path: Path) -> dict[str, Any]:
    """Read and validate the card beside ``model_path``; WallcliError when absent or wrong."""
    path = card_path(model_path)
    if not path.is_file():
        raise WallcliError(f"model card not found: {path}",
                           hint="a model needs its card beside it: same name, suffix .json")
    try:
        card = json.loads(path.read_text(encoding="utf-8"))
    except (OSError, UnicodeDecodeError, json.JSONDecodeError) as e:
        raise WallcliError(f"model card {path} is not valid JSON: {e}") from None
    validate_card(card, path)
    return card


def validate_card(card: Any, where: Path | str = "model card") -> None:
    def bad(msg: str) -> WallcliError:
        return WallcliError(f"{where}: {msg}")

    if not isinstance(card, dict) or card.get("format") != CARD_FORMAT:
        raise bad(f"not a wallcli model card (format must be {CARD_FORMAT!r})")
    if card.get("card_version") != CARD_VERSION:
        raise bad(f"unsupported card_version {card.get('card_version')!r} (this wallcli reads {CARD_VERSION})")
    missing = [k for k in REQUIRED if k not in card]
    if missing:
        raise bad(f"missing field(s): {', '.join(missing)}")
    task = card["task"]
    if task not in TASK_INPUTS:
        raise bad(f"unknown task {task!r}")
    if card["preprocessing"] not in NORMALIZATION_TEXT:
        raise bad(f"unsupported preprocessing {card['preprocessing']!r} (this wallcli applies "
                  f"{' or '.join(repr(k) for k in NORMALIZATION_TEXT)})")
    if not isinstance(card["classes"], list) or len(card["classes"]) < 2:
        raise bad("classes must be a list of at least 2 labels")
    names = [i.get("name") for i in card["inputs"] if isinstance(i, dict)]
    if names not in [list(a) for a in ALLOWED_INPUTS[task]]:
        raise bad(f"a {task} model takes inputs {' or '.join(map(str, ALLOWED_INPUTS[task]))}, card lists {names}")
    for spec in card["inputs"]:
        if spec.get("layout") != INPUT_LAYOUT:
            raise bad(f"input {spec['name']!r} layout must be {INPUT_LAYOUT}")
        if list(spec.get("shape", []))[1:] != [3, card["bins"], card["window"]]:
            raise bad(f"input {spec['name']!r} shape {spec.get('shape')} does not match bins/window")
    for key in ("window", "bins", "stride"):
        if not isinstance(card[key], int) or card[key] < 1:
            raise bad(f"{key} must be a positive integer")
    if not isinstance(card["sha256"], str) or len(card["sha256"]) != 64:
        raise bad("sha256 must be 64 hex digits")
    if card.get("confidence") is not None:
        from wallcli.infer.confidence import validate_block

        msg = validate_block(card["confidence"], len(card["classes"]))
        if msg:
            raise bad(msg)


def write_card(path: Path, card: dict[str, Any]) -> None:
    """Write ``card`` as JSON to ``path`` (the caller handles atomicity)."""
    validate_card(card, path)
    Path(path).write_text(json.dumps(card, indent=2) + "\n", encoding="utf-8")
