"""Give a shipped 8-bit-weight model 7-bit weights and measure it again (one-off, session 7).

    .venv/bin/python research/requantize.py count data/val_count6 --version 0.4.1
    .venv/bin/python research/requantize.py activity data/val_activity3 --version 0.3.1
    .venv/bin/python research/requantize.py count data/val_count6 --remeasure   # new data, same model

Why: onnxruntime's x86 uint8 x int8 kernels without VNNI add pairs of products into a saturating
int16, so an int8 model with weights up to 127 computes other numbers on an AVX2 CPU than on a
VNNI one (wallcli/train/quantize.py). count 0.4.0 and activity 0.3.0 were quantised that way and
their float weights were not kept; this rewrites their weights to |w| <= 64 from the weights
the graph dequantises to (with the int32 biases rescaled), checks that onnxruntime still fuses
every convolution into QLinearConv, scores the result on DATASET through the run-time path, and
writes the model and its card (the previous card's training record kept, the version, hash,
quantisation and validation figures replaced). A retrain (models/train.sh) quantises from float
with the same 7-bit range directly.
"""
from __future__ import annotations

import argparse
import json
import shutil
import sys
import tempfile
from pathlib import Path

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE))

from evaluate import _predict  # noqa: E402

from wallcli.infer.card import card_path, read_card, sha256_file, write_card  # noqa: E402
from wallcli.io.writer import atomic_path  # noqa: E402
from wallcli.train.data import ShardDataset  # noqa: E402
from wallcli.train.export import measured_validation  # noqa: E402
from wallcli.train.quantize import MAX_WEIGHT, METHOD, fused_convolutions, requantize_7bit, saturation_margin  # noqa: E402


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("task", choices=["count", "activity"])
    ap.add_argument("data", help="validation dataset (wallcli simulate --dataset) to measure the result on")
    ap.add_argument("--version", help="the new model version (required unless --remeasure)")
    ap.add_argument("--model", type=Path, help="source model (default: models/TASK.onnx, rewritten in place)")
    ap.add_argument("--remeasure", action="store_true",
                    help="leave the model alone; measure its card's validation figures again on DATA")
    a = ap.parse_args()
    if not a.remeasure and not a.version:
        ap.error("--version is required")

    src = a.model or HERE / f"{a.task}.onnx"
    old = read_card(src)
    with tempfile.TemporaryDirectory() as d:
        new = Path(d) / src.name  # a model and its card side by side, as the loader wants them
        card = json.loads(json.dumps(old))
        if a.remeasure:
            shutil.copyfile(src, new)
            n, worst = None, None
        else:
            n = requantize_7bit(src, new)
            import onnx

            worst = saturation_margin(onnx.load(str(new)))
            q, f = fused_convolutions(new)
            if f or q != n:
                raise SystemExit(f"onnxruntime fused {q} of {n} convolutions ({f} left in float)")
            card["version"] = a.version
            card["sha256"] = sha256_file(new)
            card["onnx"]["bytes"] = new.stat().st_size
            quant = card["onnx"]["quantization"]
            quant.update(method=METHOD, max_abs_weight=MAX_WEIGHT, largest_weight=worst)
            quant["requantized_from"] = {"version": old["version"], "sha256": old["sha256"],
                                         "by": "research/requantize.py (7-bit weights from the 8-bit ones)"}
            # measured on an 8-bit graph whose answers depended on the CPU; not this graph's
            for k in ("float32_accuracy", "max_probability_change"):
                quant.pop(k, None)
        write_card(card_path(new), card)
        ds = ShardDataset(a.data, a.task)
        _, probs, labels = _predict(a.task, ds, str(new))
        v = card["validation"] = measured_validation(
            card["validation"], probs, {"labels": labels, "visibility": ds.visibility(), "scenes": ds.scene_ids()},
            "the shipped int8 graph (7-bit weights), through onnxruntime")
        v["source"] = {"dataset": a.data, "recipe": ds.recipes[0], "seed": ds.recipes[0].get("seed"),
                       "note": "simulated with the repeatable encoder (x264 on one thread, without its AVX-512 code): "
                               "the same files on any machine with AVX2"}
        with atomic_path(src, force=True) as tmp, atomic_path(card_path(src), force=True) as tmp_card:
            shutil.copyfile(new, tmp)
            write_card(tmp_card, card)
    vis = card["validation"]["visible"]
    what = "measured again" if a.remeasure else f"{n} convolutions at |w| <= {worst}, all fused"
    print(f"{a.task} {card['version']}: {what}; accuracy "
          f"{card['validation']['accuracy']:.1%} of {card['validation']['windows']} windows, "
          f"{vis['accuracy']:.1%} of {vis['windows']} visible; sha256 {card['sha256'][:12]}")


if __name__ == "__main__":
    main()
