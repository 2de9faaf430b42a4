"""The second look at a confused pair: only the pair's probability moves, and a bad block is refused."""
from __future__ import annotations

import json

import numpy as np
import pytest

from wallcli.errors import WallcliError
from wallcli.infer.split import Split, fit, validate
from wallcli.signal.features import NAMES

CLASSES = ["none", "walking", "crouching", "waving", "jumping"]


def _block(rng):
    X = rng.normal(size=(60, len(NAMES)))
    y = (X[:, 3] + 0.3 * rng.normal(size=60) > 0).astype(float)  # the 4th feature tells them apart
    b = fit(X, y)
    b["pair"] = ["waving", "jumping"]
    return b, X, y


def test_fit_learns_the_feature_that_separates_and_moves_only_the_pair():
    rng = np.random.default_rng(0)
    b, X, y = _block(rng)
    sp = Split(b, CLASSES)
    assert np.mean((sp.second(X) > 0.5) == (y > 0.5)) > 0.9
    p = np.array([[0.1, 0.05, 0.05, 0.2, 0.6],   # jumping: re-split
                  [0.1, 0.7, 0.05, 0.1, 0.05]])  # walking: left alone
    f = np.zeros((2, len(NAMES)))
    f[:, 3] = [-3.0, 3.0]
    out = sp.apply(p, f)
    assert np.allclose(out.sum(1), 1) and np.allclose(out[:, :3], p[:, :3])
    assert out[0, 3] > out[0, 4] and np.isclose(out[0, 3] + out[0, 4], 0.8)
    assert np.allclose(out[1], p[1])


def test_weights_count():
    rng = np.random.default_rng(1)
    X = rng.normal(size=(40, len(NAMES)))
    y = (X[:, 0] > 0).astype(float)
    flipped = 1 - y
    both = np.concatenate([X, X]), np.concatenate([y, flipped])
    # the flipped copy weighs almost nothing: the fit follows the first
    b = fit(*both, weights=np.concatenate([np.ones(40), np.full(40, 1e-3)]))
    assert b["coef"][0] > 0


@pytest.mark.parametrize("bad", [
    {"pair": ["waving", "waving"]}, {"pair": ["waving", "sleeping"]}, {"coef": [1.0] * 3},
    {"scale": [0.0] * len(NAMES)}, {"intercept": float("nan")}, {"features": ["x"] * len(NAMES)},
    {"format": "other"}])
def test_a_tampered_block_is_refused_in_one_line(bad):
    b, _, _ = _block(np.random.default_rng(2))
    b = json.loads(json.dumps(b)) | bad
    assert validate(b, CLASSES)
    with pytest.raises(WallcliError, match="split block is unusable"):
        Split(b, CLASSES)


def test_trust_from_recordings_decides_only_what_enough_clips_back():
    from wallcli.train.folds import fit_trust

    n = 120
    probs = np.tile([0.01, 0.97, 0.01, 0.005, 0.005], (n, 1))
    labels = np.ones(n, int)
    db = np.full(n, 15.0)
    block = fit_trust(probs, labels, db, CLASSES, level=0.97)
    assert block["thresholds"][2][1] is not None and block["thresholds"][2][0] is None  # nobody never
    labels[:10] = 2  # ten wrong at the top: 92 % right, no threshold backs 97 %
    assert fit_trust(probs, labels, db, CLASSES, level=0.97)["thresholds"][2][1] is None
    # 60 clips all right: a 95 % bound cannot reach 97 % on so few
    assert fit_trust(probs[:60], np.ones(60, int), db[:60], CLASSES, level=0.97)["thresholds"][2][1] is None
