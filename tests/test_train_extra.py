"""train without its optional extra: one clear line before any work, never an import error at export."""
import importlib.util

import pytest


@pytest.mark.parametrize("missing", [("onnx",), ("torch",), ("torch", "onnx")])
def test_train_names_what_is_missing_before_it_starts(run_cli, monkeypatch, tmp_path, missing):
    real = importlib.util.find_spec
    monkeypatch.setattr(importlib.util, "find_spec", lambda name, *a: None if name in missing else real(name, *a))
    code, out, err = run_cli("train", "count", "--data", tmp_path / "nothing", "--out", tmp_path / "m.onnx")
    assert code != 0 and out == ""
    first = err.strip().splitlines()[0]
    assert "training needs" in first and "not installed" in first and "Traceback" not in err
    for name in missing:
        assert {"torch": "PyTorch", "onnx": "onnx"}[name] in first
    assert "pip install" in err  # the hint says how
    assert not (tmp_path / "m.onnx").exists()
