"""Accuracy breakdown of the model cards: visibility bands and scene-clustered intervals."""
from __future__ import annotations

import numpy as np
import pytest

from wallcli.train.data import ShardDataset
from wallcli.train.metrics import breakdown, clip_breakdown, scene_bootstrap


def _onehot(pred, k=3):
    return np.eye(k)[np.asarray(pred)]


def test_breakdown_splits_visible_windows_and_snr_bands():
    labels = np.array([0, 0, 1, 1, 2, 2, 1, 2])
    pred = np.array([0, 0, 1, 0, 2, 1, 0, 0])
    vis = np.array([np.nan, np.nan, 5.0, -15.0, 12.0, 3.0, -30.0, -12.0])
    r = breakdown(_onehot(pred), labels, vis, np.arange(8))
    assert r["accuracy"] == 4 / 8 and r["windows"] == 8 and r["scenes"] == 8
    assert r["confusion_matrix"] == [[2, 0, 0], [2, 1, 0], [1, 1, 1]]
    assert r["recall"] == [1.0, 1 / 3, 1 / 3]
    assert r["nobody_moving_accuracy"] == 1.0
    v = r["visible"]  # the two empty windows and the movers at 5, 12 and 3 dB
    assert v["windows"] == 5 and v["accuracy"] == 4 / 5 and v["confusion_matrix"] == [[2, 0, 0], [0, 1, 0], [0, 1, 1]]
    bands = {tuple(b["snr_db"]): (b["windows"], b["accuracy"]) for b in r["accuracy_by_snr"]}
    assert bands == {(None, -20.0): (1, 0.0), (-20.0, -10.0): (2, 0.0), (0.0, 10.0): (2, 0.5), (10.0, None): (1, 1.0)}


def test_breakdown_without_visibility_reports_plain_accuracy():
    r = breakdown(_onehot([0, 1, 1]), np.array([0, 1, 2]), None, np.array([0, 0, 1]))
    assert r["accuracy"] == 2 / 3 and r["scenes"] == 2 and "visible" not in r


def test_clip_breakdown_averages_a_scenes_windows_like_the_commands_clip_answer():
    scenes = np.array([7, 7, 7, 3, 3, 9, 9, 5, 5])
    labels = np.array([1, 1, 1, 2, 2, 0, 0, 1, 2])  # scene 5 has two labels: left out
    probs = np.array([[0.1, 0.8, 0.1], [0.1, 0.2, 0.7], [0.1, 0.6, 0.3],  # mean says 1: right, though one window says 2
                      [0.1, 0.5, 0.4], [0.1, 0.4, 0.5],  # mean 0.45 / 0.45: a tie goes to the first, 1: wrong
                      [0.9, 0.1, 0.0], [0.8, 0.1, 0.1],  # right
                      [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]])
    vis = np.array([5.0, 5.0, -12.0, 3.0, 4.0, np.nan, np.nan, 1.0, 1.0])
    r = clip_breakdown(probs, labels, vis, scenes)
    assert r["clips"] == 3 and r["mixed_label_scenes"] == 1 and r["accuracy"] == 2 / 3
    lo, hi = r["accuracy_95ci"]
    assert 0.0 <= lo <= 2 / 3 <= hi <= 1.0
    # scene 7 has a window under -10 dB, so only scenes 3 and 9 are visible clips
    assert r["visible"]["clips"] == 2 and r["visible"]["accuracy"] == 0.5
    assert "visible" not in clip_breakdown(probs, labels, None, scenes)


def test_scene_bootstrap_widens_when_errors_come_in_scenes():
    correct = np.r_[np.ones(80, bool), np.zeros(20, bool)]
    spread = scene_bootstrap(correct, np.arange(100))  # 100 independent windows
    clustered = scene_bootstrap(correct, np.arange(100) // 10)  # 10 scenes of 10: two all wrong
    assert spread[0] < 0.8 < spread[1] and clustered[0] < 0.8 < clustered[1]
    assert clustered[1] - clustered[0] > 2 * (spread[1] - spread[0])
    assert scene_bootstrap(np.ones(10, bool), np.arange(10)) == [1.0, 1.0]
    assert scene_bootstrap(np.zeros(0, bool), np.zeros(0, int)) is None


def test_scene_ids_follow_the_shards_scene_records(make_dataset):
    ds = ShardDataset(make_dataset("count", 10, shards=2, visibility=True), "count")
    assert ds.scene_ids().tolist() == [0, 0, 1, 1, 2, 2, 3, 3, 4, 4]  # two windows per scene, across shards
    plain = ShardDataset(make_dataset("count", 4, shards=1, name="plain"), "count")
    assert plain.scene_ids().tolist() == [0, 1, 2, 3]  # no scene records: each window its own


def test_paired_difference_is_tighter_than_two_intervals():
    from wallcli.train.metrics import paired_difference

    rng = np.random.default_rng(0)
    scenes = np.repeat(np.arange(50), 4)
    hard = np.repeat(rng.random(50) < 0.4, 4)  # both models fail the hard scenes
    a = ~hard
    b = a.copy()
    b[np.flatnonzero(a)[::10]] = False  # b also misses one easy window in ten
    d = paired_difference(a, b, scenes)
    assert d["difference"] == pytest.approx((a.sum() - b.sum()) / len(a))
    lo, hi = d["difference_95ci"]
    assert 0 < lo <= d["difference"] <= hi  # the gain is certain although...
    ia, ib = scene_bootstrap(a, scenes), scene_bootstrap(b, scenes)
    assert ia[0] < ib[1]  # ...the two models' own intervals overlap
    assert paired_difference(a, a, scenes) == {"difference": 0.0, "difference_95ci": [0.0, 0.0]}
