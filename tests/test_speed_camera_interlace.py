"""The interlace check's both-sides-at-once arithmetic (issue 60) reads the sums the per-side one read."""
from __future__ import annotations

from types import SimpleNamespace

import numpy as np
import pytest

from wallcli.camera import interlace
from wallcli.camera.interlace import InterlaceFilter


class _Reference(InterlaceFilter):
    """The check's reading as it was before issue 60's speed work: each side on its own, float32 sums."""

    def _fields(self, y):
        step = max(1, -(-y.shape[1] // interlace.MAX_COLUMNS))
        n = min((y.shape[0] - 1) // 2, y.shape[0] // 2 - 1)
        i = np.arange(0, n, max(1, -(-n // interlace.MAX_PAIRS)))
        g = y[(2 * i[:, None] + np.arange(4)).ravel(), ::step].astype(np.float32).reshape(len(i), 4, -1)
        top, bottom, top1, bottom1 = g[:, 0], g[:, 1], g[:, 2], g[:, 3]
        return np.maximum(0.5 * (top + top1), 1.0), bottom, np.maximum(0.5 * (bottom + bottom1), 1.0), top1

    def _observe(self, y, fps):
        if y.shape[0] < 8 or self.delta is not None or self.progressive:
            return
        self._seen.append(self._fields(y))
        if len(self._seen) < 5:
            return
        self._n += 1
        self._fps = fps
        a = max(1.0 / (interlace.TAU * fps), 1.0 / self._n)
        for side in (0, 1):
            far0, before, (ref, other), after, far1 = (f[2 * side] if i != 2 else f[2 * side:2 * side + 2]
                                                     for i, f in enumerate(self._seen))
            now = (other / ref - 1.0, (after - before) / (2.0 * ref), (far1 - far0) / (4.0 * ref))
            mean = self._mean[side] if self._mean is not None else None
            mean = list(now) if mean is None else [(1 - a) * m + a * v for m, v in zip(mean, now)]
            self._mean = self._mean or [None, None]
            self._mean[side] = mean
            if self._n < 3:
                continue
            yy, xx, zz = (v - m for v, m in zip(now, mean))
            self._sums[side] += (float(np.sum(xx * yy)), float(np.sum(xx * xx)), float(np.sum(yy * yy)), xx.size,
                                 float(np.sum(zz * yy)), float(np.sum(zz * xx)))
        if self.delta is None and self._n >= interlace.MIN_FRAMES and self._n % 4 == 0:
            self._decide()


def _woven(n, offset, shape, dtype, seed=0):
    """A wall whose light swings by 5 % once a second, its odd rows ``offset`` frames after the even ones."""
    from wallcli.io.planes import Planes
    from wallcli.io.video import Frame

    rng = np.random.default_rng(seed)
    wall = 60 + 150 * rng.random(shape)
    for k in range(n):
        light = 1 + 0.05 * np.sin(2 * np.pi * np.array([k, k + offset]) / 30)
        y = wall * light[0] + rng.normal(0, 1.0, shape)
        y[1::2] = wall[1::2] * light[1] + rng.normal(0, 1.0, wall[1::2].shape)
        yield Frame(k, k / 30, Planes(np.clip(y, 0, 255).astype(dtype), None, None, "gray"))


@pytest.mark.parametrize("offset", [0.0, 0.5, -0.5, 1.0])
@pytest.mark.parametrize("shape,dtype", [((48, 64), np.float32), ((270, 480), np.uint8), ((1081, 300), np.uint8)])
def test_same_sums_and_decision_as_the_per_side_reading(offset, shape, dtype):
    new, old = (cls(SimpleNamespace(frames=lambda: _woven(40, offset, shape, dtype))) for cls in (InterlaceFilter,
                                                                                                  _Reference))
    for f in (new, old):
        for _ in f.frames():
            pass
    assert (new._n, new.delta, new.progressive) == (old._n, old.delta, old.progressive)
    assert np.allclose(new._sums, old._sums, rtol=1e-5, atol=1e-6 * np.abs(old._sums).max())
