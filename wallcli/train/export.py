"""Export a trained net to ONNX with its model card.

The graph ends in softmax (output ``probabilities``), batch is a dynamic axis, opset 17.
Before the files are published, onnxruntime's output on random inputs is compared with
torch's (max abs difference <= 1e-4 or the export fails), and the card records the sha256
of the exact bytes written.  Both files are written atomically, the card last renamed
first, so a model never appears without its card.
"""
from __future__ import annotations

import copy
import datetime as _dt
import warnings
from pathlib import Path
from typing import Any

import numpy as np
import torch

from wallcli.errors import WallcliError
from wallcli.infer.card import (CARD_FORMAT, CARD_VERSION, OUTPUT_NAME, PREPROCESSING, card_path,
                                input_spec, sha256_file, write_card)
from wallcli.signal.window import BINS, CANONICAL_FPS, DEFAULT_STRIDE, NORMALIZATION_TEXT, WINDOW
from wallcli.train.nets import WithSoftmax

OPSET = 17
PARITY_TOL = 1e-4


def export_onnx(net: torch.nn.Module, input_names: list[str], path: Path) -> None:
    model = WithSoftmax(copy.deepcopy(net).to(memory_format=torch.contiguous_format)).eval()
    dummy = tuple(torch.zeros(2, 3, BINS, WINDOW) for _ in input_names)
    axes = {n: {0: "batch"} for n in [*input_names, OUTPUT_NAME]}
    with warnings.catch_warnings():
        # the TorchScript exporter is deprecated in favour of the dynamo one, which cannot
        # yet trace our *inputs wrapper with a dynamic batch; it is exact for these ops
        warnings.simplefilter("ignore")
        torch.onnx.export(model, dummy, str(path), input_names=list(input_names), output_names=[OUTPUT_NAME],
                          opset_version=OPSET, dynamic_axes=axes, dynamo=False)


def check_parity(net: torch.nn.Module, input_names: list[str], path: Path, *, seed: int = 0,
                 batches: tuple[int, ...] = (1, 5), tol: float = PARITY_TOL) -> float:
    """Max |onnxruntime - torch| over random inputs of several batch sizes; raises above ``tol``."""
    import onnxruntime as ort

    model = WithSoftmax(net).eval()
    sess = ort.InferenceSession(str(path), providers=["CPUExecutionProvider"])
    gen = torch.Generator().manual_seed(seed)
    worst = 0.0
    for n in batches:
        xs = [torch.randn(n, 3, BINS, WINDOW, generator=gen) for _ in input_names]
        with torch.no_grad():
            ref = model(*xs).numpy()
        got = sess.run([OUTPUT_NAME], {k: x.numpy() for k, x in zip(input_names, xs)})[0]
        if got.shape != ref.shape:
            raise WallcliError(f"exported model gives shape {got.shape}, torch {ref.shape}")
        worst = max(worst, float(np.abs(got - ref).max()))
    if worst > tol:
        raise WallcliError(f"exported ONNX model differs from torch by {worst:.2e} (> {tol:.0e})")
    return worst


def measured_validation(validation: dict[str, Any] | None, probs: np.ndarray, evaluation: dict[str, Any],
              measured_on: str) -> dict[str, Any]:
    """The validation record measured again on the graph that ships, through onnxruntime: accuracy
    with its scene-bootstrap interval, loss, confusion, visible-window and per-SNR figures."""
    from wallcli.train.metrics import breakdown

    labels = np.asarray(evaluation["labels"], np.int64)
    loss = float(-np.mean(np.log(np.clip(probs[np.arange(len(labels)), labels], 1e-12, None))))
    out = dict(validation or {})
    out.update(breakdown(probs, labels, evaluation["visibility"], evaluation["scenes"]))
    out.update(loss=loss, measured_on=measured_on)
    return out


