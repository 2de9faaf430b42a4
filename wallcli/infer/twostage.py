"""Count in two stages: is anybody there (both nets), then how many (the count net).

The count net reads the horizontal plot only (the seed's design); a person crouching, waving or
jumping in place shows mostly in the vertical plot and as a whole-wall flicker, which that net
reads as nobody. The activity net reads both plots. So:

- stage 1, presence: the two nets are two detectors of "nobody moves" (count p(0), activity
  p(none)); their evidence is combined as a product of experts with even priors,
  p_nobody = a b / (a b + (1 - a)(1 - b));
- stage 2, how many: the rest of the probability is shared between one and two people as the
  count net shares it, p(n) = (1 - p_nobody) w_n c_n / (c_1 + w_2 c_2), with w_2 the prior odds of
  two people against one (the card's ``two_stage.prior_two_vs_one``; the net was trained on even
  classes, w_2 = 1). The shipped card sets 1:4, the share of two-person rooms among occupied ones
  in the footage the models are validated for (the transfer set's labels: 20 of 100): most rooms
  with somebody in them hold one person, and a net trained on even odds says "two" too often.

The rule was fixed before any measurement (research/twostage/README.md, session 15): nothing in
it is fitted. On the transfer set it moved count from 50 to 57 of 96 detectable clips there
(paired McNemar p = 0.04); the shipped figures are in models/README.md.

Clip answers combine the clip's mean probabilities of each net (the mean of its windows, as each
command answers alone); window answers combine that window's. Whether an answer is decided comes
from the count card's ``two_stage.confidence`` block, fitted on the combined answers of this very
pair of models; with another activity model (or a count card without the block) the pair has no
validated thresholds, and every answer is undetermined rather than guessed.
"""
from __future__ import annotations

from typing import Any

import numpy as np

from wallcli.errors import WallcliError

RULE = ("presence: product of experts of the count net's p(0) and the activity net's p(none), even priors; "
        "how many: the count net's p(1) against p(2), weighted by the prior odds of two people against one")
NO_PAIR_REASON = ("no validated confidence thresholds for this pair of count and activity models "
                  "(the count card's two_stage block names another activity model, or none)")


def combine(pc: np.ndarray, pa: np.ndarray, two_odds: float = 1.0) -> np.ndarray:
    """(n, 3) count probabilities from the count net's (n, 3) and the activity net's (n, 5).

    ``two_odds``: the prior odds of two people against one where somebody moves, in the footage
    the answers are for. The count net was trained on even classes, so its share c2 / (c1 + c2)
    is a posterior under even odds; Bayes' rule moves it to another prior by weighting c2 by the
    odds (1: the net's own even prior)."""
    pc = np.asarray(pc, np.float64)
    pa = np.asarray(pa, np.float64)
    a, b = pc[:, 0], pa[:, 0]
    den = a * b + (1 - a) * (1 - b)
    nobody = np.where(den > 0, a * b / np.maximum(den, 1e-300), 0.5)
    c1, c2 = pc[:, 1], pc[:, 2] * float(two_odds)
    some = np.maximum(c1 + c2, 1e-300)
    out = np.stack([nobody, (1 - nobody) * c1 / some, (1 - nobody) * c2 / some], axis=1)
    return out / out.sum(axis=1, keepdims=True)


def classify_each(models, wins: dict[str, np.ndarray], offsets: dict[str, np.ndarray]) -> list[np.ndarray]:
    """Each model's ``classify`` of the same windows, a plot normalised once where two models'
    cards name the same normalisation (both shipped nets read the horizontal plot: ~0.4 ms a
    window each time)."""
    from wallcli.infer.model import Model

    done: dict[tuple[str, str], np.ndarray] = {}
    out = []
    for m in models:
        if (getattr(m.classify, "__func__", None) is not Model.classify
                or getattr(m.normalize, "__func__", None) is not Model.normalize):  # a classifier of its own
            out.append(m.classify(wins, offsets))
            continue
        feed = {}
        for n in m.input_names:
            key = (n, str(m.card.get("preprocessing")))
            if key not in done:
                done[key] = m.normalize(wins[n], offsets[n])
            feed[n] = done[key]
        out.append(m.predict(feed))
    return out


