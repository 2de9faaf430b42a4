"""Model cards: the JSON file beside every .onnx model (same name, suffix .json).

The card is the model's contract with inference: which task and classes, which inputs in
which layout, which preprocessing, the canonical frame rate and window, and the sha256 of
the .onnx file it describes.  Written by ``wallcli.train.export``, read and enforced by
``wallcli.infer.model``.  No torch and no onnxruntime here.
"""
from __future__ import annotations

import hashlib
import json
import math
from pathlib import Path
from typing import Any

from wallcli.errors import WallcliError
from wallcli.io import jsonfile
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


# A card is a few tens of kB; anything far larger is not a card (and would be read whole).
MAX_CARD_BYTES = 16 * 1024 * 1024
# Ranges of the numbers inference takes from a card: fps sets the resampling (1e9 fps once
# asked for terabytes), window and bins the shape of every array.
LIMITS = {"fps": (1, 1000), "window": (2, 65536), "bins": (2, 4096), "stride": (1, 65536)}


def read_card(model_path: Path) -> dict[str, Any]:
    """Read and validate the card beside ``model_path``; WallcliError when absent or wrong."""
    path = card_path(model_path)
    if not path.is_file():
        raise WallcliError(f"model card not found: {path}",
                           hint="a model needs its card beside it: same name, suffix .json")
    try:
        if path.stat().st_size > MAX_CARD_BYTES:
            raise WallcliError(f"model card {path} is {path.stat().st_size} bytes; a card is a small JSON file")
        card = jsonfile.loads(path.read_text(encoding="utf-8"))
    except (OSError, UnicodeDecodeError, ValueError) as e:
        raise WallcliError(f"model card {path} is not valid JSON: {e}") from None
    validate_card(card, path)
    return card


def _is_number(x: Any) -> bool:
    return isinstance(x, (int, float)) and not isinstance(x, bool) and math.isfinite(x)


def _is_int(x: Any) -> bool:
    return isinstance(x, int) and not isinstance(x, bool)


def validate_card(card: Any, where: Path | str = "model card") -> None:
    """Every field inference reads, by type and range, each failure naming its field. Fields it
    does not read (training history, notes, blocks added by newer model owners) are left alone."""
    def bad(msg: str) -> WallcliError:
        return WallcliError(f"{where}: {msg}")

    if not isinstance(card, dict) or card.get("format") != CARD_FORMAT:
        raise bad(f"not a wallcli model card (format must be {CARD_FORMAT!r})")
    if card.get("card_version") != CARD_VERSION:
        raise bad(f"unsupported card_version {card.get('card_version')!r} (this wallcli reads {CARD_VERSION})")
    missing = [k for k in REQUIRED if k not in card]
    if missing:
        raise bad(f"missing field(s): {', '.join(missing)}")
    for key in ("name", "version"):
        if not isinstance(card[key], str) or not card[key].strip() or len(card[key]) > 200:
            raise bad(f"field {key!r} must be a non-empty string of at most 200 characters (got {card[key]!r:.60})")
    task = card["task"]
    if not isinstance(task, str) or task not in TASK_INPUTS:
        raise bad(f"field 'task' must be one of {', '.join(TASK_INPUTS)} (got {task!r:.60})")
    if not isinstance(card["preprocessing"], str) or card["preprocessing"] not in NORMALIZATION_TEXT:
        raise bad(f"unsupported preprocessing {card['preprocessing']!r:.80} (this wallcli applies "
                  f"{' or '.join(repr(k) for k in NORMALIZATION_TEXT)})")
    fps = card["fps"]
    lo, hi = LIMITS["fps"]
    if not _is_number(fps) or not lo <= fps <= hi:
        raise bad(f"field 'fps' must be a number from {lo} to {hi} (got {fps!r:.60})")
    for key in ("window", "bins", "stride"):
        lo, hi = LIMITS[key]
        if not _is_int(card[key]) or not lo <= card[key] <= hi:
            raise bad(f"field {key!r} must be an integer from {lo} to {hi} (got {card[key]!r:.60})")
    classes = card["classes"]
    if (not isinstance(classes, list) or not 2 <= len(classes) <= 1000
            or not all((isinstance(c, str) and c) or _is_int(c) for c in classes)):
        raise bad("field 'classes' must be a list of 2 to 1000 labels (integers or non-empty strings)")
    if len({repr(c) for c in classes}) != len(classes):
        raise bad(f"field 'classes' lists a label twice: {classes}")
    if classes != TASK_CLASSES[task]:
        # the answers' words (count's number of people, activity's names), which the two-stage
        # count, the reports and the truth files compare by value
        raise bad(f"a {task} model's classes are {TASK_CLASSES[task]} (card lists {classes!r:.80})")
    inputs = card["inputs"]
    if not isinstance(inputs, list) or not all(isinstance(i, dict) for i in inputs):
        raise bad("field 'inputs' must be a list of objects")
    names = [i.get("name") for i in inputs]
    if names not in [list(a) for a in ALLOWED_INPUTS[task]]:
        raise bad(f"a {task} model takes inputs {' or '.join(map(str, ALLOWED_INPUTS[task]))}, card lists {names}")
    for spec in inputs:
        if spec.get("layout") != INPUT_LAYOUT:
            raise bad(f"input {spec['name']!r} layout must be {INPUT_LAYOUT}")
        shape = spec.get("shape")
        if (not isinstance(shape, list) or len(shape) != 4 or not (shape[0] is None or _is_int(shape[0]))
                or shape[1:] != [3, card["bins"], card["window"]]):
            raise bad(f"input {spec['name']!r} shape {shape!r:.80} does not match bins/window "
                      f"([null, 3, {card['bins']}, {card['window']}])")
        if spec.get("dtype", "float32") != "float32":
            raise bad(f"input {spec['name']!r} dtype must be float32 (got {spec.get('dtype')!r:.40})")
    output = card["output"]
    if not isinstance(output, dict) or output.get("name", OUTPUT_NAME) != OUTPUT_NAME:
        raise bad(f"field 'output' must be an object naming the output {OUTPUT_NAME!r}")
    sha = card["sha256"]
    if not isinstance(sha, str) or len(sha) != 64 or any(c not in "0123456789abcdefABCDEF" for c in sha):
        raise bad("field 'sha256' must be 64 hex digits")
    _validate_accuracy(card.get("validation"), "validation", bad)
    if card.get("confidence") is not None:
        from wallcli.infer.confidence import validate_block

        msg = validate_block(card["confidence"], len(card["classes"]))
        if msg:
            raise bad(msg)
    if card.get("two_stage") is not None:
        _validate_two_stage(card["two_stage"], len(card["classes"]), bad)


