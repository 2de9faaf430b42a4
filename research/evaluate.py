"""Score an ONNX model on a simulator dataset through wallcli's run-time path (onnxruntime).

    .venv/bin/python research/evaluate.py count data/val_count [--model models/count.onnx] [--json]
    .venv/bin/python research/evaluate.py count data/val_count --model new.onnx --against models/count.onnx
    .venv/bin/python research/evaluate.py count data/val_count7 --record   # into the card's other_sets
    .venv/bin/python research/evaluate.py count data/val_count6 data/val_count7   # two sets as one

Prints accuracy, the confusion matrix, per-class recall and accuracy against visibility
(the movers' SNR per window in the recorded plot, written by the simulator), and the same on
the visible windows only, so a model card can say not only how often the model is right but
where it stops being able to see. The 95 % intervals resample whole scenes (windows of one
scene share its room, camera and people): see wallcli/train/metrics.py. ``--against OTHER``
scores a second model on the same windows and prints the paired difference with its interval.
The per-clip line scores each scene as ``wallcli count``/``activity`` answer for a whole clip (the
mean of its windows' probabilities): what a user running the command on a clip of ~10 s sees.
``--record`` writes the figures into the model card's ``validation.other_sets`` (one entry per
dataset seed, replaced when measured again): a single validation set of a few hundred scenes
can be several points on the lucky side, and the card should say so. The card's main figures
(the set it was measured on at export) are left alone; the model file is not touched.
"""
from __future__ import annotations

import argparse
from pathlib import Path

import numpy as np

from wallcli.infer.model import load_model
from wallcli.train.data import OFFSETS, ShardDataset
from wallcli.train.metrics import VISIBLE_DB, breakdown, clip_breakdown, paired_difference, visible_mask


def _predict(task: str, ds: ShardDataset, model_path: str | None):
    model = load_model(task, model_path)
    probs, labels = [], []
    for i in range(len(ds.files)):
        arrays = ds._load_shard(i)
        probs.append(model.predict({name: model.normalize(arrays[name], arrays[OFFSETS[name]]) for name in model.input_names}))
        labels.append(arrays["label"])
    return model, np.concatenate(probs), np.concatenate(labels)


def evaluate(task: str, data: str | list[str], model_path: str | None = None, visible_db: float = VISIBLE_DB,
             against: str | None = None) -> dict:
    # every plot any model reads, so that two models of different inputs score the same windows
    ds = ShardDataset(data, task, inputs=["horizontal", "vertical"])
    model, p, y = _predict(task, ds, model_path)
    vis, scenes = ds.visibility(), ds.scene_ids()
    out = {"task": task, "data": data, "model": model.info(), "classes": model.classes,
           **breakdown(p, y, vis, scenes, visible_db), "per_clip": clip_breakdown(p, y, vis, scenes, visible_db)}
    if against is not None:
        other, q, _ = _predict(task, ds, against)
        a, b = p.argmax(1) == y, q.argmax(1) == y
        seen = visible_mask(vis, visible_db)
        out["against"] = {"model": other.info(), "all": paired_difference(a, b, scenes),
                          "visible": paired_difference(a[seen], b[seen], scenes[seen])}
    return out


def record(task: str, data: str, model_path: str | None, result: dict) -> Path:
    """Store ``result`` (from evaluate) in the card's validation.other_sets; returns the card's path."""
    from wallcli.infer.card import card_path, read_card, write_card
    from wallcli.infer.model import shipped_model_path
    from wallcli.io.writer import atomic_path

    path = Path(model_path) if model_path else shipped_model_path(task)
    card = read_card(path)
    if result["model"].get("sha256") != card.get("sha256"):
        raise SystemExit(f"{path}: the card changed while it was being measured")
    ds = ShardDataset(data, task)
    recipe, seed = ds.recipes[0], ds.manifests[0].get("seed", ds.recipes[0].get("seed"))
    entry = {"dataset": data, "seed": seed, "recipe": recipe,
             **{k: result[k] for k in ("windows", "scenes", "accuracy", "accuracy_95ci", "confusion_matrix",
                                       "visible", "accuracy_by_snr") if k in result},
             "measured_on": "the shipped graph, through onnxruntime (research/evaluate.py --record)"}
    v = card.setdefault("validation", {})
    others = [o for o in v.get("other_sets", []) if o.get("seed") != entry["seed"]]
    v["other_sets"] = sorted(others + [entry], key=lambda o: (o.get("seed") is None, o.get("seed")))
    with atomic_path(card_path(path), force=True) as tmp:
        write_card(tmp, card)
    return card_path(path)


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("task", choices=["count", "activity"])
    ap.add_argument("data", nargs="+", help="dataset folder(s); several are scored as one (scene ids stay apart)")
    ap.add_argument("--model")
    ap.add_argument("--against", help="a second model scored on the same windows: paired difference")
    ap.add_argument("--json", action="store_true")
    ap.add_argument("--visible-db", type=float, default=VISIBLE_DB,
                    help="SNR from which a mover counts as visible (default -10 dB)")
    ap.add_argument("--record", action="store_true",
                    help="write the figures into the model card's validation.other_sets (default -10 dB only)")
    a = ap.parse_args()
    if a.record and (a.visible_db != VISIBLE_DB or a.against or len(a.data) > 1):
        ap.error("--record stores one set's standard figures: one dataset, no --visible-db or --against")
    data = a.data[0] if len(a.data) == 1 else a.data
    r = evaluate(a.task, data, a.model, a.visible_db, a.against)
    if a.record:
        import sys

        print(f"recorded in {record(a.task, data, a.model, r)}", file=sys.stderr)
    if a.json:
        from wallcli.cli.output import to_json  # infinities (open SNR buckets) become null

        print(to_json(r))
        return
    lo, hi = r["accuracy_95ci"]
    print(f"{a.task} on {' + '.join(a.data)}: accuracy {r['accuracy']:.1%} (95 % CI {lo:.1%}-{hi:.1%}) over {r['windows']} windows "
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

    c, cv = r["per_clip"], r["per_clip"].get("visible")
    if c["accuracy"] is not None:
        lo, hi = c["accuracy_95ci"]
        line = f"per clip (mean of a scene's windows, as the commands' clip answer): {c['accuracy']:.1%} (95 % CI {lo:.1%}-{hi:.1%}) of {c['clips']} clips"
        if cv and cv["accuracy"] is not None:
            lo, hi = cv["accuracy_95ci"]
            line += f"; {cv['accuracy']:.1%} (95 % CI {lo:.1%}-{hi:.1%}) of the {cv['clips']} whose windows are all visible"
        print(line)

    if "against" in r:
        o = r["against"]
        for k in ("all", "visible"):
            d, (lo, hi) = o[k]["difference"], o[k]["difference_95ci"]
            print(f"{k} windows: {r['model']['version']} minus {o['model']['name']} {o['model']['version']}: "
                  f"{d:+.1%} (95 % CI {lo:+.1%} to {hi:+.1%}, paired scene bootstrap)")


if __name__ == "__main__":
    main()
