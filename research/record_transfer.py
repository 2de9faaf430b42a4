"""Record a model's transfer figures (the output of `wallcli evaluate DIR --json`) in its card.

    wallcli evaluate ../shared/transfer --task count --json > runs/transfer_count.json
    python research/record_transfer.py models/count.onnx runs/transfer_count.json [CANDIDATES_COMPARED [SINGLE_STAGE.json]]

The card gains a ``transfer`` block: accuracy with its 95 % interval, coverage and accuracy of the
decided answers, the confusion matrix and per-class figures, the clips right by SNR band
(``by_band``), and the command that measured them.
The .onnx file is not touched (the card's sha256 covers only it); the card is checked to belong
to the model that was measured, and rewritten atomically.
"""
from __future__ import annotations

import json
import sys
from pathlib import Path

from wallcli.infer.card import card_path, read_card, write_card
from wallcli.io.writer import atomic_path

KEYS = ("clips", "scored", "errors", "accuracy", "ci95", "decided", "coverage", "accuracy_decided",
        "ci95_decided", "classes", "confusion", "per_class", "all", "snr_source", "by_band")


def main() -> None:
    if len(sys.argv) not in (3, 4, 5):
        raise SystemExit(__doc__)
    model, result_path = Path(sys.argv[1]), Path(sys.argv[2])
    result = json.loads(result_path.read_text(encoding="utf-8"))
    card = read_card(model)
    if result.get("model", {}).get("sha256") != card["sha256"]:
        raise SystemExit(f"{result_path} measured another model ({result.get('model')}), not {model}")
    # the set by what it is: the folder it sits in here means nothing to a reader of the card
    block = {"description": f"independent path-traced transfer set, {result.get('clips')} clips, the headline figures on "
                            f"the {result.get('scored')} where the people are above the camera's noise or the room is "
                            "empty, the SNR bands on all (not shipped with wallcli)",
             **{k: result[k] for k in KEYS if k in result}}
    block["source"] = ("an independent path-traced renderer (other code, box people, area lights, its own camera "
                       "model), never trained on; since 2026-11-26 the validation set: candidates are compared and "
                       "decided/undetermined thresholds fitted there, and a hidden set of the same kind judges")
    block["command"] = f"wallcli evaluate TRANSFER_DIR --task {result['task']} --json"
    if result.get("stages"):  # count answered in two stages: the figures are the pair's
        block["stages"] = result["stages"]
        block["command"] += " (two-stage count: presence from both nets, then how many)"
    if len(sys.argv) > 3:  # issue 35: how many candidates were compared on this set before this one was chosen
        block["candidates_compared"] = int(sys.argv[3])
    if len(sys.argv) > 4:  # the count net alone on the same set (`--single-stage`), beside the two-stage headline
        alone = json.loads(Path(sys.argv[4]).read_text(encoding="utf-8"))
        if alone.get("stages") or alone.get("model", {}).get("sha256") != card["sha256"]:
            raise SystemExit(f"{sys.argv[4]} is not this count net alone")
        card["transfer_single_stage"] = {k: alone[k] for k in KEYS if k in alone} | {
            "command": "wallcli evaluate TRANSFER_DIR --task count --single-stage --json"}
    card["transfer"] = block
    with atomic_path(card_path(model), force=True) as tmp:
        write_card(tmp, card)
    print(f"{card_path(model)}: transfer accuracy {block['accuracy']:.1%}, "
          f"coverage {block.get('coverage', float('nan')):.0%}, decided right {block.get('accuracy_decided')}")


if __name__ == "__main__":
    main()
