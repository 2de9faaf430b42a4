"""Static int8 quantisation of an exported model (``wallcli train --quantize int8``).

Why: the activity net's two trunks cost ~14 ms per window in float32 on a 2-core AVX2 CPU
(session 3), over the 10 ms budget, and the architecture is fixed by the seed. int8
convolutions ran about 1.6x faster in onnxruntime there.

How: onnxruntime's static QDQ quantisation: weights 7-bit in int8 per output channel, activations uint8
with ranges calibrated on real training windows (normalised exactly as at inference). The head
after the time max stays float32 (it is tiny). The network input is quantised too: it is the
normalised window with all its noise still in it (unit RMS), so a step of ~1/20 of that RMS adds
~0.02 % to the noise power; keeping the first convolution in float32 instead cost 30 % of the gain.

Weights are 7-bit (|w| <= 64), not 8: onnxruntime's x86 kernels for uint8 x int8 without
VNNI (AVX2, and AVX-512 before Cascade Lake) multiply with VPMADDUBSW, which adds each pair of
products into a *saturating* int16. With 8-bit weights a pair reaches 255 * 127 * 2 = 64770;
measured on the shipped activity net, 3-4 % of the first convolution's pairs passed 32767, so
the same model gave other probabilities on an AVX2 machine than on a VNNI one (and flipped the
waving example's answer). With |w| <= 64 a pair is at most 32640 and every CPU computes the
exact integer sums the graph defines (``saturation_margin`` checks it; the tests check the
shipped models).

The quantised graph is what ships: the train command measures its validation accuracy again
through onnxruntime and records, in the card, the float model's accuracy and the largest change
in any class probability between the two.
"""
from __future__ import annotations

from pathlib import Path
from typing import Any

import numpy as np

from wallcli.errors import WallcliError
from wallcli.extras import ONNX
from wallcli.infer.card import OUTPUT_NAME

METHOD = ("onnxruntime static QDQ of the convolution trunks: 7-bit weights (int8 storage, |w| <= 64) per output "
          "channel, uint8 activations (min/max calibration); the head after the time max kept in float32")
# x86 u8s8 kernels without VNNI add two uint8 x int8 products into a saturating int16:
# 255 * 64 * 2 = 32640 fits, 255 * 65 * 2 does not.
MAX_WEIGHT = 64


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
                           hint=ONNX) from None

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
                        activation_type=QuantType.QUInt8, weight_type=QuantType.QInt8, nodes_to_exclude=keep,
                        reduce_range=True)
        saturation_margin(onnx.load(str(dst)))
    finally:
        pre.unlink(missing_ok=True)
        for extra in Path(dst).parent.glob(Path(dst).name + "*.data"):
            extra.unlink(missing_ok=True)
    return {"method": METHOD, "calibration_windows": int(n), "float32_nodes": keep, "max_abs_weight": MAX_WEIGHT}


def dequantize(dq, arrays: dict[str, np.ndarray]) -> tuple[np.ndarray, int | None]:
    """The float64 values of a DequantizeLinear node whose inputs are constants in ``arrays``,
    and its axis (None when one scale covers the whole tensor)."""
    q = arrays[dq.input[0]].astype(np.float64)
    scale = arrays[dq.input[1]].astype(np.float64)
    zero = arrays[dq.input[2]].astype(np.float64) if len(dq.input) > 2 and dq.input[2] else np.zeros_like(scale)
    if not scale.ndim:
        return (q - zero) * scale, None
    axis = next((a.i for a in dq.attribute if a.name == "axis"), 1)
    shape = [1] * q.ndim
    shape[axis] = -1
    return (q - zero.reshape(shape)) * scale.reshape(shape), axis


def _quantized_weights(model):
    """(conv node, int8 weights, scales, their DequantizeLinear node, the initializers by name)
    for every convolution whose weights come through a DequantizeLinear of an int8 initializer."""
    from onnx import numpy_helper

    init = {i.name: i for i in model.graph.initializer}
    made_by = {o: n for n in model.graph.node for o in n.output}
    for node in model.graph.node:
        if node.op_type != "Conv" or len(node.input) < 2:
            continue
        dq = made_by.get(node.input[1])
        if dq is None or dq.op_type != "DequantizeLinear" or dq.input[0] not in init:
            continue
        w = numpy_helper.to_array(init[dq.input[0]])
        if w.dtype == np.int8:
            yield node, w, numpy_helper.to_array(init[dq.input[1]]), dq, init