# the prior odds of two people against one that a two-stage count weighs p(2) by: a share of
# two-person rooms from 1 in 1000 to 999 in 1000 (1e308 made every answer two, -1 became 1 unsaid)
PRIOR_ODDS = (1e-3, 1e3)


def _validate_two_stage(block: Any, n_classes: int, bad) -> None:
    """The two-stage count's block of a count card (see infer.twostage), as that reads it."""
    from wallcli.infer.confidence import validate_block

    if not isinstance(block, dict):
        raise bad("field 'two_stage' must be an object")
    pair = block.get("activity_model")
    if pair is not None and not (isinstance(pair, dict) and isinstance(pair.get("sha256", ""), str)):
        raise bad("field 'two_stage.activity_model' must be an object with the activity model's sha256")
    if block.get("confidence") is not None:
        msg = validate_block(block["confidence"], n_classes)
        if msg:
            raise bad("two_stage." + msg)
    odds = block.get("prior_two_vs_one")
    lo, hi = PRIOR_ODDS
    if odds is not None and not (_is_number(odds) and lo <= odds <= hi):
        raise bad(f"field 'two_stage.prior_two_vs_one' must be a number from {lo:g} to {hi:g} (got {odds!r:.40})")


def _validate_accuracy(block: Any, name: str, bad) -> None:
    """The validation figures the commands print under their tables (see cli._classify)."""
    if block is None:
        return
    if not isinstance(block, dict):
        raise bad(f"field {name!r} must be an object")
    if "accuracy" in block and not (_is_number(block["accuracy"]) and 0 <= block["accuracy"] <= 1):
        raise bad(f"field '{name}.accuracy' must be a number from 0 to 1 (got {block['accuracy']!r:.40})")
    ci = block.get("accuracy_95ci")
    if ci is not None and not (isinstance(ci, list) and len(ci) == 2
                               and all(_is_number(x) and 0 <= x <= 1 for x in ci)):
        raise bad(f"field '{name}.accuracy_95ci' must be two numbers from 0 to 1 (got {ci!r:.60})")
    if "min_snr_db" in block and not _is_number(block["min_snr_db"]):
        raise bad(f"field '{name}.min_snr_db' must be a number (got {block['min_snr_db']!r:.40})")
    if "visible" in block:
        _validate_accuracy(block["visible"], f"{name}.visible", bad)
    others = block.get("other_sets")
    if others is not None:
        if not isinstance(others, list):
            raise bad(f"field '{name}.other_sets' must be a list")
        for i, other in enumerate(others):
            _validate_accuracy(other, f"{name}.other_sets[{i}]", bad)


def card_text(card: dict[str, Any]) -> str:
    """``card`` as the JSON text wallcli writes: sealed (its ``trust`` block set to the digest of
    the fields it was just given, :mod:`wallcli.infer.trust`), since whoever writes a card through
    here has just measured them."""
    from wallcli.infer.trust import seal

    return json.dumps(seal(card), indent=2) + "\n"


def write_card(path: Path, card: dict[str, Any]) -> None:
    """Write ``card``, sealed, as JSON to ``path`` (the caller handles atomicity)."""
    validate_card(card, path)
    Path(path).write_text(card_text(card), encoding="utf-8")
