"""Install the cards written by `wallcli train ... --clips ../shared/transfer --folds 5 --epochs 0` as the
shipped ones (the .onnx files are unchanged: --epochs 0 keeps the nets' bytes), naming the files as shipped
and saying how many candidates were compared out of fold (research/recordings/README.md)."""
import json
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]
CANDIDATES = {"count": 26, "activity": 25}  # counted in research/recordings/README.md

for task, src in (("count", "runs/cand/count-keep.json"), ("activity", "runs/cand/activity-split.json")):
    card = json.loads((ROOT / src).read_text())
    shipped = ROOT / "models" / f"{task}.onnx"
    import hashlib
    assert hashlib.sha256(shipped.read_bytes()).hexdigest() == card["sha256"], f"{task}: not the shipped graph"
    card["onnx"]["file"] = f"{task}.onnx"
    card["recordings"]["folders"] = ["the recordings (../shared/transfer in the repository's workspace)"]
    card["recordings"]["candidates_compared"] = {
        "count": CANDIDATES[task], "where": "research/recordings/README.md",
        "rule": "shipped only when paired against the previous model on the same clips: exact McNemar p <= 0.1, "
                "no band down by 2 or more"}
    if task == "activity":  # what the split does on the simulator's windows (sim_split.py)
        card["validation_with_split"] = json.loads((ROOT / "runs" / "sim_split.json").read_text())
    if task == "count":
        act = json.loads((ROOT / "runs/cand/activity-split.json").read_text())
        card["two_stage"]["activity_model"].update(name=act["name"], version=act["version"])
        card["transfer"]["stages"] = {"activity_model": {"name": act["name"], "version": act["version"],
                                                         "sha256": act["sha256"]}}
    from wallcli.infer.card import card_text  # sealed: these figures are the measured ones

    (ROOT / "models" / f"{task}.json").write_text(card_text(card))
    print(task, card["version"], card["transfer"]["accuracy"], card["recordings"]["out_of_fold"]["detectable"])
