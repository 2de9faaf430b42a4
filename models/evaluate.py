"""Score an ONNX model on a simulator dataset through wallcli's run-time path (onnxruntime).

    .venv/bin/python models/evaluate.py count data/val_count [--model models/count.onnx] [--json]

Prints accuracy, the confusion matrix, per-class recall and accuracy against visibility
(the movers' SNR per window in the recorded plot, written by the simulator), and the same on
the visible windows only, so a model card can say not only how often the model is right but
where it stops being able to see. The 95 % intervals resample whole scenes (windows of one
scene share its room, camera and people): see wallcli/train/metrics.py.
"""
from __future__ import annotations

import argparse

import numpy as np

from wallcli.infer.model import load_model
from wallcli.train.data import ShardDataset
from wallcli.train.metrics import VISIBLE_DB, breakdown


def evaluate(task: str, data: str, model_path: str | None = None, visible_db: float = VISIBLE_DB) -> dict:
    model = load_model(task, model_path)
    ds = ShardDataset(data, task)
    probs, labels = [], []
    for i in range(len(ds.files)):
        arrays = ds._load_shard(i)
        probs.append(model.predict({name: model.normalize(arrays[name]) for name in ds.inputs}))
        labels.append(arrays["label"])
    r = breakdown(np.concatenate(probs), np.concatenate(labels), ds.visibility(), ds.scene_ids(), visible_db)
    return {"task": task, "data": data, "model": model.info(), "classes": model.classes, **r}


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("task", choices=["count", "activity"])
    ap.add_argument("data")
    ap.add_argument("--model")
    ap.add_argument("--json", action="store_true")
    ap.add_argument("--visible-db", type=float, default=VISIBLE_DB,
                    help="SNR from which a mover counts as visible (default -10 dB)")
    a = ap.parse_args()
    r = evaluate(a.task, a.data, a.model, a.visible_db)
    if a.json:
        from wallcli.cli.output import to_json  # infinities (open SNR buckets) become null

        print(to_json(r))
        return
    lo, hi = r["accuracy_95ci"]
    print(f"{a.task} on {a.data}: accuracy {r['accuracy']:.1%} (95 % CI {lo:.1%}-{hi:.1%}) over {r['windows']} windows "
          f"from {r['scenes']} scenes")
    print("confusion (rows true, columns predicted):", r["classes"])
    for c, row in zip(r["classes"], r["confusion_matrix"]):
        print(f"  {str(c):>10}  " + " ".join(f"{v:5d}" for v in row))
    v = r["visible"]
    lo, hi = v["accuracy_95ci"] or (float("nan"), float("nan"))
    print(f"visible windows (nobody moving, or every mover's SNR >= {v['min_snr_db']:g} dB): accuracy {v['accuracy']:.1%} "
          f"(95 % CI {lo:.1%}-{hi:.1%}) over {v['windows']} from {v['scenes']} scenes")
    for c, row in zip(r["classes"], v["confusion_matrix"]):
        print(f"  {str(c):>10}  " + " ".join(f"{x:5d}" for x in row))
    for b in r["accuracy_by_snr"]:
        lo, hi = ("-inf" if b["snr_db"][0] is None else b["snr_db"][0]), ("inf" if b["snr_db"][1] is None else b["snr_db"][1])
        print(f"  least visible mover's SNR {lo:>6} .. {hi:<6} dB: {b['accuracy']:.1%} of {b['windows']}")


if __name__ == "__main__":
    main()
