"""Write the recordings' out-of-fold figures over the grown set (229 clips) and the learning curve
into the shipped cards, without touching the models (issue 53).

Inputs, each made by a command that answers every fold with a model fitted without it:
  runs/cand229/count-keep.json      wallcli train count --clips ../shared/transfer --clip-cache runs/reccache
                                      --folds 5 --init models/count.onnx --epochs 0 --out runs/cand229/count-keep.onnx
  runs/cand229/activity-split.json  wallcli train activity ... --init models/activity.onnx --epochs 0
                                      --split waving,jumping --out runs/cand229/activity-split.onnx
  runs/curve.json, runs/curve_balanced.json   python research/recordings/curve.py [--folds balanced]

What changes in models/*.json: `recordings` (the out-of-fold block, now over 229 clips / activity's 189
with at most one person, plus `learning_curve`), `transfer` (the same figures in evaluate's shape) and
the `fitted_on` wording of the confidence blocks, whose thresholds are checked to be unchanged. The
ONNX files and every fitted number the models answer with stay as shipped: activity's split stays the
one fitted on the first 220 clips (refitted on 229 its coefficients move by at most ~0.07; shipping
that would be a new model, judged by the rule like any candidate), and the card says so.

    python research/recordings/card_grown.py
"""
import hashlib
import json
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]
FOLDERS = ["the rendered recordings (../shared/transfer in the repository's workspace)"]


def rendered(text: str) -> str:
    """train --clips writes 'labelled recordings' (a user's own footage); the shipped cards' clips are rendered."""
    return text.replace("labelled recordings", "labelled rendered recordings")


def curve_block(task: str) -> dict:
    out = {"where": "research/recordings/README.md (research/recordings/curve.py)",
           "what": "out-of-fold detectable clips right when each fold's candidate is fitted on 25/50/75/100 % of "
                   "its training rooms (nested subsets, 20 draws, the same held-out folds); mean and range over "
                   "the draws, exact 95 % interval of the rounded mean"}
    for rule, f in (("fixed_folds", "curve.json"), ("balanced_folds", "curve_balanced.json")):
        d = json.loads((ROOT / "runs" / f).read_text())
        block = {}
        for name, pts in d["curve"][task].items():
            block[name] = {"points": [{k: (round(v, 2) if isinstance(v, float) else v) for k, v in p.items()
                                       if k in ("fraction", "rooms", "mean_k", "min_k", "max_k", "n")}
                                      | {"ci95": [round(x, 4) for x in p["cp95"]]} for p in pts],
                           "per_doubling_of_rooms": round(d["fits"][f"{task} | {name}"]["slope_per_doubling"], 4)}
        out[rule] = block
    return out


def same_thresholds(a: dict, b: dict) -> bool:
    strip = lambda d: {k: v for k, v in d.items() if k != "fitted_on"}  # noqa: E731
    return strip(a) == strip(b)


def main() -> None:
    for task, src in (("count", "runs/cand229/count-keep.json"), ("activity", "runs/cand229/activity-split.json")):
        new = json.loads((ROOT / src).read_text())
        path = ROOT / "models" / f"{task}.json"
        card = json.loads(path.read_text())
        onnx = (ROOT / "models" / f"{task}.onnx").read_bytes()
        assert hashlib.sha256(onnx).hexdigest() == card["sha256"] == new["sha256"], f"{task}: not the shipped net"
        rec = new["recordings"]
        rec["folders"] = FOLDERS
        rec["candidates_compared"] = card["recordings"]["candidates_compared"]
        rec["learning_curve"] = curve_block(task)
        if task == "count":
            assert same_thresholds(card["two_stage"]["confidence"], new["two_stage"]["confidence"])
            card["two_stage"]["confidence"]["fitted_on"] = rendered(new["two_stage"]["confidence"]["fitted_on"])
        else:
            assert same_thresholds(card["confidence"], new["confidence"])
            card["confidence"]["fitted_on"] = rendered(new["confidence"]["fitted_on"])
            rec["split_fitted_on"] = ("t001-t220 (" + card["split"]["fitted_on"] + "); each fold's split in "
                                      "these figures is refitted on its 4 training folds of all 229 clips")
        card["recordings"] = rec
        card["transfer"] = new["transfer"]
        card["transfer"]["description"] = rendered(card["transfer"]["description"])
        from wallcli.infer.card import card_text  # sealed: these figures are the measured ones

        path.write_text(card_text(card))
        print(task, rec["out_of_fold"]["detectable"]["right"], "of", rec["out_of_fold"]["detectable"]["clips"])


if __name__ == "__main__":
    main()