def saturation_margin(model) -> int:
    """The largest |weight| of any int8 convolution; raises if one could overflow the int16
    pair sums of x86 u8s8 kernels (see the module's docstring)."""
    worst = 0
    for node, w, _, _, _ in _quantized_weights(model):
        big = int(np.abs(w.astype(np.int16)).max())
        if big > MAX_WEIGHT:
            raise WallcliError(f"convolution {node.name} has int8 weights up to {big}: above {MAX_WEIGHT}, "
                               "x86 CPUs without VNNI saturate and compute another model")
        worst = max(worst, big)
    return worst


def requantize_7bit(src: Path, dst: Path) -> int:
    """Rewrite an 8-bit-weight QDQ graph with 7-bit weights (per output channel, scale = max|w|/64),
    from the weights the graph dequantises to. For models whose float weights are gone (the
    int8 models shipped before this fix); a new export quantises from float directly. Returns
    the number of convolutions rewritten."""
    import onnx
    from onnx import numpy_helper

    model = onnx.load(str(src))
    made_by = {o: nd for nd in model.graph.node for o in nd.output}
    n = 0
    for conv, w, scale, dq, init in list(_quantized_weights(model)):
        wf, axis = dequantize(dq, {k: numpy_helper.to_array(init[k]) for k in dq.input if k})
        reduce = None if axis is None else tuple(i for i in range(w.ndim) if i != axis)
        shape = [] if axis is None else [-1 if i == axis else 1 for i in range(w.ndim)]
        amax = np.abs(wf).max(axis=reduce)
        s7 = np.where(amax > 0, amax / MAX_WEIGHT, 1.0)
        w7 = np.clip(np.rint(wf / s7.reshape(shape)), -MAX_WEIGHT, MAX_WEIGHT).astype(np.int8)
        init[dq.input[0]].CopyFrom(numpy_helper.from_array(w7, dq.input[0]))
        init[dq.input[1]].CopyFrom(numpy_helper.from_array(np.asarray(s7, scale.dtype), dq.input[1]))
        # The int32 bias is stored in units of input scale x weight scale; onnxruntime fuses the
        # QDQ pattern into QLinearConv only when that (nearly) holds, else the conv runs in float.
        bq = made_by.get(conv.input[2]) if len(conv.input) > 2 else None
        if bq is not None and bq.op_type == "DequantizeLinear" and bq.input[0] in init:
            dqx = made_by.get(conv.input[0])
            if dqx is None or dqx.op_type != "DequantizeLinear" or dqx.input[1] not in init:
                raise WallcliError(f"convolution {conv.name}: its input is not quantised, so its int32 bias "
                                   "has no input scale to follow")
            x_scale = numpy_helper.to_array(init[dqx.input[1]]).astype(np.float64)
            b = numpy_helper.to_array(init[bq.input[0]]).astype(np.float64)
            b = b * numpy_helper.to_array(init[bq.input[1]]).astype(np.float64)
            # the product in float64, rounded once (within an ulp of the float32 product, which
            # onnxruntime's fusion tolerates; kept so the shipped 0.4.1/0.3.1 come out byte for byte)
            bs = np.asarray(x_scale * s7, np.float32)
            init[bq.input[0]].CopyFrom(numpy_helper.from_array(
                np.rint(b / bs.astype(np.float64)).astype(np.int32), bq.input[0]))
            init[bq.input[1]].CopyFrom(numpy_helper.from_array(bs, bq.input[1]))
        n += 1
    saturation_margin(model)
    onnx.save(model, str(dst))
    return n


def fused_convolutions(path: Path) -> tuple[int, int]:
    """(QLinearConv, float Conv) nodes after onnxruntime's graph optimisation. A QDQ convolution
    whose int32 bias scale is not input scale x weight scale is not fused and runs in float,
    about 4x slower (measured on the shipped count net, with a simulation beside it: 13.8 vs
    2.7 ms per window)."""
    import tempfile

    import onnx
    import onnxruntime as ort

    with tempfile.TemporaryDirectory() as d:
        o = ort.SessionOptions()
        o.optimized_model_filepath = str(Path(d) / "optimized.onnx")
        ort.InferenceSession(str(path), o, providers=["CPUExecutionProvider"])
        ops = [n.op_type for n in onnx.load(o.optimized_model_filepath).graph.node]
    # an unfused convolution may come back as Conv, FusedConv or another float variant
    return ops.count("QLinearConv"), sum(op.endswith("Conv") and op != "QLinearConv" for op in ops)


def onnx_probabilities(path: Path, feeds: dict[str, np.ndarray], batch: int = 64) -> np.ndarray:
    import onnxruntime as ort

    sess = ort.InferenceSession(str(path), providers=["CPUExecutionProvider"])
    n = len(next(iter(feeds.values())))
    out = [sess.run([OUTPUT_NAME], {k: v[i:i + batch] for k, v in feeds.items()})[0] for i in range(0, n, batch)]
    return np.concatenate(out).astype(np.float64)
