"""The repeat check's and the frame clock's cheaper steps (issue 60) give what the steps they replaced gave."""
from __future__ import annotations

from fractions import Fraction

import numpy as np
import pytest

from wallcli.camera.repeats import MAX_SAMPLES, _sample
from wallcli.io.rates import FrameClock


@pytest.mark.parametrize("h,w,pad", [(1080, 1920, 0), (1081, 1923, 61), (2160, 3840, 0), (240, 320, 8)])
def test_the_lattice_is_the_strided_one_contiguous(h, w, pad):
    y = np.random.default_rng(h).integers(0, 256, (h, w + pad), dtype=np.uint8)[:, :w]
    step = max(1, int(np.ceil(np.sqrt(y.size / MAX_SAMPLES))))
    got = _sample(y)
    assert got.flags.c_contiguous and np.array_equal(got, y[::step, ::step])


def test_the_clocks_gaps_are_those_of_numpys_median():
    rng = np.random.default_rng(2)
    pts = np.cumsum(rng.integers(30, 36, 400))
    pts[50:] += 900  # jumps: frames lost
    pts[200:] += 4000
    pts[300:] += 600
    clock = FrameClock(Fraction(1, 1000), Fraction(30), "x")
    recent, gaps, last = [], [], None
    for i, p in enumerate(pts):
        t, gap = clock.stamp(int(p), i)
        if i:  # the rule as it read with np.median
            dt = t - last
            typical = float(np.median(recent[-16:])) if len(recent) >= 4 else 1 / 30
            if dt > 5 * typical and dt > max(5 / 30, 0.25):
                gaps.append(dt)
            else:
                recent.append(dt)
        last = t
        assert gap == (gaps[-1] if gaps and gap else 0.0)
    assert len(clock.gaps) == len(gaps) == 3
