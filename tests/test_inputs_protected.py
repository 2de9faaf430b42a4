"""--force replaces an earlier output, never an input: labels.csv, sidecars, models and their cards,
a dataset's manifest, by any name (a symbolic link included). Issue 38, item 1."""
import json
import os

import numpy as np
import pytest
from clips import write_clip

from wallcli.errors import WallcliError
from wallcli.io.writer import check_output, read_with


def _wall(i):
    return np.full((48, 64, 3), 120.0) + np.random.default_rng(i).normal(0, 1.0, (48, 64, 3))


@pytest.fixture
def clip(tmp_path):
    return write_clip(tmp_path / "c.mkv", _wall, 12, fps=30, codec="ffv1", pix_fmt="bgr0", options={})


def test_a_model_brings_its_card(tmp_path):
    m = tmp_path / "m.onnx"
    assert read_with([m, None, "-", "http://x/y.mp4"]) == [m, tmp_path / "m.json"]
    with pytest.raises(WallcliError, match="is the input"):
        check_output(tmp_path / "m.json", force=True, inputs=[m])


def test_evaluate_plot_over_labels_csv(tmp_path, run_cli, clip):
    labels = tmp_path / "labels.csv"
    labels.write_text("file,people,activity\nc.mkv,0,none\n")
    before = labels.read_bytes()
    code, _, err = run_cli("evaluate", tmp_path, "--task", "count", "--plot", labels, "--force")
    # refused before anything is written: a figure's name must end in .png
    assert code == 2 and ".png" in err and labels.read_bytes() == before


def test_evaluate_plot_over_a_sidecar(tmp_path, run_cli, clip):
    side = tmp_path / "c.json"
    side.write_text(json.dumps({"people": 0, "activity": "none"}))
    before = side.read_bytes()
    link = tmp_path / "plot.png"  # a figure's name must say .png: reach the sidecar through a link
    link.symlink_to(side)
    code, _, err = run_cli("evaluate", tmp_path, "--task", "count", "--plot", link, "--force")
    assert code == 1 and "is the input" in err and side.read_bytes() == before


def test_evaluate_plot_through_a_link_to_labels(tmp_path, run_cli, clip):
    labels = tmp_path / "labels.csv"
    labels.write_text("file,people,activity\nc.mkv,0,none\n")
    out = tmp_path / "out"
    out.mkdir()
    (out / "fig.png").symlink_to(labels)
    code, _, err = run_cli("evaluate", tmp_path, "--task", "count", "--plot", out / "fig.png", "--force")
    assert code == 1 and "is the input" in err and labels.read_text().startswith("file,")


def test_count_plot_over_the_model_card(tmp_path, run_cli, clip):
    model, card = tmp_path / "m.onnx", tmp_path / "m.json"
    model.write_bytes(b"not a model")
    card.write_text("{}")
    link = tmp_path / "plot.png"  # a figure's name must say .png: reach the card through a link
    link.symlink_to(card)
    code, _, err = run_cli("count", clip, "--model", model, "--plot", link, "--force")
    assert code == 1 and "is the input" in err and card.read_text() == "{}"


def test_count_plot_over_the_shipped_card(tmp_path, run_cli, clip):
    from wallcli.infer.model import shipped_model_path

    card = shipped_model_path("count").with_suffix(".json")
    link = tmp_path / "p.png"
    link.symlink_to(card)
    before = card.read_bytes()
    code, _, err = run_cli("count", clip, "--plot", link, "--force")
    assert code == 1 and "is the input" in err and card.read_bytes() == before


def test_report_through_a_link_to_the_card(tmp_path, run_cli, clip):
    model, card = tmp_path / "m.onnx", tmp_path / "m.json"
    model.write_bytes(b"not a model")
    card.write_text("{}")
    (tmp_path / "r.html").symlink_to(card)
    code, _, err = run_cli("report", clip, "--count-model", model, "-o", tmp_path / "r.html", "--force")
    assert code == 1 and "is the input" in err and card.read_text() == "{}"


def test_train_card_over_the_dataset_manifest(tmp_path, run_cli):
    pytest.importorskip("torch")
    data = tmp_path / "data"
    data.mkdir()
    (data / "dataset.json").write_text('{"format": "x"}')
    code, _, err = run_cli("train", "count", "--data", data, "--out", data / "dataset.onnx", "--force")
    assert code == 1 and "is the input" in err and (data / "dataset.json").read_text() == '{"format": "x"}'


def test_train_checkpoint_over_the_manifest(tmp_path, run_cli):
    pytest.importorskip("torch")
    data = tmp_path / "data"
    data.mkdir()
    (data / "dataset.json").write_text('{"format": "x"}')
    code, _, err = run_cli("train", "count", "--data", data, "--out", tmp_path / "m.onnx",
                           "--checkpoint", data / "dataset.json")
    assert code == 1 and "is the input" in err and (data / "dataset.json").read_text() == '{"format": "x"}'
    assert not os.path.exists(tmp_path / "m.onnx")
