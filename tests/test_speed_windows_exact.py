"""The per-window speed paths (issue 60) give the values of the code they replaced, to the last bit:
the exposure fit's sort-based medians, its span means, its cached Legendre fits, and the colours'
mean summed by hand."""
from __future__ import annotations

import numpy as np
import pytest

from wallcli.camera import exposure


@pytest.mark.parametrize("shape,axis", [((256, 128), 1), ((128, 255), -1), ((255,), 0), ((256,), -1), ((7, 5), 0),
                                        ((1, 1), 1)])
def test_median_is_numpys(shape, axis):
    rng = np.random.default_rng(sum(shape))
    x = rng.standard_normal(shape)
    x.flat[::7] = x.flat[-1]  # ties
    want = np.median(x, axis=axis)
    got = exposure.median(x, axis=axis)
    assert np.array_equal(got, want)
    assert np.shape(got) == np.shape(want)


def test_median_is_nan_where_numpys_is():
    x = np.arange(24.0).reshape(4, 6)
    x[1, 2] = np.nan
    assert np.array_equal(exposure.median(x, axis=1), np.median(x, axis=1), equal_nan=True)
    assert np.isnan(exposure.median(x[1]))


def _masked_means_before(r, w, idx, half, span, least):
    """The span means as they were computed before (np.clip of each end, concatenated cumsums)."""
    t = r.size
    cs = np.concatenate([[0.0], np.cumsum(r * w)])
    cn = np.concatenate([[0.0], np.cumsum(w)])
    b_hi, b_lo = np.clip(idx - half, 0, t), np.clip(idx - half - span, 0, t)
    a_lo, a_hi = np.clip(idx + half, 0, t), np.clip(idx + half + span, 0, t)
    nb, na = cn[b_hi] - cn[b_lo], cn[a_hi] - cn[a_lo]
    with np.errstate(invalid="ignore", divide="ignore"):
        before = np.where(nb >= least, (cs[b_hi] - cs[b_lo]) / np.maximum(nb, 1), np.nan)
        after = np.where(na >= least, (cs[a_hi] - cs[a_lo]) / np.maximum(na, 1), np.nan)
    return before, after


@pytest.mark.parametrize("half,span,least", [(5, 15, 5), (0, 15, 5), (10, 30, 2)])
def test_masked_means_as_before(half, span, least):
    rng = np.random.default_rng(half + span)
    r = rng.standard_normal(256)
    w = np.ones(256)
    w[40:52] = 0.0
    w[250:] = 0.0
    for idx in (np.arange(-3, 260), np.array([100]), np.array([0])):
        got = exposure._masked_means(r, w, idx, half, span, least)
        want = _masked_means_before(r, w, idx, half, span, least)
        for g, e in zip(got, want):
            assert np.array_equal(g, e, equal_nan=True)


def test_cached_legendre_fits_are_the_fresh_ones():
    basis, pinv = exposure._legendre(256, 3)
    fresh = np.polynomial.legendre.legvander(np.linspace(-1.0, 1.0, 256), 3)
    assert np.array_equal(basis, fresh)
    assert np.array_equal(pinv, np.linalg.pinv(fresh))
    assert np.array_equal(exposure._ends_pinv(256, 3, 9), np.linalg.pinv(fresh[9:247]))
    with pytest.raises(ValueError):
        basis[0, 0] = 1.0  # shared between windows: read only


def test_steps_and_drift_reads_no_state_between_windows():
    rng = np.random.default_rng(3)
    rel = 0.001 * rng.standard_normal((256, 64))
    rel[120:] += 0.02  # an exposure step
    rel += np.linspace(0, 0.01, 256)[:, None]  # and drift
    first = exposure._steps_and_drift(rel, 30.0)
    again = exposure._steps_and_drift(rel.copy(), 30.0)
    assert np.array_equal(first[0], again[0]) and first[1:] == again[1:]
    assert first[1] and abs(first[1][0][1] - 0.02) < 0.002


def test_colours_summed_by_hand_are_numpys_mean_and_sum():
    from wallcli.signal import features

    rng = np.random.default_rng(1)
    w = rng.uniform(0, 255, (2, 64, 256, 3)).astype(np.float32)
    x = w.astype(np.float64)
    assert np.array_equal((x[..., 0] + x[..., 1] + x[..., 2]) / 3.0, x.mean(-1))
    assert np.array_equal(x[..., 0] + x[..., 1] + x[..., 2], x.sum(-1))
    want = x.mean(-1)
    assert np.array_equal(features._centred(w), want - want.mean(2, keepdims=True))
