"""Score an ONNX model on a simulator dataset through wallcli's run-time path (onnxruntime).

    .venv/bin/python models/evaluate.py count data/val_count [--model models/count.onnx] [--json]
    .venv/bin/python models/evaluate.py count data/val_count --model new.onnx --against models/count.onnx

Prints accuracy, the confusion matrix, per-class recall and accuracy against visibility
(the movers' SNR per window in the recorded plot, written by the simulator), and the same on
the visible windows only, so a model card can say not only how often the model is right but
where it stops being able to see. The 95 % intervals resample whole scenes (windows of one
scene share its room, camera and people): see wallcli/train/metrics.py. ``--against OTHER``
scores a second model on the same windows and prints the paired difference with its interval.
"""
from __future__ import annotations

import argparse

import numpy as np

from wallcli.infer.model import load_model
from wallcli.train.data import ShardDataset
from wallcli.train.metrics import VISIBLE_DB, breakdown, paired_difference, visible_mask


def _predict(task: str, ds: ShardDataset, model_path: str | None):
    model = load_model(task, model_path)
    probs, labels = [], []
    for i in range(len(ds.files)):
        arrays = ds._load_shard(i)
        probs.append(model.predict({name: model.normalize(arrays[name]) for name in ds.inputs}))
        labels.append(arrays["label"])
    return model, np.concatenate(probs), np.concatenate(labels)


def evaluate(task: str, data: str, model_path: str | None = None, visible_db: float = VISIBLE_DB,
             against: str | None = None) -> dict:
    ds = ShardDataset(data, task)
    model, p, y = _predict(task, ds, model_path)
    vis, scenes = ds.visibility(), ds.scene_ids()
    out = {"task": task, "data": data, "model": model.info(), "classes": model.classes,
           **breakdown(p, y, vis, scenes, visible_db)}
    if against is not None:
        other, q, _ = _predict(task, ds, against)
        a, b = p.argmax(1) == y, q.argmax(1) == y
        seen = visible_mask(vis, visible_db)
        out["against"] = {"model": other.info(), "all": paired_difference(a, b, scenes),
                          "visible": paired_difference(a[seen], b[seen], scenes[seen])}
    return out


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("task", choices=["count", "activity"])
    ap.add_argument("data")
    ap.add_argument("--model")
    ap.add_argument("--against", help="a second model scored on the same windows: paired difference")
    ap.add_argument("--json", action="store_true")
    ap.add_argument("--visible-db", type=float, default=VISIBLE_DB,
                    help="SNR from which a mover counts as visible (default -10 dB)")
    a = ap.parse_args()
    r = evaluate(a.task, a.data, a.model, a.visible_db, a.against)
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

    if "against" in r:
        o = r["against"]
        for k in ("all", "visible"):
            d, (lo, hi) = o[k]["difference"], o[k]["difference_95ci"]
            print(f"{k} windows: {r['model']['version']} minus {o['model']['name']} {o['model']['version']}: "
                  f"{d:+.1%} (95 % CI {lo:+.1%} to {hi:+.1%}, paired scene bootstrap)")


if __name__ == "__main__":
    main()
