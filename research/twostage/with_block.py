"""Give a candidate count model's card the shipped card's two_stage block (the rule, the prior odds
of two people against one, which come from the transfer set's labels and not from any model's
answers), without its confidence thresholds: those were fitted for the shipped pair and do not
carry over (twostage.TwoStageCount then decides nothing, as for any uncalibrated pair).

    python research/twostage/with_block.py runs/c_pt.json [models/count.json]
"""
import json
import sys
from pathlib import Path

cand = Path(sys.argv[1])
ref = Path(sys.argv[2] if len(sys.argv) > 2 else "models/count.json")
card = json.loads(cand.read_text())
block = dict(json.loads(ref.read_text())["two_stage"])
block.pop("confidence", None)
block["activity_model"] = {}
card["two_stage"] = block
cand.write_text(json.dumps(card, indent=1))
print(f"{cand}: two_stage block from {ref}, prior_two_vs_one {block.get('prior_two_vs_one')}")
