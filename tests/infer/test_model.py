import json
import shutil

import numpy as np
import pytest

from wallcli.errors import WallcliError
from wallcli.infer.card import card_path, sha256_file
from wallcli.infer.model import Model, load_model, shipped_model_path


def _copy(src, dst_dir, name=None):
    dst = dst_dir / (name or src.name)
    shutil.copy(src, dst)
    shutil.copy(card_path(src), card_path(dst))
    return dst


def test_session_is_lazy_and_threads_apply(models):
    m = Model.load(models["count"], task="count", threads=1)
    assert m._session is None
    p = m.predict({"horizontal": np.zeros((3, 3, 64, 256), np.float32)})
    assert p.shape == (3, 3) and np.allclose(p.sum(1), 1)
    assert m.session.get_session_options().intra_op_num_threads == 1


def test_tampered_model_is_refused(models, tmp_path, run_cli, plot_file):
    bad = _copy(models["count"], tmp_path)
    data = bytearray(bad.read_bytes())
    data[-10] ^= 0xFF
    bad.write_bytes(bytes(data))
    with pytest.raises(WallcliError, match="does not match its card"):
        Model.load(bad)
    code, out, err = run_cli("count", plot_file(), "--model", bad, "--json")
    assert code == 1 and out == "" and err.startswith("Error:") and "sha256" in err


def test_card_edited_sha_is_refused(models, tmp_path):
    m = _copy(models["count"], tmp_path)
    card = json.loads(card_path(m).read_text())
    card["sha256"] = "0" * 64
    card_path(m).write_text(json.dumps(card))
    with pytest.raises(WallcliError, match="does not match"):
        Model.load(m)


def test_wrong_card_for_the_model(models, tmp_path):
    # the activity card, re-signed for the count graph: the graph's inputs do not match it
    m = _copy(models["count"], tmp_path)
    card = json.loads(card_path(models["activity"]).read_text())
    card["sha256"] = sha256_file(m)
    card_path(m).write_text(json.dumps(card))
    model = Model.load(m)
    with pytest.raises(WallcliError, match="wrong card"):
        model.session


def test_card_with_other_classes_is_refused(models, tmp_path):
    m = _copy(models["count"], tmp_path)
    card = json.loads(card_path(m).read_text())
    card["classes"] = [0, 1, 2, 3]
    card_path(m).write_text(json.dumps(card))
    with pytest.raises(WallcliError, match=r"count model's classes are \[0, 1, 2\]"):  # on load (issue 55)
        Model.load(m).session


def test_model_of_the_other_task_is_refused(models, run_cli, plot_file):
    code, out, err = run_cli("activity", plot_file(), "--model", models["count"])
    assert code == 1 and "'count' model" in err and "'activity'" in err


def test_missing_or_broken_card(models, tmp_path):
    m = tmp_path / "lonely.onnx"
    shutil.copy(models["count"], m)
    with pytest.raises(WallcliError, match="card not found"):
        Model.load(m)
    card_path(m).write_text("{not json")
    with pytest.raises(WallcliError, match="not valid JSON"):
        Model.load(m)
    card = json.loads(card_path(models["count"]).read_text())
    card["preprocessing"] = "something else v9"
    card_path(m).write_text(json.dumps(card))
    with pytest.raises(WallcliError, match="preprocessing"):
        Model.load(m)


def test_wrong_input_shape_is_a_clear_error(models):
    m = Model.load(models["activity"])
    x = np.zeros((2, 3, 64, 128), np.float32)
    with pytest.raises(WallcliError, match=r"expects \(N, 3, 64, 256\)"):
        m.predict({"horizontal": x, "vertical": x})
    with pytest.raises(WallcliError, match="needs input 'vertical'"):
        m.predict({"horizontal": np.zeros((2, 3, 64, 256), np.float32)})


def test_shipped_model_is_found_or_reported_missing():
    p = shipped_model_path("count")
    assert p.name == "count.onnx"
    if p.is_file():
        assert load_model("count").task == "count"
    else:
        with pytest.raises(WallcliError, match="shipped count model is missing"):
            load_model("count")
