"""The overlay check's cheaper steps (issue 60) give what the steps they replaced gave, value for value."""
from __future__ import annotations

import statistics

import cv2
import numpy as np
import pytest

from wallcli.camera import overlay
from wallcli.io.planes import Planes


def _blurred_band(eight, long, k):
    # the whole band's median, as _static read it before: the band of still samples, half a kernel about it
    rows, cols = np.flatnonzero(long.any(axis=1)), np.flatnonzero(long.any(axis=0))
    r0, r1 = max(int(rows[0]) - k // 2, 0), min(int(rows[-1]) + k // 2 + 1, eight.shape[0])
    c0, c1 = max(int(cols[0]) - k // 2, 0), min(int(cols[-1]) + k // 2 + 1, eight.shape[1])
    ground = np.zeros(eight.shape, np.uint8)
    ground[r0:r1, c0:c1] = cv2.medianBlur(np.ascontiguousarray(eight[r0:r1, c0:c1]), k)
    return ground[long]


def test_medians_at_a_few_samples_are_the_bands_median_blur():
    rng = np.random.default_rng(7)
    for trial in range(200):
        h, w = (int(v) for v in rng.integers(3, 100, 2))
        k = int(rng.choice([5, 7, 11, 31, 61]))
        eight = rng.integers(0, 256, (h, w)).astype(np.uint8)
        if trial % 3 == 0:  # many ties
            eight = (eight // 64 * 64).astype(np.uint8)
        long = rng.random((h, w)) < float(rng.choice([0.002, 0.02, 0.2]))
        long[int(rng.integers(0, h)), int(rng.integers(0, w))] = True
        if trial % 4 == 0:  # the corners: the border replicated
            long[0, 0] = long[-1, -1] = long[0, -1] = True
        rr, cc = np.nonzero(long)
        assert np.array_equal(overlay._medians_at(eight, rr, cc, k), _blurred_band(eight, long, k))


@pytest.mark.parametrize("h,w", [(1080, 1920), (1081, 1923), (720, 1280), (2160, 3840), (480, 1300), (1300, 20)])
def test_the_lattice_is_the_whole_planes_nearest_resize(h, w):
    y = np.random.default_rng(h + w).integers(0, 256, (h, w + 64), dtype=np.uint8)[:, :w]  # a decoder's row padding
    f = overlay.OverlayFilter(None)
    got = f._sample(Planes(y, None, None, kind="gray"))
    step = max(1, -(-max(h, w) // overlay.MAX_SIDE))
    want = cv2.resize(y[: h - h % step, : w - w % step], (w // step, h // step), interpolation=cv2.INTER_NEAREST)
    assert got.shape == want.shape and np.array_equal(got, want)
    assert np.array_equal(got, y[: h - h % step: step, : w - w % step: step][: h // step, : w // step])


def test_median_and_p90_of_codes_are_numpys():
    rng = np.random.default_rng(3)
    for n in (1, 2, 3, 10, 11, 99, 100, 14400):
        a = rng.integers(0, int(rng.integers(1, 256)), n).astype(np.uint8).reshape(1, -1)
        median, p90 = overlay._median_p90(a)
        assert median == float(np.median(a)) and p90 == pytest.approx(float(np.percentile(a, 90)), abs=1e-9)


def test_a_few_floats_median_is_numpys():
    rng = np.random.default_rng(5)
    for n in range(1, 17):
        values = [float(v) for v in rng.normal(3.0, 2.0, n)]
        assert statistics.median(values) == float(np.median(values))
