"""Camera shake regressed out of the profiles (issue 27 point 2): the projector measures each
frame's sub-pixel shift on both axes (count's horizontal-only path too), and the corrections fit
every bin's response to it and remove it, leaving a hidden person's light."""
from __future__ import annotations

import json

import numpy as np
import pytest

from test_stabilize import _frame, _wall

T = 300


def _track(seed: int, rms: float) -> np.ndarray:
    """A smooth random camera path (AR(1), time scale 0.3 s at 30 fps), ``rms`` px per axis."""
    rng = np.random.default_rng(seed)
    a = np.exp(-1 / 9.0)
    e = rng.standard_normal((T, 2)) * rms * np.sqrt(1 - a * a)
    s = np.zeros((T, 2))
    for i in range(1, T):
        s[i] = a * s[i - 1] + e[i]
    return s - s[0]


def _person(tex: np.ndarray) -> np.ndarray:
    """(T, H, W) relative light of a hidden person: a broad bump sweeping along the wall, 1 %."""
    h, w = tex.shape
    x = np.arange(w)[None, :]
    t = np.arange(T)[:, None]
    centre = w * (0.3 + 0.4 * (0.5 + 0.5 * np.sin(2 * np.pi * t / 140.0)))
    bump = 0.01 * np.exp(-0.5 * ((x - centre) / (0.12 * w)) ** 2)
    return bump[:, None, :].repeat(h, axis=1).astype(np.float32)


def _frames(seed: int, rms: float):
    tex = _wall(seed)
    light = _person(tex)
    track = _track(seed + 1, rms) if rms else np.zeros((T, 2))
    rng = np.random.default_rng(seed + 2)
    return [_frame(tex * (1 + light[i]), dx, dy, noise=0.7, rng=rng) for i, (dx, dy) in enumerate(track)], track


def _profiles(frames, register=True):
    from wallcli.io.video import Planes
    from wallcli.signal.blocks import RgbProjector, check_roi

    roi = check_roi(None, frames[0].shape[1], frames[0].shape[0])
    proj = RgbProjector(roi, 64, vertical=False, register=register)
    rows, shifts = [], []
    for f in frames:
        h, _ = proj(Planes(f, None, None, kind="gray", full_range=True))
        rows.append(h)
        shifts.append(proj.shift)
    return np.array(rows), np.array(shifts)


def _correct(rows, shifts, shake=True):
    from wallcli.camera import corrections as C

    win = rows[-256:].transpose(1, 0, 2)[None].astype(np.float32)  # (1, bins, T, 3)
    out, found = C.correct_windows([win], [np.zeros((1, 64, 3), np.float32)], 30.0,
                                   options=C.Options(deflicker=False, exposure=False, shake=shake),
                                   shifts=shifts[-256:][None])
    return out[0][0].transpose(1, 0, 2), found[0]


def _dev(a):
    return a - a.mean(axis=0)


@pytest.mark.parametrize("seed", [0, 1])
def test_shake_is_regressed_out_and_the_persons_light_kept(seed):
    still, _ = _frames(seed, 0.0)
    shaking, track = _frames(seed, 0.5)
    r0, _ = _profiles(still)
    r1, sh = _profiles(shaking)
    # both axes measured, though the projection is horizontal only (count's path)
    assert np.abs(sh - track).max() < 0.12
    fixed, found = _correct(r1, sh)
    ref = _dev(r0[-256:])
    before = np.sqrt(np.mean((_dev(r1[-256:]) - ref) ** 2))
    after = np.sqrt(np.mean((_dev(fixed) - ref) ** 2))
    assert before > 0.5  # the door frame's edges swing by codes
    assert after < 0.1 * before
    # (a fit on the levels, not their frame-to-frame changes, left 0.12: a slow light taken by chance)
    # the person's light (the still clip's plot) survives: its pattern and its size
    signal = np.sqrt(np.mean(ref ** 2))
    assert after < 0.3 * signal
    assert np.corrcoef(_dev(fixed).ravel(), ref.ravel())[0, 1] > 0.98
    (f,) = [x for x in found if x["kind"] == "shake"]
    assert f["rms_px"] == pytest.approx(np.sqrt(np.mean(np.sum(_dev(track[-256:]) ** 2, axis=1))), rel=0.15)


def test_a_still_camera_and_no_shake_option_change_nothing():
    still, _ = _frames(3, 0.0)
    r0, sh0 = _profiles(still)
    assert np.sqrt(np.mean(sh0 ** 2)) < 0.05  # a still camera's measured shifts are noise
    fixed, found = _correct(r0, sh0)
    assert found == [] and np.array_equal(fixed, r0[-256:].astype(np.float32))
    shaking, _ = _frames(3, 0.5)
    r1, sh1 = _profiles(shaking)
    fixed, found = _correct(r1, sh1, shake=False)
    assert found == [] and np.array_equal(fixed, r1[-256:].astype(np.float32))