class TwoStageCount:
    """The count task's classifier: quacks like :class:`wallcli.infer.model.Model` for
    the stages of :mod:`wallcli.infer.classify` (task, classes, inputs, window, fps, card), but its raw output
    per window is both nets' probabilities side by side (3 + 5 columns); :meth:`combine` turns
    them into the count answer and :meth:`stages` says what each stage found."""

    def __init__(self, count, activity):
        for attr in ("fps", "window", "bins"):
            if getattr(count, attr) != getattr(activity, attr):
                raise WallcliError(f"the count and activity models differ in {attr} "
                                   f"({getattr(count, attr)} against {getattr(activity, attr)}): they cannot be combined",
                                   hint="pass --single-stage to count with the count model alone")
        if count.task != "count" or activity.task != "activity":
            raise WallcliError("a two-stage count needs a count model and an activity model")
        self.count, self.activity = count, activity
        block = count.card.get("two_stage") if isinstance(count.card.get("two_stage"), dict) else {}
        pair = block.get("activity_model", {}) if isinstance(block.get("activity_model"), dict) else {}
        self.calibrated = pair.get("sha256") == activity.card["sha256"] and isinstance(block.get("confidence"), dict)
        self.card = dict(count.card)
        self.card["confidence"] = block.get("confidence") if self.calibrated else None
        self.card["two_stage"] = block
        self.path = count.path
        # a pair is as validated as its less validated card (the prior odds and thresholds are the count card's)
        self.unvalidated = getattr(count, "unvalidated", None) or getattr(activity, "unvalidated", None)
        # the prior odds of two people against one (the card's, fixed from the share of two-person
        # rooms in the footage it was validated for; 1 = the count net's own even prior)
        odds = block.get("prior_two_vs_one", 1.0)
        self.two_odds = float(odds) if isinstance(odds, (int, float)) and not isinstance(odds, bool) and odds > 0 else 1.0

    task = "count"
    single = False

    @property
    def classes(self) -> list[Any]:
        return self.count.classes

    @property
    def input_names(self) -> list[str]:
        names = set(self.count.input_names) | set(self.activity.input_names)
        return [n for n in ("horizontal", "vertical") if n in names]

    window = property(lambda self: self.count.window)
    bins = property(lambda self: self.count.bins)
    fps = property(lambda self: self.count.fps)

    def info(self) -> dict[str, str]:
        return self.count.info()

    def classify(self, wins: dict[str, np.ndarray], offsets: dict[str, np.ndarray]) -> np.ndarray:
        """Raw output (n, 8): the count net's 3 probabilities, then the activity net's 5."""
        count, activity = classify_each((self.count, self.activity), wins, offsets)
        return np.concatenate([count, activity], axis=1)

    def combine(self, raw: np.ndarray) -> np.ndarray:
        raw = np.atleast_2d(raw)
        return combine(raw[:, :3], raw[:, 3:], self.two_odds)

    def no_block_reason(self) -> str | None:
        return None if self.calibrated else NO_PAIR_REASON

    def stages(self, raw: np.ndarray) -> dict[str, Any]:
        """What each stage found for one answer (its raw row, or the clip's mean raw row)."""
        raw = np.asarray(raw, np.float64)
        p = self.combine(raw)[0]
        somebody = float(1 - p[0])
        return {"presence": round(somebody, 6),
                # stage 2: one or two people, given somebody moves (the count net's share, under
                # the card's prior odds of two against one)
                "how_many": [round(float(p[1]) / max(somebody, 1e-300), 6), round(float(p[2]) / max(somebody, 1e-300), 6)],
                "count": [round(float(v), 6) for v in raw[:3]],
                "activity": [round(float(v), 6) for v in raw[3:]],
                # the stage that made the label: nobody is the presence stage's answer, one or two
                # people the count stage's (once the presence stage said somebody moves)
                "decided_by": "presence" if int(np.argmax(p)) == 0 else "count"}


def stages_info(model) -> dict[str, Any] | None:
    """The result's description of a two-stage model (None for a single model)."""
    if not isinstance(model, TwoStageCount):
        return None
    return {"rule": RULE, "activity_model": model.activity.info(), "calibrated": model.calibrated,
            "prior_two_vs_one": model.two_odds}


def load_count(path=None, *, activity_path=None, threads: int = 0, single: bool = False):
    """The count classifier: the two-stage pair (default) or the count net alone (``single``)."""
    from wallcli.infer.model import load_model

    count = load_model("count", path, threads=threads)
    if single:
        return count
    return TwoStageCount(count, load_model("activity", activity_path, threads=threads))


def load_classifier(task: str, path=None, *, threads: int = 0, activity_path=None, single: bool = False):
    """What a command classifies ``task`` with: count in two stages unless ``single``."""
    from wallcli.infer.model import load_model

    if task == "count":
        return load_count(path, activity_path=activity_path, threads=threads, single=single)
    if task == "activity":  # checked for two people by the shipped count net
        return with_count_check(load_model(task, path, threads=threads), threads=threads)
    return load_model(task, path, threads=threads)


NO_COUNT_REASON = ("the count model cannot read this activity model's windows, so two people cannot be ruled "
                   "out: one activity is not defined for two people")


