"""Give a retrained net the shipped card's rules, so it is compared with the shipped model as users
meet it, not as a bare net: count's two-stage rule (presence from the count and activity nets
together, how many from the count net with the shipped prior), activity's waving/jumping split
(a logistic regression on the plots' physical features, fitted on the recordings).

    python research/render/two_stage_card.py CANDIDATE.onnx [--shipped models/count.json]

Copies ``two_stage`` (count) or ``split`` (activity) from the shipped card of the candidate's task
into the candidate's card beside its .onnx and reseals it (wallcli/infer/trust.py). The thresholds
in them were fitted on the shipped models' answers: figures of the candidate are read on every
answer (``accuracy``), not on the decided ones.
"""
from __future__ import annotations

import argparse
import json
from pathlib import Path

from wallcli.infer.card import card_path, card_text
from wallcli.infer.trust import reseal
from wallcli.io.writer import write_text_atomic


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("candidate", type=Path)
    ap.add_argument("--shipped", type=Path, help="the shipped card (default: models/TASK.json)")
    a = ap.parse_args()
    path = card_path(a.candidate)
    card = json.loads(path.read_text())
    shipped_path = a.shipped or Path(__file__).resolve().parents[2] / "models" / f"{card['task']}.json"
    shipped = json.loads(shipped_path.read_text())
    field = "two_stage" if card["task"] == "count" else "split"
    card[field] = shipped[field]
    write_text_atomic(path, card_text(card), force=True)
    reseal(path)
    print(f"{path}: {field} from {shipped_path}, resealed")


if __name__ == "__main__":
    main()
