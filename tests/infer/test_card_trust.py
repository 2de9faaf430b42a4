"""A card's thresholds and validation figures are bound to what was measured (issue 62 point 12):
a card edited after it was sealed, or never sealed, is an "unvalidated card" whose answers are all
undetermined with that reason and whose figures are not quoted; resealing (what `wallcli train`
does when it writes a card) makes its thresholds count again."""
from __future__ import annotations

import json
import shutil
from pathlib import Path

import pytest

from wallcli.infer.model import shipped_model_path

WALKING = Path(__file__).resolve().parents[2] / "examples" / "walking.mp4"


def _copy(tmp_path, task="count") -> Path:
    src = shipped_model_path(task)
    for ext in (".onnx", ".json"):
        shutil.copy(src.with_suffix(ext), tmp_path / f"{task}{ext}")
    return tmp_path / f"{task}.onnx"


def _edit(model: Path, change) -> None:
    card = json.loads(model.with_suffix(".json").read_text())
    change(card)
    model.with_suffix(".json").write_text(json.dumps(card, indent=2))


def _zero_thresholds(card):
    card["two_stage"]["confidence"]["thresholds"] = [[0, 0, 0]] * 3


def test_the_shipped_cards_are_sealed():
    from wallcli.infer.model import Model
    from wallcli.infer.trust import problem

    for task in ("count", "activity"):
        card = json.loads(shipped_model_path(task).with_suffix(".json").read_text())
        assert card["trust"]["sha256"] and problem(card) is None, task
        assert Model.load(shipped_model_path(task), task=task).unvalidated is None


def test_zeroed_thresholds_in_a_copied_card_decide_nothing(tmp_path, run_cli):
    model = _copy(tmp_path)
    _edit(model, _zero_thresholds)
    code, out, err = run_cli("count", WALKING, "--model", model, "--json", "-v")
    assert code == 0, err
    res = json.loads(out)
    assert res["label"] == 1 and res["confident"] is False and res["reason"].startswith("unvalidated card")
    assert all(not w["confident"] and w["reason"].startswith("unvalidated card") for w in res["windows"])
    assert "unvalidated card" in err and "right on" not in err  # -v quotes none of its figures
    code, out, err = run_cli("count", WALKING, "--model", model)
    assert "decided" not in out and "in validation" not in out and "unvalidated card" in out


def test_resealing_makes_the_thresholds_count_again(tmp_path, run_cli):
    from wallcli.infer.trust import main

    model = _copy(tmp_path)
    _edit(model, _zero_thresholds)
    assert main([str(model.with_suffix(".json"))]) == 0
    code, out, err = run_cli("count", WALKING, "--model", model, "--json")
    assert code == 0, err
    assert json.loads(out)["confident"] is True  # the zeros, now vouched for by whoever resealed them
    assert main(["--help"]) == 2 and main([str(tmp_path / "none.json")]) == 1


@pytest.mark.parametrize("change", [
    lambda c: c["transfer"].update(accuracy=0.99),  # a quoted figure
    lambda c: c.pop("trust"),  # no seal at all
    lambda c: c["trust"].update(format="other"),  # a seal of another kind
    lambda c: c.update(stride=32),  # the answers it was measured on were made otherwise
])
def test_any_change_to_a_trust_field_or_the_seal_unvalidates(tmp_path, change):
    from wallcli.infer.model import Model

    model = _copy(tmp_path, "activity")
    _edit(model, change)
    assert Model.load(model, task="activity").unvalidated.startswith("unvalidated card")


def test_re_indenting_or_fields_outside_the_seal_change_nothing(tmp_path):
    from wallcli.infer.model import Model

    model = _copy(tmp_path, "activity")
    card = json.loads(model.with_suffix(".json").read_text())
    card["notes"] = "a note beside the figures"
    model.with_suffix(".json").write_text(json.dumps(dict(reversed(card.items())), indent=None))
    assert Model.load(model, task="activity").unvalidated is None


def test_an_activity_answer_checked_by_an_edited_count_card_is_unvalidated(tmp_path, run_cli):
    count = _copy(tmp_path)
    _edit(count, lambda c: c["two_stage"].update(prior_two_vs_one=0.001))
    from wallcli.infer.model import Model
    from wallcli.infer.twostage import OnePersonActivity

    act = Model.load(shipped_model_path("activity"), task="activity")
    assert OnePersonActivity(act, Model.load(count, task="count")).unvalidated.startswith("unvalidated card")
    assert OnePersonActivity(act, Model.load(shipped_model_path("count"), task="count")).unvalidated is None


def test_the_report_shows_no_figure_of_an_unvalidated_card(tmp_path):
    from wallcli.infer.model import Model
    from wallcli.report.cards import model_summary

    model = _copy(tmp_path)
    shown = model_summary(Model.load(model, task="count"))
    assert shown["transfer"] and not any("unvalidated" in x for x in shown["limits"])
    _edit(model, _zero_thresholds)
    shown = model_summary(Model.load(model, task="count"))
    assert not shown["transfer"] and not shown["simulated"] and not shown["by_snr"]
    assert shown["limits"][0].startswith("Unvalidated card:")
