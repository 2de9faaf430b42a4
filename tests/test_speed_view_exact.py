"""The view check's faster paths (issue 60) give what the plain numpy and OpenCV calls they replace
give, to the bit: the answers must not move."""
from __future__ import annotations

import cv2
import numpy as np
import pytest

from wallcli.view.image import (
    _inner_difference, _median, _robust_sigma, _whole_block_bounds, _whole_blocks,
)


@pytest.mark.parametrize("n", [1, 2, 3, 4, 7, 880, 881, 4096])
def test_median_is_numpys(n):
    rng = np.random.default_rng(n)
    for x in (rng.normal(1.0, 0.3, n).astype(np.float32), rng.integers(0, 5, n).astype(np.float32) / 3):
        assert _median(x) == float(np.median(x))


@pytest.mark.parametrize("shape", [(10, 12), (40, 72), (176, 320), (180, 320), (270, 480), (71, 93)])
def test_inner_difference_is_the_cropped_difference_as_robust_sigma_reads_it(shape):
    rng = np.random.default_rng(shape[0])
    a, b = (rng.normal(0, 2, shape).astype(np.float32) for _ in range(2))
    b[::3] = a[::3]  # repeated (skip) blocks: _coded reads the coded ones
    assert _robust_sigma(_inner_difference(a, b, 4)) == _robust_sigma((a - b)[4:-4, 4:-4])


def test_robust_sigma_is_the_plain_formula():
    rng = np.random.default_rng(1)
    for n in (16, 300, 4097, 20000):
        d = rng.normal(0, 1.5, n).astype(np.float32)
        s = d[:: d.size // 2048] if d.size > 4096 else d
        a = np.abs(s - float(np.partition(s, s.size // 2)[s.size // 2]))
        k = int(0.9 * (a.size - 1))
        keep = np.partition(a, k)[:k + 1]
        assert _robust_sigma(d) == float(np.sqrt(np.mean(keep * keep, dtype=np.float64) / 0.623 / 2.0))


def test_a_window_applied_before_the_phase_correlation_is_its_own():
    rng = np.random.default_rng(2)
    base = cv2.GaussianBlur(rng.normal(0, 10, (200, 340)).astype(np.float32), (0, 0), 1.5)
    win = cv2.createHanningWindow((320, 176), cv2.CV_32F)
    ref = base[10:186, 10:330].copy()
    for dx, dy in ((0, 0), (1, 0), (3, -2), (7, 5)):
        cur = base[10 + dy:186 + dy, 10 + dx:330 + dx] + rng.normal(0, 1, (176, 320)).astype(np.float32)
        assert cv2.phaseCorrelate(ref * win, cur * win) == cv2.phaseCorrelate(ref.copy(), cur.copy(), win)


@pytest.mark.parametrize("shape", [(90, 160), (88, 160), (16, 4000), (1000, 1), (33, 33), (120, 160)])
def test_whole_block_bounds_are_whole_blocks(shape):
    img = np.arange(shape[0] * shape[1], dtype=np.float32).reshape(shape)
    rows, cols = _whole_block_bounds(shape)
    assert np.array_equal(img[rows, cols], _whole_blocks(img))
