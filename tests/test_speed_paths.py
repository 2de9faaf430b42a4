"""The faster paths of issue 60 give the slow paths' exact figures: the column SNR's column sums
through OpenCV are numpy's integer sums, for 8-bit, 16-bit and RGB planes and regions off the origin."""
from __future__ import annotations

from types import SimpleNamespace

import numpy as np
import pytest

from wallcli.snr import column


@pytest.mark.parametrize("dtype,top", [(np.uint8, 256), (np.uint16, 1024), (np.float32, 1)])
@pytest.mark.parametrize("kind", ["yuv", "rgb"])
def test_column_sums_are_exact(dtype, top, kind):
    rng = np.random.default_rng(3)
    y, u, v = ((rng.random((270, 480)) * top).astype(dtype) for _ in range(3))
    planes = SimpleNamespace(y=y, u=u, v=v, kind=kind, width=480, height=270)
    roi = (7, 11, 401, 203)
    got = column._luma(planes, roi)
    used = (y, u, v) if kind == "rgb" else (y,)
    want = sum(np.sum(p[11:214, 7:408].astype(np.float64), axis=0) for p in used) / len(used) / 203
    assert got.dtype == np.float64 and got.shape == (401,)
    if dtype == np.float32:
        np.testing.assert_allclose(got, want, rtol=1e-6)
    else:
        assert np.array_equal(got, want)  # integer codes: the same sums to the last bit
