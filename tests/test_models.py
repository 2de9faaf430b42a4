"""The shipped models: golden outputs on a seeded clip through the whole run-time path.

(How they fare on the bundled examples: tests/test_examples.py.)"""

import json
from pathlib import Path

import numpy as np
import pytest

GOLDEN = Path(__file__).resolve().parent / "golden"


@pytest.fixture(scope="module")
def golden_clip(tmp_path_factory):
    from wallcli.cli.app import main

    clip = tmp_path_factory.mktemp("golden") / "golden.mp4"
    spec = json.loads((GOLDEN / "count.json").read_text())["clip"]
    try:
        main(["simulate", "-o", str(clip), *spec])
    except SystemExit as exc:
        assert exc.code in (0, None)
    return clip


@pytest.mark.slow
@pytest.mark.parametrize("task", ["count", "activity"])
def test_golden_outputs(task, golden_clip, run_cli):
    golden = json.loads((GOLDEN / f"{task}.json").read_text())
    code, out, err = run_cli(task, golden_clip, "--json")
    assert code == 0, err
    r = json.loads(out)
    assert r["model"]["sha256"] == golden["sha256"], "the shipped model changed: run tests/golden/make_golden.py"
    assert r["label"] == golden["label"]
    assert [w["start"] for w in r["windows"]] == pytest.approx([w["start"] for w in golden["windows"]], abs=1e-6)
    got = np.array([w["probabilities"] for w in r["windows"]])
    want = np.array([w["probabilities"] for w in golden["windows"]])
    assert np.allclose(got, want, atol=1e-4)


@pytest.mark.parametrize("task", ["count", "activity"])
def test_corrupt_plot_file(tmp_path, run_cli, task):
    bad = tmp_path / "plots.npz"
    bad.write_bytes(b"PK\x03\x04 not really a zip")
    code, out, err = run_cli(task, bad, "--json")
    assert code == 1 and out == ""
    assert len(err.strip().splitlines()) == 1 and err.startswith("Error:") and "npz" in err


@pytest.mark.parametrize("task", ["count", "activity"])
def test_shipped_cards_carry_the_measured_accuracy_and_the_table_says_it(task, golden_clip, run_cli):
    card = json.loads((Path(__file__).resolve().parents[1] / "models" / f"{task}.json").read_text())
    v = card["validation"]
    vis = v["visible"]
    assert v["scenes"] < v["windows"] and vis["windows"] < v["windows"]
    for block in (v, vis):
        lo, hi = block["accuracy_95ci"]
        assert lo <= block["accuracy"] <= hi
    assert np.array(vis["confusion_matrix"]).sum() == vis["windows"]
    # what users meet first: the figures on the independent renderer's clips, beside the simulator's
    tr = card["transfer"]
    assert tr["scored"] == sum(map(sum, tr["confusion"])) and tr["ci95"][0] <= tr["accuracy"] <= tr["ci95"][1]
    assert 0 <= tr["coverage"] <= 1 and tr["decided"] == round(tr["coverage"] * tr["scored"])
    # the decided/undetermined thresholds are fitted on the recordings, out of fold (a two-stage
    # count's on its pair's answers), and the card says how many clips back them
    trust = card["two_stage"]["confidence"] if task == "count" else card["confidence"]
    assert "out-of-fold answers on" in trust["fitted_on"] and trust["level"] >= 0.97
    rec = card["recordings"]
    assert rec["folds"] == 5 and rec["out_of_fold"]["detectable"]["clips"] == tr["scored"]
    assert rec["out_of_fold"]["detectable"]["right"] == round(tr["accuracy"] * tr["scored"])
    assert rec["candidates_compared"]["count"] >= 1
    code, out, err = run_cli(task, golden_clip, "-v")  # the card's figures, for a reader who asks
    assert code == 0, err
    said = " ".join(err.split())  # the note is wrapped to the terminal's width
    assert f"right on {tr['accuracy']:.0%} (95 % CI {tr['ci95'][0]:.0%}" in said and "independent renderer" in said
    assert "right on" not in out  # the note is for the reader, on stderr


@pytest.mark.parametrize("task", ["count", "activity"])
def test_shipped_graphs_take_any_batch_at_opset_17_or_later(task):
    """What the issue asks of a shipped network: ONNX opset >= 17, a dynamic batch axis, the inputs
    its card names; and it gives one distribution per window for batches of 1 and 5."""
    onnx = pytest.importorskip("onnx")
    from wallcli.infer.model import load_model, shipped_model_path

    graph = onnx.load(str(shipped_model_path(task)))
    assert max(o.version for o in graph.opset_import if o.domain in ("", "ai.onnx")) >= 17
    names = [i.name for i in graph.graph.input]
    model = load_model(task)
    assert names == model.input_names
    for i in graph.graph.input:
        assert not i.type.tensor_type.shape.dim[0].HasField("dim_value")  # batch is symbolic
    rng = np.random.default_rng(0)
    for n in (1, 5):
        p = model.predict({k: rng.standard_normal((n, 3, 64, 256)).astype(np.float32) for k in names})
        assert p.shape == (n, len(model.classes)) and np.allclose(p.sum(axis=1), 1, atol=1e-5)


@pytest.mark.parametrize("task", ["count", "activity"])
def test_shipped_int8_models_compute_the_same_on_every_x86_cpu(task):
    """x86 u8s8 kernels without VNNI add pairs of products into a saturating int16 (8-bit weights
    gave the waving example another answer on AVX2 than on AVX-512 VNNI): the shipped weights stay
    within |w| <= 64, and onnxruntime still runs every convolution as QLinearConv (not float)."""
    onnx = pytest.importorskip("onnx")
    from wallcli.infer.model import shipped_model_path
    from wallcli.train.quantize import MAX_WEIGHT, fused_convolutions, saturation_margin

    path = shipped_model_path(task)
    model = onnx.load(str(path))
    convs = sum(n.op_type == "Conv" for n in model.graph.node)
    assert convs == {"count": 5, "activity": 10}[task]
    assert 0 < saturation_margin(model) <= MAX_WEIGHT
    assert fused_convolutions(path) == (convs, 0)


@pytest.mark.parametrize("task", ["count", "activity"])
def test_documented_confusion_matrices_are_the_shipped_cards(task):
    """docs/models.md's matrices ('visible / all' per cell) are the cards', for the shipped version."""
    root = Path(__file__).resolve().parents[1]
    card = json.loads((root / "models" / f"{task}.json").read_text())
    lines = (root / "docs" / "models.md").read_text().splitlines()
    head = next(i for i, line in enumerate(lines) if line.startswith(f"| {task} {card['version']} |"))
    rows = [line.strip("|").split("|")[1:] for line in lines[head + 2: head + 2 + len(card["classes"])]]
    vis = [[int(c.split("/")[0]) for c in r] for r in rows]
    every = [[int(c.split("/")[1]) for c in r] for r in rows]
    assert vis == card["validation"]["visible"]["confusion_matrix"]
    assert every == card["validation"]["confusion_matrix"]
