"""What `wallcli train` writes is sealed (issue 62 point 12): the exported card, and the card whose
thresholds and figures the recordings step refits, load as validated cards, not unvalidated ones."""
from __future__ import annotations

import json
import shutil

import pytest

torch = pytest.importorskip("torch")
pytest.importorskip("onnx")

from wallcli.infer.model import Model, shipped_model_path  # noqa: E402
from wallcli.infer.trust import problem  # noqa: E402


def test_an_exported_card_is_sealed(tmp_path):
    from wallcli.train.export import export_model
    from wallcli.train.nets import build

    torch.manual_seed(0)
    net = build("count").eval()
    out = tmp_path / "c.onnx"
    card = export_model(net, ["horizontal"], out, dict(name="t", version="0.0.1", task="count", classes=[0, 1, 2],
                                                       training_data={"recipe": {}}, training={"seed": 0},
                                                       validation=None))
    assert card["trust"]["sha256"] and problem(json.loads(out.with_suffix(".json").read_text())) is None
    assert Model.load(out, task="count").unvalidated is None


def test_the_recordings_step_reseals_what_it_refits(tmp_path):
    from wallcli.cli._train_clips import write_block

    src = shipped_model_path("activity")
    out = tmp_path / "a.onnx"
    shutil.copy(src, out)
    shutil.copy(src.with_suffix(".json"), out.with_suffix(".json"))
    trust = {"format": "wallcli.confidence v1", "level": 0.9, "signal_edges_db": [0.0],
             "thresholds": [[None] * 5, [None, 0.5, 0.5, 0.5, 0.5]]}
    card = write_block(out, {"clips": 3, "confidence": trust})
    assert card["confidence"]["thresholds"][1][1] == 0.5 and card["recordings"] == {"clips": 3}
    assert problem(card) is None and Model.load(out, task="activity").unvalidated is None
