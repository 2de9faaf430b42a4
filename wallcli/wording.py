"""How figures and answers are written for people, the same in tables, reasons and pages.

A decibel figure: one decimal, and never "-0.0". JSON keeps more digits. Every table, reason and page writes this rounding of the JSON's own value,
so one figure reads the same wherever it appears (a reason saying "19 dB" beside a ``signal_db``
of 18.6 looked like a second measurement). What each dB figure measures: docs/outputs.md, "Which SNR is
which".
"""
from __future__ import annotations

import math

# What count counts, said the same way in the README, `count --help` and every simulated clip's
# truth file (whose 'people' counts everyone in the room)
COUNT_COUNTS = "count counts the people who move: a person standing still counts 0"


# evaluate's by_band names (CONTRACT.md: "empty", "<0 dB", ...) as its table and figure say them.
# "empty" holds every clip where nobody moves, a person standing still included (standing.mp4):
# "empty rooms" said otherwise of a room with a person in it.
BAND_TEXT = {"empty": "nobody moving", "<0 dB": "under 0 dB", "0-10 dB": "0-10 dB", ">=10 dB": "10 dB and over",
             "not measured": "SNR unknown"}


def format_db(x) -> str:
    """``x`` dB as text: '12.3', '0.0' (for -0.04 too), '-' when there is no finite number."""
    try:
        v = float(x)
    except (TypeError, ValueError):
        return "-"
    if not math.isfinite(v):
        return "-"
    text = f"{v:.1f}"
    return "0.0" if text == "-0.0" else text


def span_text(a: float, b: float) -> str:
    """A time span as it reads: '0.6-1.4 s', or '0.6 s' when both ends round alike ('0.6-0.6 s'
    read as a range of nothing)."""
    lo, hi = f"{a:.1f}", f"{b:.1f}"
    return f"{lo} s" if lo == hi else f"{lo}-{hi} s"


def plural(n: int, word: str, words: str | None = None) -> str:
    """'1 video', '2 videos' ('1 person', '3 people' with ``words``)."""
    return f"{n} {word if n == 1 else (words or word + 's')}"


def frames_text(decoded: int, corrections=None) -> str:
    """A clip's frames as every command says them: the frames decoded, and the repeats among them
    left out of the analysis (the ``duplicates`` correction): '360 frames (1 repeat left out)'."""
    dups = sum(int(c.get("frames") or 0) for c in corrections or () if c.get("kind") == "duplicates")
    return f"{plural(int(decoded), 'frame')}" + (f" ({plural(dups, 'repeat')} left out)" if dups else "")


def label_text(label) -> str:
    """An answer as words: count's 1 -> '1 person', 0 -> '0 people'; activity's labels as they are."""
    if isinstance(label, int) and not isinstance(label, bool):
        return f"{label} {'person' if label == 1 else 'people'}"
    return str(label)


def answer_text(result: dict) -> str:
    """A clip's answer as a title states it, in words: '1 person (decided, p=0.97)', or
    'undetermined (most likely 1 person, p=0.75)' when it may not be relied upon; the same words
    over a table and over a figure. A title starts with the answer ('count = 1'), for grep."""
    p = max(result["probabilities"])
    said = label_text(result["label"])
    confident = result.get("confident")
    if confident is None:  # a result that was never judged: no claim either way
        return f"{said} (p={p:.2f})"
    if confident:
        return f"{said} (decided, p={p:.2f})"
    return f"undetermined (most likely {said}, p={p:.2f})"


# -- the trust rule, worded once: every reason, note and page takes its figure from the card's
# confidence level (``level``), so the figure follows whatever card ships

def level_text(level) -> str:
    """A card's confidence level as a figure: 0.97 -> '97 %', 0.975 -> '97.5 %'."""
    return f"{float(level) * 100:.1f}".rstrip("0").rstrip(".") + " %"


def not_often_enough(what: str, signal_db, level, band: str) -> str:
    """Why an answer whose cell of the card has no threshold is not decided."""
    return (f"'{what}' at signal {format_db(signal_db)} dB: answers like this were not right often enough in "
            f"validation to be relied on ({level_text(level)} needed; {band})")


def under_threshold(p: float, what: str, signal_db, level, t: float) -> str:
    """Why an answer under its cell's threshold is not decided."""
    return (f"p={p:.3f} for '{what}' at signal {format_db(signal_db)} dB: answers like this were right "
            f"{level_text(level)} of the time in validation only from p={t:.3f}")


def decided_text(level) -> str:
    """What a decided answer means, in words (tables, pages)."""
    if level is None:
        return "decided"
    return f"decided: answers like this were right at least {level_text(level)} of the time in validation"


# the report's words for a view note: a change of light on the wall is no fault of the view (the
# contract), so the note is said beside the answers, not as a warning that they were refused
VIEW_NOTE = "also seen, and analysed (no fault of the view)"


def view_note_lines(view) -> list[str]:
    """One line per note of the view check (``view.notes``), for under a terminal table."""
    notes = view.get("notes") if isinstance(view, dict) else None
    return [f"{VIEW_NOTE}: {n}." for n in notes or []]
