"""research/evaluate.py --record: a second validation set's figures go into the card, nothing else."""
from __future__ import annotations

import importlib.util
import json
import shutil
from pathlib import Path

import numpy as np

from wallcli.infer.card import card_path, sha256_file
from wallcli.infer.model import shipped_model_path

ROOT = Path(__file__).resolve().parents[2]


def _evaluate_module():
    spec = importlib.util.spec_from_file_location("wallcli_research_evaluate", ROOT / "research" / "evaluate.py")
    mod = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(mod)
    return mod


def test_record_stores_the_figures_per_seed_and_leaves_the_model_alone(make_dataset, tmp_path):
    ev = _evaluate_module()
    model = tmp_path / "count.onnx"
    shutil.copyfile(shipped_model_path("count"), model)
    shutil.copyfile(card_path(shipped_model_path("count")), card_path(model))
    before = json.loads(card_path(model).read_text())
    digest = sha256_file(model)

    a = make_dataset("count", 12, seed=31, shards=1, name="a", visibility=True)
    r = ev.evaluate("count", str(a), str(model))
    ev.record("count", str(a), str(model), r)
    card = json.loads(card_path(model).read_text())
    shipped = [o["seed"] for o in before["validation"].get("other_sets", [])]
    assert 31 not in shipped and 5 not in shipped
    (entry,) = [o for o in card["validation"]["other_sets"] if o["seed"] == 31]
    assert [o["seed"] for o in card["validation"]["other_sets"]] == sorted(shipped + [31])
    assert entry["seed"] == 31 and entry["windows"] == 12 == r["windows"]
    assert entry["accuracy"] == r["accuracy"] and entry["visible"]["accuracy"] == r["visible"]["accuracy"]
    assert np.array(entry["confusion_matrix"]).sum() == 12
    # the card's own validation figures and the model are untouched
    assert {k: v for k, v in card["validation"].items() if k != "other_sets"} == \
        {k: v for k, v in before["validation"].items() if k != "other_sets"}
    assert sha256_file(model) == digest == card["sha256"]

    # measured again on the same seed: replaced, not appended; another seed is added, in seed order
    ev.record("count", str(a), str(model), r)
    b = make_dataset("count", 8, seed=5, shards=1, name="b", visibility=True)
    ev.record("count", str(b), str(model), ev.evaluate("count", str(b), str(model)))
    card = json.loads(card_path(model).read_text())
    assert [o["seed"] for o in card["validation"]["other_sets"]] == sorted(shipped + [5, 31])

    from wallcli.cli._classify import accuracy_note

    assert accuracy_note(card).count("on another set") == len(shipped) + 2
