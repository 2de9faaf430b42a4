import json

import numpy as np
import pytest

torch = pytest.importorskip("torch")
onnx = pytest.importorskip("onnx")

from wallcli.infer.card import read_card, sha256_file  # noqa: E402
from wallcli.infer.model import Model  # noqa: E402
from wallcli.train.export import check_parity, export_model  # noqa: E402
from wallcli.train.nets import build  # noqa: E402


FIELDS = dict(name="t", version="0.0.1", training_data={"recipe": {}}, training={"seed": 0}, validation=None)


@pytest.mark.parametrize("task", ["count", "activity"])
def test_export_parity_dynamic_batch_and_card(tmp_path, task):
    torch.manual_seed(0)
    net = build(task).eval()
    inputs = list(net.input_names)
    out = tmp_path / f"{task}.onnx"
    card = export_model(net, inputs, out, dict(FIELDS, task=task, classes=net.classes))
    assert card["onnx"]["parity_max_abs_diff"] <= 1e-4
    assert card["sha256"] == sha256_file(out)
    assert read_card(out) == json.loads(json.dumps(card))  # what was written is what was returned
    m = onnx.load(str(out))
    assert max(o.version for o in m.opset_import if o.domain in ("", "ai.onnx")) >= 17
    assert [i.name for i in m.graph.input] == inputs
    assert m.graph.input[0].type.tensor_type.shape.dim[0].dim_param  # symbolic batch
    # onnxruntime agrees with torch for batches the export never saw
    model = Model.load(out, task=task)
    for n in (1, 7):
        xs = [np.random.default_rng(n).normal(size=(n, 3, 64, 256)).astype(np.float32) for _ in inputs]
        ref = torch.softmax(net(*map(torch.from_numpy, xs)), 1).detach().numpy()
        got = model.predict(dict(zip(inputs, xs)))
        assert np.abs(got - ref).max() <= 1e-4
    assert card["preprocessing"] == "wallcli.signal.window.normalize_window v1"
    assert (card["fps"], card["window"], card["bins"], card["stride"]) == (30, 256, 64, 64)
    assert card["inputs"][0]["layout"] == "NCHW" and card["inputs"][0]["shape"] == [None, 3, 64, 256]


def test_parity_check_detects_a_different_model(tmp_path):
    torch.manual_seed(0)
    net = build("count").eval()
    out = tmp_path / "c.onnx"
    export_model(net, ["horizontal"], out, dict(FIELDS, task="count", classes=[0, 1, 2]))
    torch.manual_seed(1)
    with pytest.raises(Exception, match="differs"):
        check_parity(build("count").eval(), ["horizontal"], out)


def test_train_command_end_to_end(make_dataset, tmp_path, capsys, cli_code):
    data = make_dataset("count", 20)
    val = make_dataset("count", 6, seed=9, shards=1, name="val", visibility=True)
    out = tmp_path / "models" / "count.onnx"
    out.parent.mkdir()
    args = ["train", "count", "--data", str(data), "--val", str(val), "--out", str(out), "--epochs", "1",
            "--batch-size", "8", "--threads", "2", "--model-version", "0.1.0"]
    assert cli_code(args) == 0
    card = read_card(out)
    assert card["task"] == "count" and card["classes"] == [0, 1, 2] and card["version"] == "0.1.0"
    assert card["sha256"] == sha256_file(out)
    assert card["training_data"]["recipe"] == [{"generator": "tests/train/conftest.py streaks"}]
    assert card["training_data"]["windows"] == 20 and card["training"]["optimizer"] == "RMSprop"
    assert card["training"]["lr"] == 1e-3 and card["training"]["augmentation"]
    v = card["validation"]
    assert v["windows"] == 6 and np.array(v["confusion_matrix"]).shape == (3, 3)
    assert np.array(v["confusion_matrix"]).sum() == 6 and 0.0 <= v["accuracy"] <= 1.0
    # measured on the exported graph, with the scene-bootstrap interval and visible-window figures
    assert v["measured_on"].startswith("the shipped float32 graph") and v["scenes"] == 3
    lo, hi = v["accuracy_95ci"]
    assert 0.0 <= lo <= v["accuracy"] <= hi <= 1.0
    labels = np.concatenate([np.load(f)["label"] for f in sorted(val.glob("shard-*.npz"))])
    assert v["visible"]["windows"] >= int((labels == 0).sum()) and v["accuracy_by_snr"]
    assert card["training"]["weight_average"] == {"ema_decay_per_step": 0.995, "exported": "last"}
    assert card["validation"]["epoch"] == 1
    assert out.with_suffix(".ckpt.pt").is_file()
    assert capsys.readouterr().out == ""  # nothing but data on stdout
    # an existing model is never overwritten without --force, and the check comes before training
    assert cli_code(args) == 1
    assert "exists" in capsys.readouterr().err


def test_train_on_two_folders(make_dataset, tmp_path, cli_code):
    a = make_dataset("count", 12)
    b = make_dataset("count", 8, seed=5, shards=1, name="more")
    out = tmp_path / "count.onnx"
    args = ["train", "count", "--data", str(a), "--data", str(b), "--val-fraction", "0.25", "--out", str(out),
            "--epochs", "1", "--batch-size", "4", "--threads", "1", "--ema", "0", "--superpose", "0.5"]
    assert cli_code(args) == 0
    card = read_card(out)
    assert card["training_data"]["windows"] == 20 and len(card["training_data"]["recipe"]) == 2
    assert card["training_data"]["dataset"] == [str(a), str(b)]
    assert card["training"]["augmentation"][0].startswith("superposition") and "--superpose 0.5" in card["training"]["command"]


