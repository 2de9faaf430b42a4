"""The temporal-noise tap's cheaper gather and integer sums (issue 60) give the sums the float64 ones gave."""
from __future__ import annotations

from types import SimpleNamespace

import numpy as np
import pytest

from wallcli.camera.tnr import TILE, TemporalNoise, _tiles


class _Reference:
    """The tap as it was before issue 60's speed work: an index of the plane, float64 einsums."""

    def __init__(self):
        self.d, self.held, self.blocks, self.pairs, self.hist, self.at = None, 0, 0, 0, [], None

    def __call__(self, y, gap=0.0):
        if self.at is None:
            corners = _tiles(*y.shape)
            self.d = np.zeros((2, len(corners)))
            r, c = (np.array([k[i] for k in corners], np.intp).reshape(-1, 1, 1) for i in (0, 1))
            self.at = (r + np.arange(TILE).reshape(1, -1, 1), c + np.arange(TILE + 2).reshape(1, 1, -1))
        if gap:
            self.hist = []
        luma = y[self.at]
        z = luma[:, :, 2:].astype(np.int32) - luma[:, :, :-2]
        if self.hist:
            prev_luma, prev_z = self.hist[-1]
            same = np.equal(luma[:, :, :TILE], prev_luma[:, :, :TILE]).reshape(len(z), TILE // 8, 8, TILE // 8, 8)
            held = same.all(axis=(2, 4))
            self.blocks += held.size
            self.held += int(np.count_nonzero(held))
            if len(self.hist) == 2:
                for k, before in ((0, prev_z), (1, self.hist[0][1])):
                    dz = (z - before).astype(np.float64)
                    self.d[k] += np.einsum("ijk,ijk->i", dz, dz)
                self.pairs += 1
        self.hist = (self.hist + [(luma, z)])[-2:]


def _frames(dtype, h, w, pad, n, seed):
    rng = np.random.default_rng(seed)
    top = 255 if dtype == np.uint8 else 65535
    base = rng.integers(0, top + 1, (h, w + pad))
    plane = None
    for i in range(n):
        if plane is None or i % 5:  # every fifth frame a copy of the one before: its blocks held
            plane = np.clip(base + rng.integers(-3, 4, (h, w + pad)), 0, top).astype(dtype)
        yield SimpleNamespace(planes=SimpleNamespace(y=plane[:, :w]), gap=0.5 if i == 20 else 0.0)


@pytest.mark.parametrize("dtype,h,w,pad", [(np.uint8, 270, 480, 32), (np.uint8, 97, 131, 0),
                                           (np.uint16, 180, 320, 64), (np.uint16, 64, 64, 0)])
def test_the_sums_and_held_blocks_are_the_references(dtype, h, w, pad):
    tap, ref = TemporalNoise(), _Reference()
    for frame in _frames(dtype, h, w, pad, 45, h + w):
        tap(frame)
        ref(frame.planes.y, frame.gap)
    assert np.array_equal(tap._d, ref.d) and tap.pairs == ref.pairs == 41
    assert tap._held == ref.held and tap._blocks == ref.blocks and ref.held > 0


def test_a_plane_whose_rows_are_not_evenly_spaced_in_memory_is_indexed():
    tap, ref = TemporalNoise(), _Reference()
    for frame in _frames(np.uint8, 200, 120, 0, 40, 1):
        y = np.ascontiguousarray(frame.planes.y.T)[:, ::-1]  # a turned plane's view
        tap(SimpleNamespace(planes=SimpleNamespace(y=y), gap=0.0))
        ref(y)
    assert np.array_equal(tap._d, ref.d) and tap._held == ref.held
