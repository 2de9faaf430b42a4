"""Score an ONNX model on a simulator dataset through wallcli's run-time path (onnxruntime).

    .venv/bin/python models/evaluate.py count data/val_count [--model models/count.onnx] [--json]

Prints accuracy, the confusion matrix, per-class recall and accuracy against visibility
(the movers' SNR per window in the recorded plot, written by the simulator), and the same on
the visible windows only, so a model card can say not only how often the model is right but
where it stops being able to see.
"""
from __future__ import annotations

import argparse

import numpy as np

from wallcli.infer.model import load_model
from wallcli.signal.window import normalize_window
from wallcli.train.data import ShardDataset

SNR_EDGES = [-np.inf, -20.0, -10.0, 0.0, 10.0, np.inf]


def evaluate(task: str, data: str, model_path: str | None = None, visible_db: float = -10.0) -> dict:
    model = load_model(task, model_path)
    ds = ShardDataset(data, task)
    probs, labels = [], []
    for i in range(len(ds.files)):
        arrays = ds._load_shard(i)
        probs.append(model.predict({name: normalize_window(arrays[name]) for name in ds.inputs}))
        labels.append(arrays["label"])
    p, y, s = np.concatenate(probs), np.concatenate(labels), ds.visibility()
    pred = p.argmax(axis=1)
    k = len(model.classes)
    cm = np.zeros((k, k), np.int64)
    np.add.at(cm, (y, pred), 1)
    buckets = []
    movers = ~np.isnan(s)
    for lo, hi in zip(SNR_EDGES[:-1], SNR_EDGES[1:]):
        sel = movers & (s >= lo) & (s < hi)
        if sel.any():
            buckets.append({"snr_db": [lo, hi], "windows": int(sel.sum()), "accuracy": float((pred[sel] == y[sel]).mean())})
    # "visible": nobody moving, or the movers' signal at least visible_db against the rest of the window
    vis = ~movers | (np.nan_to_num(s, nan=-np.inf) >= visible_db)
    cm_vis = np.zeros((k, k), np.int64)
    np.add.at(cm_vis, (y[vis], pred[vis]), 1)
    return {
        "task": task, "data": data, "model": model.info(), "windows": int(len(y)),
        "visible": {"min_snr_db": visible_db, "windows": int(vis.sum()), "accuracy": float((pred[vis] == y[vis]).mean()),
                    "confusion_matrix": cm_vis.tolist()},
        "accuracy": float((pred == y).mean()),
        "classes": model.classes,
        "confusion_matrix": cm.tolist(),
        "recall": [float(cm[i, i] / cm[i].sum()) if cm[i].sum() else None for i in range(k)],
        "nobody_moving_accuracy": float((pred[~movers] == y[~movers]).mean()) if (~movers).any() else None,
        "accuracy_by_snr": buckets,
    }


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("task", choices=["count", "activity"])
    ap.add_argument("data")
    ap.add_argument("--model")
    ap.add_argument("--json", action="store_true")
    ap.add_argument("--visible-db", type=float, default=-10.0,
                    help="SNR from which a mover counts as visible (default -10 dB)")
    a = ap.parse_args()
    r = evaluate(a.task, a.data, a.model, a.visible_db)
    if a.json:
        from wallcli.cli.output import to_json  # infinities (open SNR buckets) become null

        print(to_json(r))
        return
    print(f"{a.task} on {a.data}: accuracy {r['accuracy']:.1%} over {r['windows']} windows")
    print("confusion (rows true, columns predicted):", r["classes"])
    for c, row in zip(r["classes"], r["confusion_matrix"]):
        print(f"  {str(c):>10}  " + " ".join(f"{v:5d}" for v in row))
    v = r["visible"]
    print(f"visible windows (nobody moving, or movers' SNR >= {v['min_snr_db']:g} dB): accuracy {v['accuracy']:.1%} "
          f"over {v['windows']}")
    for c, row in zip(r["classes"], v["confusion_matrix"]):
        print(f"  {str(c):>10}  " + " ".join(f"{x:5d}" for x in row))
    for b in r["accuracy_by_snr"]:
        print(f"  movers' SNR {b['snr_db'][0]:>6} .. {b['snr_db'][1]:<6} dB: {b['accuracy']:.1%} of {b['windows']}")


if __name__ == "__main__":
    main()