def two_people_reason(p_two: float, level: float) -> str:
    """Why an activity answer is not decided where two people may be moving (the one wording)."""
    from wallcli.wording import level_text

    if p_two >= 0.5:
        return f"two people likely (p={p_two:.2f} of two among people moving): one activity is not defined"
    return (f"two people possible (p={p_two:.2f} of two among people moving; a decided answer must be right "
            f"{level_text(level)} of the time): one activity is not defined for two people")


def two_people_aside(p_two: float | None) -> str:
    """The two-people check said after the reason that decided (the card's thresholds): short, as a
    reason is one sentence."""
    if p_two is None:
        return "and two people cannot be ruled out (the count model cannot read these windows)"
    how = "likely" if p_two >= 0.5 else "possible"
    return f"two people {how} too (p={p_two:.2f} of two among people moving)"


class OnePersonActivity:
    """The activity task's classifier: the activity net, checked by the count net on the same windows.

    The activity net was trained and validated on rooms with one person, so its answer is not
    defined with two. A decided answer must be right at the card's level (e.g. 97 %), and it can only be
    right if one person moves; so it may be decided only where the two-stage count (this pair of
    nets, the count card's prior odds) leaves two people less likely than the answers may be wrong,
    1 - level. The count net reads the horizontal plot, which the activity path already has. Raw
    output per window: the activity net's 5 probabilities, then the count net's 3."""

    task = "activity"
    single = True

    def __init__(self, activity, count):
        from wallcli.infer.split import from_card

        self.activity, self.card, self.path = activity, activity.card, activity.path
        self.k = len(activity.classes)
        self.split = from_card(activity.card)  # a second look at two answers the net confuses
        try:
            self.pair = TwoStageCount(count, activity)
        except WallcliError:  # your own activity model, on windows the count net cannot read
            self.pair = None
        self.count = count if self.pair is not None else None
        # the count net's check reads its card's prior odds: an edited one unvalidates the answers too
        self.unvalidated = (getattr(activity, "unvalidated", None)
                            or (self.pair.unvalidated if self.pair is not None else None))

    classes = property(lambda self: self.activity.classes)
    window = property(lambda self: self.activity.window)
    bins = property(lambda self: self.activity.bins)
    fps = property(lambda self: self.activity.fps)

    @property
    def input_names(self) -> list[str]:
        names = set(self.pair.input_names if self.pair is not None else self.activity.input_names)
        if self.split is not None:
            names |= {"horizontal", "vertical"}
        return [n for n in ("horizontal", "vertical") if n in names]

    def info(self) -> dict[str, str]:
        return self.activity.info()

    def classify(self, wins, offsets) -> np.ndarray:
        """Raw output per window: the activity net's probabilities, the count net's (when it reads
        these windows), then the window's features (when the card has a split block)."""
        parts = classify_each((self.activity, self.count) if self.count is not None else (self.activity,),
                              wins, offsets)
        if self.split is not None:
            from wallcli.signal.features import window_features

            parts.append(window_features(wins["horizontal"], wins["vertical"], offsets["horizontal"],
                                         offsets["vertical"]))
        return np.concatenate(parts, axis=1)

    def combine(self, raw: np.ndarray) -> np.ndarray:
        raw = np.atleast_2d(raw)
        p = raw[:, :self.k]
        if self.split is not None:  # the features are the last columns (a clip's: its windows' mean)
            p = self.split.apply(p, raw[:, self.k + (3 if self.count is not None else 0):])
        return p

    def stages(self, raw) -> None:
        return None

    def no_block_reason(self) -> None:
        return None

    def two_people(self, raw) -> float | None:
        """P(two people | somebody moves) of the two-stage count on this answer's windows (None:
        no count net reads them)."""
        if self.pair is None:
            return None
        raw = np.atleast_2d(np.asarray(raw, np.float64))
        p = combine(raw[:, self.k:self.k + 3], raw[:, :self.k], self.pair.two_odds)[0]
        return float(p[2] / max(p[1] + p[2], 1e-300))

    def gate(self, raw, label) -> tuple[float | None, str | None]:
        """(P(two | somebody), the reason the answer may not be decided, or None)."""
        p_two = self.two_people(raw)
        if label == "none":  # never decided anyway, and it presumes nobody rather than one
            return p_two, None
        if p_two is None:
            return None, NO_COUNT_REASON
        block = self.card.get("confidence") or {}
        level = float(block.get("level", 1.0))
        return p_two, (None if p_two < 1 - level else two_people_reason(p_two, level))


def with_count_check(activity, count=None, *, threads: int = 0):
    """``activity`` checked by ``count`` (default: the shipped count net) for two people."""
    from wallcli.infer.model import load_model

    return OnePersonActivity(activity, count if count is not None else load_model("count", threads=threads))