def test_superpose_is_refused_for_activity(make_dataset, tmp_path, capsys, cli_code):
    data = make_dataset("activity", 8)
    args = ["train", "activity", "--data", str(data), "--out", str(tmp_path / "a.onnx"), "--superpose", "0.3"]
    assert cli_code(args) == 2
    assert "count only" in capsys.readouterr().err


def test_train_without_torch_says_how_to_install(monkeypatch, capsys, tmp_path, cli_code):
    monkeypatch.setitem(__import__("sys").modules, "torch", None)  # import torch -> ImportError
    assert cli_code(["train", "count", "--data", str(tmp_path), "--out", str(tmp_path / "m.onnx")]) == 1
    err = capsys.readouterr().err
    # wallcli is not on the index: the hint installs the extra's packages, or the checkout's extra
    assert err.startswith("Error:") and "pip install torch==2.13.0 && pip install '.[train]'" in err
    assert "wallcli[" not in err


@pytest.mark.slow
def test_int8_export_ships_a_quantised_graph_with_remeasured_accuracy(make_dataset, tmp_path, capsys, cli_code):
    pytest.importorskip("onnx")
    import onnx

    data = make_dataset("activity", 16)
    val = make_dataset("activity", 10, seed=4, shards=1, name="val")
    out = tmp_path / "act.onnx"
    args = ["train", "activity", "--data", str(data), "--val", str(val), "--out", str(out), "--epochs", "1",
            "--batch-size", "8", "--threads", "2", "--quantize", "int8"]
    assert cli_code(args) == 0
    card = read_card(out)
    assert card["sha256"] == sha256_file(out) and card["onnx"]["precision"] == "int8"
    # the closing line reports the shipped (int8) graph's accuracy, the one in the card
    err = " ".join(capsys.readouterr().err.split())  # rich may wrap the line
    assert err.endswith(f"validation accuracy {card['validation']['accuracy']:.1%} on 10 windows")
    q = card["onnx"]["quantization"]
    assert q["calibration_windows"] == 16 and "/Softmax" in q["float32_nodes"]
    assert 0.0 <= q["max_probability_change"] < 0.5 and 0.0 <= q["float32_accuracy"] <= 1.0
    assert card["validation"]["windows"] == 10 and "int8" in card["validation"]["measured_on"]
    ops = {n.op_type for n in onnx.load(str(out)).graph.node}
    assert "QuantizeLinear" in ops and "DequantizeLinear" in ops
    # 7-bit weights (no int16 saturation on AVX2), and every convolution still fused
    from wallcli.train.quantize import fused_convolutions, saturation_margin

    assert q["max_abs_weight"] == 64 and 0 < saturation_margin(onnx.load(str(out))) <= 64
    assert fused_convolutions(out) == (10, 0)
    # it runs through the normal inference path
    from wallcli.infer.model import Model

    m = Model.load(out, task="activity")
    x = np.random.default_rng(0).standard_normal((2, 3, 64, 256)).astype(np.float32)
    p = m.predict({"horizontal": x, "vertical": x})
    assert p.shape == (2, 5) and np.allclose(p.sum(1), 1, atol=1e-5)


def test_preprocessing_v2_is_trained_recorded_and_followed_at_inference(make_dataset, tmp_path, capsys, cli_code):
    from wallcli.infer.model import Model
    from wallcli.signal.window import NORMALIZATION_V2, normalize_window

    data = make_dataset("count", 12)
    val = make_dataset("count", 6, seed=9, shards=1, name="val", visibility=True)
    out = tmp_path / "count.onnx"
    args = ["train", "count", "--data", str(data), "--val", str(val), "--out", str(out), "--epochs", "1",
            "--batch-size", "4", "--threads", "1", "--preprocessing", "v2"]
    assert cli_code(args) == 0
    card = read_card(out)
    assert card["preprocessing"] == NORMALIZATION_V2 and "asinh" in card["normalisation"]
    assert "--preprocessing v2" in card["training"]["command"]
    m = Model.load(out)
    x = np.random.default_rng(0).normal(size=(2, 64, 256, 3)).astype(np.float32)
    assert np.array_equal(m.normalize(x), normalize_window(x, NORMALIZATION_V2))
    # the card's validation was measured with v2 inputs: scoring them again gives its figure
    labels = np.concatenate([np.load(f)["label"] for f in sorted(val.glob("shard-*.npz"))])
    raw = np.concatenate([np.load(f)["horizontal"] for f in sorted(val.glob("shard-*.npz"))])
    assert np.mean(m.predict({"horizontal": m.normalize(raw)}).argmax(1) == labels) == card["validation"]["accuracy"]
    # a v1 checkpoint is not resumed into a v2 run (the inputs differ), and unknown versions are refused
    assert cli_code([*args[:-2], "--preprocessing", "v1", "--force"]) == 1
    assert "different run" in capsys.readouterr().err
    assert cli_code([*args[:-2], "--preprocessing", "v9", "--force"]) == 2
