"""int8 graphs that every x86 CPU computes alike: 7-bit weights, fused convolutions."""
import numpy as np
import pytest

onnx = pytest.importorskip("onnx")
ort = pytest.importorskip("onnxruntime")

from onnx import TensorProto, helper, numpy_helper  # noqa: E402

from wallcli.errors import WallcliError  # noqa: E402
from wallcli.train.quantize import MAX_WEIGHT, fused_convolutions, requantize_7bit, saturation_margin  # noqa: E402


def _float_conv_net(path, rng):
    """input (N, 3, 16, 32) -> conv 5x5 (8) -> leaky ReLU -> conv 3x3 (8) -> output."""
    w1 = rng.normal(0, 0.3, (8, 3, 5, 5)).astype(np.float32)
    w2 = rng.normal(0, 0.3, (8, 8, 3, 3)).astype(np.float32)
    b1, b2 = rng.normal(0, 0.1, 8).astype(np.float32), rng.normal(0, 0.1, 8).astype(np.float32)
    nodes = [helper.make_node("Conv", ["x", "w1", "b1"], ["h"], pads=[2, 2, 2, 2], name="c1"),
             helper.make_node("LeakyRelu", ["h"], ["a"], alpha=0.1, name="r1"),
             helper.make_node("Conv", ["a", "w2", "b2"], ["y"], pads=[1, 1, 1, 1], name="c2")]
    g = helper.make_graph(nodes, "t", [helper.make_tensor_value_info("x", TensorProto.FLOAT, ["n", 3, 16, 32])],
                          [helper.make_tensor_value_info("y", TensorProto.FLOAT, ["n", 8, 16, 32])],
                          [numpy_helper.from_array(a, n) for a, n in ((w1, "w1"), (b1, "b1"), (w2, "w2"), (b2, "b2"))])
    onnx.save(helper.make_model(g, opset_imports=[helper.make_opsetid("", 17)]), str(path))


def _reference(path, x):
    """The graph's own QDQ arithmetic, unfused (DequantizeLinear -> float Conv -> QuantizeLinear)."""
    o = ort.SessionOptions()
    o.graph_optimization_level = ort.GraphOptimizationLevel.ORT_DISABLE_ALL
    return ort.InferenceSession(str(path), o, providers=["CPUExecutionProvider"]).run(None, {"x": x})[0]


@pytest.mark.parametrize("per_channel", [True, False])
def test_requantize_7bit_bounds_weights_keeps_fusion_and_the_function(tmp_path, per_channel):
    from onnxruntime.quantization import CalibrationDataReader, QuantFormat, QuantType, quantize_static

    rng = np.random.default_rng(0)
    fp32, q8, q7 = tmp_path / "f.onnx", tmp_path / "q8.onnx", tmp_path / "q7.onnx"
    _float_conv_net(fp32, rng)
    calib = [rng.standard_normal((2, 3, 16, 32)).astype(np.float32) for _ in range(4)]

    class Reader(CalibrationDataReader):
        def __init__(self):
            self.it = iter(calib)

        def get_next(self):
            x = next(self.it, None)
            return None if x is None else {"x": x}

    # the old recipe: full 8-bit weights
    quantize_static(str(fp32), str(q8), Reader(), quant_format=QuantFormat.QDQ, per_channel=per_channel,
                    activation_type=QuantType.QUInt8, weight_type=QuantType.QInt8)
    with pytest.raises(WallcliError, match="saturate"):
        saturation_margin(onnx.load(str(q8)))

    assert requantize_7bit(q8, q7) == 2
    assert saturation_margin(onnx.load(str(q7))) == MAX_WEIGHT  # each scale's largest weight maps to 64
    assert fused_convolutions(q7) == (2, 0)  # biases rescaled with the weights, so still QLinearConv
    x = rng.standard_normal((3, 3, 16, 32)).astype(np.float32)
    sess = ort.InferenceSession(str(q7), providers=["CPUExecutionProvider"])
    y7, y8 = sess.run(None, {"x": x})[0], _reference(q8, x)
    # the same function up to a weight step: within a few per cent of the output's range
    assert np.abs(y7 - y8).max() < 0.05 * np.abs(y8).max()
    # fused == its own QDQ graph, up to one output step where float and integer paths round a .5 apart
    assert np.abs(y7 - _reference(q7, x)).max() <= 0.01 * np.abs(y8).max()