def test_unshake_needs_shifts_that_explain_the_profiles():
    from wallcli.camera.shake import unshake

    rng = np.random.default_rng(4)
    # profiles that do not move with the camera (a plain wall): a slow light and the sensor's noise
    slow = np.cumsum(rng.standard_normal((256, 40)), axis=0) * 0.1
    series = slow + 0.1 * rng.standard_normal((256, 40))
    shifts = _track(4, 0.5)[:256]
    out, finding = unshake(series, shifts)
    assert finding is None and out is series or np.array_equal(out, series)
    moved = series + 3.0 * shifts[:, :1] - 2.0 * shifts[:, 1:] ** 2
    out, finding = unshake(moved, shifts)
    assert finding is not None and finding["explained"] > 0.5
    shake = np.sqrt(np.mean(_dev(moved - series) ** 2))
    assert np.sqrt(np.mean((_dev(out) - _dev(series)) ** 2)) < 0.05 * shake


def test_count_lists_shake_and_no_shake_turns_it_off(tmp_path, run_cli):
    from wallcli.sim.views import encode

    frames, _ = _frames(5, 0.5)
    path = encode((np.repeat(f[:, :, None], 3, axis=2) for f in frames), tmp_path / "shaking.mp4", fps=30.0, crf=0)
    code, out, err = run_cli("count", path, "--json")
    assert code == 0, err
    assert "shake" in [c["kind"] for c in json.loads(out)["corrections"]]
    code, out, err = run_cli("count", path, "--json", "--no-shake")
    assert code == 0, err
    assert "shake" not in [c["kind"] for c in json.loads(out)["corrections"]]


def _snr(frames, shake: bool):
    from wallcli.camera.corrections import Options
    from wallcli.io.video import Planes
    from wallcli.snr.estimate import SnrAccumulator

    acc = SnrAccumulator((0, 0, frames[0].shape[1], frames[0].shape[0]),
                         corrections=Options(deflicker=False, exposure=False, shake=shake), fps=30.0)
    for f in frames:
        acc.update(Planes(f, None, None, kind="gray", full_range=True))
    res = acc.result()
    return {s.block: float(s.snr_db[1]) for s in res.scales}, acc.corrections


def test_the_snr_of_a_shaking_clip_is_the_still_clips():
    still, _ = _frames(0, 0.0)
    shaking, _ = _frames(0, 0.5)
    ref, found = _snr(still, True)
    assert found == []  # a still camera: nothing fitted
    off, _ = _snr(shaking, False)
    on, found = _snr(shaking, True)
    assert [f["kind"] for f in found] == ["shake"]
    assert abs(off[8] - ref[8]) > 1.0  # the door frame's edges swing: the SNR is far off
    for block in (4, 8, 16, 32):  # within 10 % in power (0.41 dB) wherever blocks average the noise
        assert abs(on[block] - ref[block]) < 0.41, (block, on[block], ref[block])


def test_shake_sums_give_the_regressed_series_sums_exactly():
    """The SNR path's sums after the fact equal those of the series with the fit removed."""
    from wallcli.camera.shake import ShakeSums, regressors

    rng = np.random.default_rng(7)
    t, p = 120, 6
    shifts = _track(7, 0.5)[:t]
    x = np.array([regressors(*s) for s in shifts])
    y = np.cumsum(rng.standard_normal((t, p)), axis=0) * 0.2 + x @ rng.standard_normal((5, p))
    c = (y - y[0]).astype(np.float32)  # centred on the first frame, as the estimator keeps them
    sums = ShakeSums((p,))
    sums.first(*shifts[0])
    for i in range(1, t):
        sums.add(c[i], c[i] - c[i - 1], *shifts[i])
    d = np.diff(c, axis=0).astype(np.float64)  # float32 differences, as the estimator takes them
    c64 = c.astype(np.float64)
    s1, s2, sd, ds = c64.sum(0), (c64 ** 2).sum(0), (d ** 2).sum(0), d.sum(0)
    got = sums.corrected(s1, s2, sd, ds, sums.xc, sums.dxd)
    dx = np.diff(x, axis=0)
    beta = np.linalg.lstsq(dx, d, rcond=None)[0]  # on the changes, as unshake fits them
    c2 = c - x @ beta
    d2 = d - dx @ beta
    want = (c2.sum(0), (c2 ** 2).sum(0), (d2 ** 2).sum(0), d2.sum(0))
    for g, w in zip(got, want):
        np.testing.assert_allclose(g, w, rtol=1e-6, atol=1e-6)


def test_shake_is_corrected_in_answers_read_from_a_plot(tmp_path, run_cli):
    """Issue 38 item 3: stplot keeps each frame's measured shift in the .npz, so count read from the
    plot regresses the shake out as count read from the video does."""
    from wallcli.sim.views import encode

    frames, _ = _frames(5, 0.5)
    path = encode((np.repeat(f[:, :, None], 3, axis=2) for f in frames), tmp_path / "shaking.mp4", fps=30.0, crf=0)
    npz = tmp_path / "p.npz"
    code, _, err = run_cli("stplot", path, "-o", npz)
    assert code == 0, err
    code, out, err = run_cli("count", npz, "--json")
    assert code == 0, err
    from_plot = json.loads(out)
    code, out, err = run_cli("count", path, "--json")
    from_video = json.loads(out)
    kinds = [c["kind"] for c in from_plot["corrections"]]
    assert "shake" in kinds and kinds == [c["kind"] for c in from_video["corrections"]]
    assert from_plot["label"] == from_video["label"]
    code, out, err = run_cli("count", npz, "--json", "--no-shake")
    assert code == 0 and "shake" not in [c["kind"] for c in json.loads(out)["corrections"]]
