"""Exact block averaging: integer sums, fractional edges, two ways that must agree."""

import numpy as np
import pytest

from wallcli.errors import WallcliError
from wallcli.signal.blocks import bin_edges, block_means, check_roi, projection_means


@pytest.mark.parametrize("dtype", [np.uint8, np.uint16])
def test_fractional_blocks_equal_supersampled_means(dtype):
    rng = np.random.default_rng(0)
    a = rng.integers(0, 256, (7, 5)).astype(dtype)
    rows, cols = bin_edges(0.5, 6.5, 3), bin_edges(0, 5, 4)
    # Supersample each pixel 12x12: block means of the big image at integer edges are exact.
    big = np.repeat(np.repeat(a.astype(np.float64), 12, 0), 12, 1)[6:78]
    ref = big.reshape(3, 24, 4, 15).mean(axis=(1, 3))
    assert np.allclose(block_means(a, rows, cols), ref, atol=1e-9)
    c, r = projection_means(a, rows, cols)
    assert np.allclose(c, ref.mean(axis=0), atol=1e-9) and np.allclose(r, ref.mean(axis=1), atol=1e-9)


def test_sums_do_not_round_subcode_differences():
    a = np.full((1080, 1920), 100, np.uint8)
    a[:, :30][::5] = 101  # one pixel in five is brighter in the first bin: +0.2 code values
    c, _ = projection_means(a, bin_edges(0, 1080, 64), bin_edges(0, 1920, 64))
    assert c[0] == pytest.approx(100.2, abs=1e-9) and np.allclose(c[1:], 100.0)


def test_check_roi():
    assert check_roi(None, 64, 48) == (0, 0, 64, 48)
    with pytest.raises(WallcliError, match="64x48"):
        check_roi((60, 0, 10, 10), 64, 48)


def test_projector_without_vertical_gives_the_same_horizontal_profile():
    from wallcli.io.video import Planes
    from wallcli.signal.blocks import RgbProjector

    rng = np.random.default_rng(3)
    planes = Planes(rng.integers(16, 236, (90, 160), dtype=np.uint8), rng.integers(16, 240, (45, 80), dtype=np.uint8),
                    rng.integers(16, 240, (45, 80), dtype=np.uint8), sub_x=1, sub_y=1)
    roi = (10.5, 7, 131, 70.25)
    h_full, v_full = RgbProjector(roi, 16)(planes)
    h_only, v_none = RgbProjector(roi, 16, vertical=False)(planes)
    assert np.array_equal(h_full, h_only) and np.ptp(v_full) > 0 and not v_none.any()


def test_projector_runs_opencv_on_one_thread_and_restores_the_callers_setting(monkeypatch):
    import cv2

    from wallcli.io.video import Planes
    from wallcli.signal import blocks

    seen = []
    reduce = cv2.reduce

    def spy(*args, **kwargs):
        seen.append(cv2.getNumThreads())
        return reduce(*args, **kwargs)

    rng = np.random.default_rng(4)
    planes = Planes(rng.integers(16, 236, (90, 160), dtype=np.uint8), rng.integers(16, 240, (45, 80), dtype=np.uint8),
                    rng.integers(16, 240, (45, 80), dtype=np.uint8), sub_x=1, sub_y=1)
    before = cv2.getNumThreads()
    try:
        cv2.setNumThreads(3)
        monkeypatch.setattr(cv2, "reduce", spy)
        blocks.RgbProjector((0, 0, 160, 90), 16)(planes)
        assert seen and set(seen) == {1}  # the frame's reductions ran single-threaded
        assert cv2.getNumThreads() == 3  # and a library caller's choice is back
    finally:
        cv2.setNumThreads(before)


def test_the_buffered_8_bit_sums_equal_the_general_exact_ones():
    """ProjectionPlan's fast path (8-bit plane, whole-pixel rectangle: OpenCV float32 sums into
    buffers made once) gives exactly what the general path gives for the same values in 16 bits."""
    from wallcli.signal.blocks import ProjectionPlan

    rng = np.random.default_rng(5)
    plane = rng.integers(0, 256, (1080, 1920), dtype=np.uint8)
    plane[:, 7] = 255  # a column of the largest sum: 1080 x 255 must still be exact in float32
    plan = ProjectionPlan(bin_edges(0, 1080, 64), bin_edges(0, 1920, 64))
    fast = plan(plane)
    assert plan._fast is True
    general = ProjectionPlan(bin_edges(0, 1080, 64), bin_edges(0, 1920, 64))(plane.astype(np.uint16))
    for a, b in zip(fast, general):
        assert np.array_equal(a, b)
    for a, b in zip(fast, plan(plane)):  # a second frame through the same buffers
        assert np.array_equal(a, b)


@pytest.mark.parametrize("kind", ["yuv", "gray", "rgb", "yuv-full-10bit"])
def test_the_projector_converts_to_rgb_as_to_rgb_does(kind):
    """The projector's one affine map per format equals Planes.to_rgb on the same means."""
    from wallcli.io.video import Planes
    from wallcli.signal.blocks import RgbProjector, projection_means

    rng = np.random.default_rng(6)
    deep = kind.endswith("10bit")
    hi, dt = (1024, np.uint16) if deep else (256, np.uint8)
    y = rng.integers(0, hi, (90, 160), dtype=dt)
    if kind == "gray":
        planes = Planes(y, None, None, kind="gray")
    elif kind == "rgb":
        planes = Planes(y, rng.integers(0, 256, (90, 160), dtype=dt), rng.integers(0, 256, (90, 160), dtype=dt), kind="rgb")
    else:
        planes = Planes(y, rng.integers(0, hi, (45, 80), dtype=dt), rng.integers(0, hi, (45, 80), dtype=dt),
                        sub_x=1, sub_y=1, depth=10 if deep else 8, matrix="bt709", full_range=deep)
    roi = (3, 2, 150, 84)
    h, v = RgbProjector(roi, 16)(planes)
    rows, cols = bin_edges(2, 86, 16), bin_edges(3, 153, 16)
    yc, yr = projection_means(planes.y, rows, cols)
    if planes.u is None:
        want_h, want_v = planes.to_rgb(yc), planes.to_rgb(yr)
    else:
        sx, sy = 1 << planes.sub_x, 1 << planes.sub_y
        uc, ur = projection_means(planes.u, rows / sy, cols / sx)
        vc, vr = projection_means(planes.v, rows / sy, cols / sx)
        want_h, want_v = planes.to_rgb(yc, uc, vc), planes.to_rgb(yr, ur, vr)
    assert np.allclose(h, want_h, rtol=0, atol=1e-4) and np.allclose(v, want_v, rtol=0, atol=1e-4)


def test_the_camera_pipeline_holds_one_opencv_thread_for_its_decode_and_gives_it_back(tmp_path):
    # A toggle per call once OpenCV's pool has worked rebuilds it (0.3-0.7 ms, four a frame):
    # the pipeline sets one thread for the whole decode, and a library caller's setting is back after.
    import cv2

    from clips import write_clip
    from wallcli.camera.pipeline import CameraPipeline
    from wallcli.io.video import open_video

    rng = np.random.default_rng(5)
    clip = write_clip(tmp_path / "wall.mp4", lambda i: 120 + rng.normal(0, 2, (72, 96, 3)), 12)
    before = cv2.getNumThreads()
    try:
        cv2.setNumThreads(3)
        with open_video(clip) as reader:
            inside = [cv2.getNumThreads() for _ in CameraPipeline(reader).frames()]
        assert len(inside) == 12 and set(inside) == {1}
        assert cv2.getNumThreads() == 3
    finally:
        cv2.setNumThreads(before)
