"""Give a retrained count net the shipped count card's two-stage rule, so it is compared with the
shipped model as users meet it (presence from the count and activity nets together, how many from
the count net with the shipped prior), not as a bare net.

    python research/render/two_stage_card.py CANDIDATE.onnx [--shipped models/count.json]

Copies ``two_stage`` from the shipped card into the candidate's card beside its .onnx and reseals it
(wallcli/infer/trust.py). The thresholds in it were fitted on the shipped pair's answers: figures
of the candidate are read on every answer (``accuracy``), not on the decided ones.
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
    ap.add_argument("--shipped", type=Path, default=Path(__file__).resolve().parents[2] / "models" / "count.json")
    a = ap.parse_args()
    shipped = json.loads(a.shipped.read_text())
    path = card_path(a.candidate)
    card = json.loads(path.read_text())
    card["two_stage"] = shipped["two_stage"]
    write_text_atomic(path, card_text(card), force=True)
    reseal(path)
    print(f"{path}: two_stage from {a.shipped}, resealed")


if __name__ == "__main__":
    main()
