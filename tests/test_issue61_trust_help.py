"""Issue 61.2: 'Rely on decided answers only' while the shipped cards decide nothing. The help of
count and activity says what holds today, read from the shipped card, and -v no longer tells the
reader to rely on answers that never come."""
from __future__ import annotations

import json
from pathlib import Path

import pytest

from wallcli.cli._classify import accuracy_note, decides_nothing

MODELS = Path(__file__).resolve().parents[1] / "models"


@pytest.mark.parametrize("task", ["count", "activity"])
def test_help_says_nothing_is_decided_while_the_card_decides_nothing(task, run_cli):
    card = json.loads((MODELS / f"{task}.json").read_text())
    assert decides_nothing(card)  # today's shipped cards: every threshold null
    code, out, _ = run_cli(task, "--help")
    said = " ".join(out.split())
    assert code == 0 and "Today no answer is decided" in said and "best guess" in said


def test_verbose_note_follows_the_card():
    card = json.loads((MODELS / "count.json").read_text())
    note = accuracy_note(card)
    assert "Rely on decided answers only" not in note and "No answer is decided today" in note
    # a card with one threshold can decide: then, and only then, the note says to rely on decided answers
    block = card["two_stage"]["confidence"]
    block["thresholds"][2][1] = 0.9
    assert not decides_nothing(card)
    assert "Rely on decided answers only" in accuracy_note(card)
