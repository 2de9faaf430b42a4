"""Static int8 quantisation of an exported model (``wallcli train --quantize int8``).

Why: the activity net's two trunks cost ~14 ms per window in float32 on this 2-core AVX2 CPU,
over the 10 ms budget, and the architecture is fixed by the seed. int8 convolutions run about
1.6x faster in onnxruntime here.

How: onnxruntime's static QDQ quantisation: weights int8 per output channel, activations uint8
with ranges calibrated on real training windows (normalised exactly as at inference). The head
after the time max stays float32 (it is tiny). The network input is quantised too: it is the
normalised window with all its noise still in it (unit RMS), so a step of ~1/20 of that RMS adds
~0.02 % to the noise power; keeping the first convolution in float32 instead cost 30 % of the gain.

The quantised graph is what ships: the train command measures its validation accuracy again
through onnxruntime and records, in the card, the float model's accuracy and the largest change
in any class probability between the two.
"""
from __future__ import annotations

from pathlib import Path
from typing import Any

import numpy as np

from wallcli.errors import WallcliError
from wallcli.infer.card import OUTPUT_NAME

METHOD = ("onnxruntime static QDQ of the convolution trunks: int8 weights per output channel, uint8 activations "
          "(min/max calibration); the head after the time max kept in float32")


def _float_nodes(model) -> list[str]:
    """Nodes kept in float32: the small head after the time max (max, concatenation, linear
    layers, softmax), so that probabilities do not come in steps of 1/255."""
    return [n.name for n in model.graph.node
            if n.op_type in ("ReduceMax", "Concat", "Gemm", "MatMul", "Softmax") or "/head/" in n.name]


def quantize_int8(src: Path, dst: Path, calib: dict[str, np.ndarray], batch: int = 8) -> dict[str, Any]:
    """Quantise ``src`` into ``dst``; ``calib`` maps input names to normalised (N, 3, bins, T) windows."""
    try:
        import onnx
        from onnxruntime.quantization import CalibrationDataReader, QuantFormat, QuantType, quantize_static
        from onnxruntime.quantization.shape_inference import quant_pre_process
    except ImportError as e:  # the train extra brings onnx
        raise WallcliError(f"int8 quantisation needs the onnx package ({e})",
                           hint="pip install 'wallcli[train]'") from None

    n = min(len(v) for v in calib.values())
    if n == 0:
        raise WallcliError("no windows to calibrate the quantisation on")

    class Reader(CalibrationDataReader):
        def __init__(self) -> None:
            self.i = 0

        def get_next(self):
            if self.i >= n:
                return None
            sl = slice(self.i, self.i + batch)
            self.i += batch
            return {k: np.ascontiguousarray(v[sl], np.float32) for k, v in calib.items()}

    pre = Path(str(dst) + ".pre.onnx")
    try:
        quant_pre_process(str(src), str(pre), skip_symbolic_shape=True)
        keep = _float_nodes(onnx.load(str(pre)))
        quantize_static(str(pre), str(dst), Reader(), quant_format=QuantFormat.QDQ, per_channel=True,
                        activation_type=QuantType.QUInt8, weight_type=QuantType.QInt8, nodes_to_exclude=keep)
    finally:
        pre.unlink(missing_ok=True)
        for extra in Path(dst).parent.glob(Path(dst).name + "*.data"):
            extra.unlink(missing_ok=True)
    return {"method": METHOD, "calibration_windows": int(n), "float32_nodes": keep}


def onnx_probabilities(path: Path, feeds: dict[str, np.ndarray], batch: int = 64) -> np.ndarray:
    import onnxruntime as ort

    sess = ort.InferenceSession(str(path), providers=["CPUExecutionProvider"])
    n = len(next(iter(feeds.values())))
    out = [sess.run([OUTPUT_NAME], {k: v[i:i + batch] for k, v in feeds.items()})[0] for i in range(0, n, batch)]
    return np.concatenate(out).astype(np.float64)
