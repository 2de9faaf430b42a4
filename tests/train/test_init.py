"""Fine-tuning from an exported model: `wallcli train --init MODEL.onnx`."""
import json

import numpy as np
import pytest

torch = pytest.importorskip("torch")
pytest.importorskip("onnx")

from wallcli.errors import WallcliError  # noqa: E402
from wallcli.infer.card import read_card, sha256_file  # noqa: E402
from wallcli.train.export import export_model  # noqa: E402
from wallcli.train.init import init_from_onnx  # noqa: E402
from wallcli.train.nets import build  # noqa: E402

FIELDS = dict(name="t", version="0.0.1", training_data={"recipe": {}}, training={"seed": 0}, validation=None)


def _trained(task, seed=0):
    """A net whose batch norms hold real (non-default) statistics and parameters."""
    torch.manual_seed(seed)
    net = build(task)
    xs = [torch.randn(8, 3, 64, 256) * 2 + 0.5 for _ in net.input_names]
    opt = torch.optim.SGD(net.parameters(), lr=0.05)
    net.train()
    for _ in range(3):
        opt.zero_grad()
        net(*xs).logsumexp(1).mean().backward()
        opt.step()
    return net.eval()


@pytest.mark.slow
@pytest.mark.parametrize("task", ["count", "activity"])
def test_init_reproduces_an_exported_float_model(tmp_path, task):
    ref = _trained(task)
    out = tmp_path / "m.onnx"
    export_model(ref, list(ref.input_names), out, dict(FIELDS, task=task, classes=ref.classes))
    calib = [torch.randn(16, 3, 64, 256) for _ in ref.input_names]
    xs = [torch.randn(16, 3, 64, 256) for _ in ref.input_names]  # other windows of the same kind
    net = build(task)
    init_from_onnx(net, out, calib)
    net.eval()
    with torch.no_grad():
        want, got = ref(*xs), net(*xs)
        # train mode (batch statistics) starts close to eval mode on windows it was not calibrated on
        net.train()
        got_train = torch.softmax(net(*xs), 1)
    assert torch.allclose(got, want, atol=1e-4)
    assert (got_train - torch.softmax(want, 1)).abs().max() < 0.05


def test_init_rejects_a_model_of_another_task(tmp_path):
    ref = _trained("count")
    out = tmp_path / "c.onnx"
    export_model(ref, ["horizontal"], out, dict(FIELDS, task="count", classes=ref.classes))
    with pytest.raises(WallcliError, match="does not match|has 5 convolutions|not a"):
        init_from_onnx(build("activity"), out, [torch.randn(2, 3, 64, 256)] * 2)


def test_train_init_fine_tunes_and_records_the_base_model(make_dataset, tmp_path, capsys, cli_code):
    data = make_dataset("count", 16)
    val = make_dataset("count", 6, seed=9, shards=1, name="val", visibility=True)
    base = tmp_path / "base.onnx"
    args = ["train", "count", "--data", data, "--val", val, "--epochs", "1", "--batch-size", "8", "--threads", "1",
            "--quantize", "int8"]
    assert cli_code([*args, "--out", base]) == 0
    tuned = tmp_path / "tuned.onnx"
    assert cli_code([*args, "--out", tuned, "--init", base, "--lr", "1e-4", "--anneal", "1"]) == 0
    card = read_card(tuned)
    assert card["training"]["init"]["sha256"] == sha256_file(base)
    assert card["training"]["lr"] == 1e-4 and "--init" in card["training"]["command"]
    assert "--lr 0.0001" in card["training"]["command"]
    capsys.readouterr()
    # an activity model cannot start a count run
    act = make_dataset("activity", 8, name="act")
    a = tmp_path / "a.onnx"
    assert cli_code(["train", "activity", "--data", act, "--out", a, "--epochs", "1", "--batch-size", "4",
                 "--threads", "1", "--val-fraction", "0.25"]) == 0
    assert cli_code([*args, "--out", tmp_path / "x.onnx", "--init", a]) == 2
    assert "activity" in capsys.readouterr().err


@pytest.mark.parametrize("task", ["count", "activity"])
def test_init_from_the_shipped_int8_model_computes_what_onnxruntime_does(task):
    import onnxruntime as ort

    from wallcli.infer.model import shipped_model_path
    from wallcli.signal.window import normalize_window

    rng = np.random.default_rng(0)
    net = build(task)
    feeds = {n: normalize_window(rng.standard_normal((16, 64, 256, 3)).astype(np.float32)) for n in net.input_names}
    xs = [torch.from_numpy(np.ascontiguousarray(feeds[n])) for n in net.input_names]
    init_from_onnx(net, shipped_model_path(task), xs)
    with torch.no_grad():
        got = torch.softmax(net.eval()(*xs), 1).numpy()
    want = ort.InferenceSession(str(shipped_model_path(task)), providers=["CPUExecutionProvider"]).run(None, feeds)[0]
    # float weights and activations against the int8 graph's rounded ones
    assert np.abs(got - want).max() < 0.02 and (got.argmax(1) == want.argmax(1)).mean() >= 0.9
