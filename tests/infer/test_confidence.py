"""Decided or undetermined: thresholds fitted on validation windows, and how answers are judged."""
import numpy as np

from wallcli.infer.confidence import NO_BLOCK_REASON, fit, judge, validate_block

CLASSES = [0, 1, 2]
NEUTRAL = ["a", "b", "c"]  # classes none of which is 'nobody' (never decided): the fit alone is tested


def _validation(seed=0, n=6000):
    """Windows whose answers are right more often the higher their probability, and never right
    in the faintest band when they say 0 (a person the model cannot see reads as nobody)."""
    rng = np.random.default_rng(seed)
    truth = rng.integers(0, 3, n)
    snr = rng.uniform(-25, 20, n)
    pmax = rng.uniform(0.34, 1.0, n)
    right = rng.random(n) < pmax ** 0.3  # confident answers are right more often
    pred = np.where(right, truth, (truth + rng.integers(1, 3, n)) % 3)
    faint = snr < -10
    pred[faint] = 0
    truth[faint] = 1
    probs = np.full((n, 3), 0.0)
    probs[np.arange(n), pred] = pmax
    for i in range(n):
        others = [c for c in range(3) if c != pred[i]]
        probs[i, others] = (1 - pmax[i]) / 2
    return probs, truth, snr


def test_fitted_thresholds_meet_the_level_where_they_exist():
    probs, truth, snr = _validation()
    block = fit(probs, truth, snr, CLASSES, level=0.95, edges=[-10.0, 0.0, 10.0])
    assert validate_block(block, 3) is None
    assert block["thresholds"][0][0] is None  # the faint band's 'nobody' is never right: never decided
    decided = np.array([judge(block, p, s, CLASSES)[0] for p, s in zip(probs, snr)])
    right = probs.argmax(1) == truth
    assert decided.mean() > 0.1  # (a third of the answers are 'nobody', never decided: judge, NOBODY)
    assert right[decided].mean() >= 0.95  # in-sample, the level holds by construction
    # on fresh windows from the same process it holds within sampling error
    p2, t2, s2 = _validation(seed=1)
    d2 = np.array([judge(block, p, s, CLASSES)[0] for p, s in zip(p2, s2)])
    assert (p2.argmax(1) == t2)[d2].mean() > 0.92


def test_a_threshold_must_hold_in_every_validation_set_on_its_own():
    """A large set where confident answers are right must not carry a threshold over a smaller
    set (another simulated world) where the same confident answers are often wrong."""
    rng = np.random.default_rng(0)
    p_easy = rng.uniform(0.5, 1.0, 2000)
    t_easy = np.where(p_easy > 0.6, 0, 1)  # easy world: 'nobody' is right whenever p > 0.6
    p_hard = rng.uniform(0.9, 1.0, 100)
    t_hard = np.where(rng.random(100) < 0.5, 0, 1)  # hard world: confident 'nobody' is a coin toss
    pm = np.r_[p_easy, p_hard]
    P = np.stack([pm, 1 - pm, np.zeros_like(pm)], 1)
    T, S = np.r_[t_easy, t_hard], np.zeros(len(pm))
    groups = np.r_[np.zeros(2000), np.ones(100)]
    pooled = fit(P, T, S, CLASSES, level=0.95, edges=[10.0])
    per_set = fit(P, T, S, CLASSES, level=0.95, edges=[10.0], groups=groups)
    assert validate_block(per_set, 3) is None and "per_set" in per_set
    hard = groups == 1

    def decided(block):
        return np.array([judge(block, p, s, NEUTRAL)[0] for p, s in zip(P[hard], S[hard])])

    assert decided(pooled).sum() > 80  # pooled, the easy world vouches for the hard one's coin tosses
    assert decided(per_set).sum() < 25  # per set, only where too few of the hard world's answers remain
    t = per_set["thresholds"][0][0]
    assert t is None or t > pooled["thresholds"][0][0]


def test_judge_gives_a_reason_whenever_it_does_not_decide():
    probs, truth, snr = _validation()
    block = fit(probs, truth, snr, CLASSES, level=0.95, edges=[-10.0, 0.0, 10.0])
    ok, reason = judge(block, [0.05, 0.05, 0.9], -20.0, CLASSES)
    assert not ok and "'2 people'" in reason and "under -10 dB" in reason
    # one figure, the card's level, worded so that it does not read as 'never right' at a glance
    assert "not right often enough in validation to be relied on (95 % needed" in reason and "never" not in reason
    t = block["thresholds"][3][1]
    assert judge(block, [0.0, t, 1 - t], 15.0, CLASSES)[0] is False or t >= 0.5
    ok, reason = judge(block, [0.01, 0.98, 0.01], 15.0, CLASSES)
    assert ok and reason is None
    ok, reason = judge(None, [0.01, 0.98, 0.01], 15.0, CLASSES)
    assert not ok and reason == NO_BLOCK_REASON


def test_a_malformed_block_is_named():
    probs, truth, snr = _validation()
    block = fit(probs, truth, snr, CLASSES, level=0.95, edges=[-10.0, 0.0, 10.0])
    assert "level" in validate_block({**block, "level": 2}, 3)
    assert "signal_edges_db" in validate_block({**block, "signal_edges_db": [3, 1, 2]}, 3)
    assert "one row per signal band" in validate_block({**block, "thresholds": block["thresholds"][:2]}, 3)
    assert "one entry per class" in validate_block(block, 5)


def test_nobody_is_never_decided_whatever_the_card_says():
    """An empty room and a person too faint to see give the same plot: 'nobody' (count 0,
    activity 'none') stays undetermined even where a card's calibration, which left faint people
    out, certified it; under the noise and above it alike (codec residue reads as a few dB on an
    empty wall). An answer that someone moves is the card's to judge."""
    block = {"level": 0.97, "signal_edges_db": [0.0], "thresholds": [[0.9, 0.9, 0.9], [0.9, 0.9, 0.9]]}
    ok, reason = judge(block, [0.99, 0.005, 0.005], -3.0, CLASSES)
    assert not ok and "no movement above the camera's noise" in reason and "-3.0 dB" in reason
    ok, reason = judge(block, [0.99, 0.005, 0.005], 2.0, CLASSES)
    assert not ok and "'0 people' is never decided" in reason and "2.0 dB" in reason
    assert judge(block, [0.005, 0.99, 0.005], -3.0, CLASSES) == (True, None)  # a person seen is the card's to judge
    acts = ["none", "walking", "crouching"]
    for snr in (-3.0, 2.0, 25.0):
        ok, reason = judge(block, [0.99, 0.005, 0.005], snr, acts)
        assert not ok and "faint" in reason
    assert judge(block, [0.005, 0.99, 0.005], 2.0, acts) == (True, None)


def test_the_trust_figure_follows_the_card():
    """One figure, the card's level, in every reason (and the same words in each)."""
    from wallcli.wording import level_text

    assert [level_text(x) for x in (0.97, 0.95, 0.975, 1)] == ["97 %", "95 %", "97.5 %", "100 %"]
    for level in (0.9, 0.97):
        block = {"level": level, "signal_edges_db": [0.0], "thresholds": [[None] * 3, [0.9, None, 0.95]]}
        assert f"({level_text(level)} needed" in judge(block, [0.2, 0.7, 0.1], 4.7, CLASSES)[1]
        assert f"right {level_text(level)} of the time in validation only from p=0.950" in \
            judge(block, [0.1, 0.1, 0.8], 3.0, CLASSES)[1]