def build_card(*, name: str, version: str, task: str, classes: list[Any], input_names: list[str],
               preprocessing: str = PREPROCESSING, normalisation: str | None = None,
               sha256: str, size_bytes: int, parameters: int, stride: int = DEFAULT_STRIDE,
               training_data: dict[str, Any], training: dict[str, Any], validation: dict[str, Any] | None,
               onnx_file: str, parity: float, quantization: dict[str, Any] | None = None) -> dict[str, Any]:
    return {
        "format": CARD_FORMAT, "card_version": CARD_VERSION,
        "name": name, "version": version, "task": task, "classes": list(classes),
        "inputs": [input_spec(n, BINS, WINDOW) for n in input_names],
        "output": {"name": OUTPUT_NAME, "shape": [None, len(classes)], "meaning": "class probabilities (softmax)"},
        "preprocessing": preprocessing,
        "normalisation": normalisation or NORMALIZATION_TEXT[preprocessing],
        "fps": int(CANONICAL_FPS) if float(CANONICAL_FPS).is_integer() else CANONICAL_FPS, "window": WINDOW, "bins": BINS, "stride": stride,
        "clip_aggregation": "mean of window probabilities",
        "onnx": {"file": onnx_file, "opset": OPSET, "bytes": size_bytes, "parameters": parameters,
                 "parity_max_abs_diff": parity, "torch": torch.__version__,
                 "precision": "int8" if quantization else "float32", "quantization": quantization},
        "sha256": sha256,
        "training_data": training_data,
        "training": training,
        "validation": validation,
        "created": _dt.datetime.now(_dt.timezone.utc).replace(microsecond=0).isoformat(),
    }


def export_model(net: torch.nn.Module, input_names: list[str], out: Path, card_fields: dict[str, Any], *,
                 force: bool = False, seed: int = 0, quantize: dict[str, Any] | None = None,
                 evaluation: dict[str, Any] | None = None) -> dict[str, Any]:
    """Write OUT (.onnx) and its card OUT.json; returns the card.

    ``quantize``: {"calib": feeds} ships an int8 graph instead (wallcli/train/quantize.py); the
    float graph is still checked against torch first.
    ``evaluation``: {"feeds", "labels", "visibility", "scenes"} of the validation windows: the
    card's validation figures are then measured on the exported graph, through onnxruntime.
    """
    import os

    from wallcli.io.writer import atomic_path

    out = Path(out)
    net = net.eval()
    card_fields = dict(card_fields)
    with atomic_path(out, force=force) as tmp_onnx, atomic_path(card_path(out), force=force) as tmp_card:
        export_onnx(net, input_names, tmp_onnx)
        parity = check_parity(net, input_names, tmp_onnx, seed=seed)
        quant = None
        if quantize is not None:
            from wallcli.train.quantize import onnx_probabilities, quantize_int8

            fp32 = Path(str(tmp_onnx) + ".fp32.onnx")
            os.replace(tmp_onnx, fp32)
            try:
                quant = quantize_int8(fp32, tmp_onnx, quantize["calib"])
                if evaluation is not None:
                    p32 = onnx_probabilities(fp32, evaluation["feeds"])
                    quant["float32_accuracy"] = float(np.mean(p32.argmax(1) == evaluation["labels"]))
            finally:
                fp32.unlink(missing_ok=True)
        if evaluation is not None:
            from wallcli.train.quantize import onnx_probabilities

            shipped = onnx_probabilities(tmp_onnx, evaluation["feeds"])
            if quant is not None:
                quant["max_probability_change"] = float(np.abs(shipped - p32).max())
            card_fields["validation"] = measured_validation(
                card_fields.get("validation"), shipped, evaluation,
                f"the shipped {'int8' if quant is not None else 'float32'} graph, through onnxruntime")
        card = build_card(input_names=input_names, sha256=sha256_file(tmp_onnx), size_bytes=tmp_onnx.stat().st_size,
                          parameters=sum(p.numel() for p in net.parameters()), onnx_file=out.name, parity=parity,
                          quantization=quant, **card_fields)
        write_card(tmp_card, card)
    return card
