"""Stabilisation (issue 27): a camera that moves by a fraction of a pixel moves the profiles'
fine structure; LineShift finds the shift from the line sums, and the projector reads the bins
where the picture moved them, so a still wall's plot comes back."""
from __future__ import annotations

import numpy as np
import pytest


def _wall(seed=0, H=240, W=320, features=True):
    import cv2

    rng = np.random.default_rng(seed)
    tex = (120 + 4 * rng.standard_normal((H, W))).astype(np.float32)
    tex = cv2.GaussianBlur(tex, (0, 0), 1.0) + np.linspace(0, 30, W, dtype=np.float32)[None, :]
    if features:  # a door frame, a switch plate and a skirting board
        tex[:, int(0.7 * W):int(0.74 * W)] -= 35
        tex[100:140, 60:75] -= 40
        tex[int(0.9 * H):int(0.94 * H), :] -= 30
    return cv2.GaussianBlur(tex, (0, 0), 0.8)


def _frame(tex, dx, dy=0.0, noise=1.0, rng=None):
    import cv2

    m = np.float32([[1, 0, dx], [0, 1, dy]])
    f = cv2.warpAffine(tex, m, tex.shape[::-1], flags=cv2.INTER_CUBIC, borderMode=cv2.BORDER_REFLECT)
    if noise:
        f = f + noise * (rng or np.random.default_rng(1)).standard_normal(f.shape).astype(np.float32)
    return np.clip(f + 0.5, 0, 255).astype(np.uint8)


@pytest.mark.parametrize("dx", [0.3, -0.75, 1.4, -4.2])
def test_line_shift_finds_a_sub_pixel_shift_on_a_wall_with_features(dx):
    from wallcli.signal.blocks import LineShift

    tex = _wall()
    ls = LineShift()
    assert ls(_frame(tex, 0).sum(0).astype(np.float32)) == 0.0  # the reference
    est = ls(_frame(tex, dx).sum(0).astype(np.float32))
    assert est == pytest.approx(dx, abs=0.08)


def test_line_shift_says_nothing_on_a_plain_wall_or_under_its_floor():
    from wallcli.signal.blocks import LineShift

    tex = _wall(features=False)
    ls = LineShift()
    ls(_frame(tex, 0).sum(0).astype(np.float32))
    assert ls(_frame(tex, 1.0, rng=np.random.default_rng(5)).sum(0).astype(np.float32)) == 0.0
    ls = LineShift()
    tex = _wall()
    ls(_frame(tex, 0).sum(0).astype(np.float32))
    assert abs(ls(_frame(tex, 0.03).sum(0).astype(np.float32)) - 0.03) < 0.05


def test_a_shaking_wall_gives_the_still_walls_profiles_back():
    from wallcli.io.video import Planes
    from wallcli.signal.blocks import RgbProjector, check_roi

    tex = _wall()
    still = _frame(tex, 0.0, noise=0)
    roi = check_roi(None, still.shape[1], still.shape[0])

    def profiles(frames, stabilize):
        proj = RgbProjector(roi, 64, vertical=True, stabilize=stabilize)
        out = [proj(Planes(f, None, None, kind="gray", full_range=True)) for f in frames]
        return np.array([h for h, _ in out]), np.array([v for _, v in out]), proj.shifts

    moves = [(0, 0), (0.6, -0.4), (-1.1, 0.8), (1.7, 0.3)]
    frames = [_frame(tex, dx, dy, noise=0) for dx, dy in moves]
    h0, v0, _ = profiles([still] * len(frames), False)
    h_off, v_off, _ = profiles(frames, False)
    h_on, v_on, log = profiles(frames, True)
    # interior bins (the motion pushes the picture past the frame's edge at the ends)
    err_off = np.abs(h_off - h0)[:, 3:-3].max()
    err_on = np.abs(h_on - h0)[:, 3:-3].max()
    assert err_off > 1.0  # a door frame's edge moving by a pixel moves its bins by codes
    assert err_on < 0.15 * err_off
    assert np.abs(v_on - v0)[:, 3:-3].max() < 0.3 * np.abs(v_off - v0)[:, 3:-3].max()
    s = log.summary()
    assert s["kind"] == "shake" and s["frames"] == 3 and s["max_px"] == pytest.approx(np.hypot(1.7, 0.3), abs=0.15)


def test_without_stabilisation_nothing_changes():
    from wallcli.io.video import Planes
    from wallcli.signal.blocks import RgbProjector, check_roi

    tex = _wall()
    f = _frame(tex, 0.9, noise=0)
    roi = check_roi(None, f.shape[1], f.shape[0])
    a = RgbProjector(roi, 64, stabilize=False)
    b = RgbProjector(roi, 64, stabilize=True)
    first = _frame(tex, 0.0, noise=0)
    for p in (a, b):
        p(Planes(first, None, None, kind="gray", full_range=True))
    ha, _ = a(Planes(f, None, None, kind="gray", full_range=True))
    hb, _ = b(Planes(f, None, None, kind="gray", full_range=True))
    assert a.shifts.summary() is None and b.shifts.summary()["frames"] == 1
    assert not np.allclose(ha, hb)
