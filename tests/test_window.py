"""What the networks see: window normalisation v1 (RMS) and v2 (noise units, asinh)."""
import numpy as np
import pytest

from wallcli.signal.window import (NORMALIZATION, NORMALIZATION_TEXT, NORMALIZATION_V2, NORMALIZATION_V3, normalize_window,
                                   window_power_db, window_signal_db)


def _window(strong: float, faint: float, sigma: float = 1.0, seed: int = 0) -> np.ndarray:
    """(64, 256, 3): a strong slow mover at bins 10-20, a faint one at 40-50, white noise."""
    rng = np.random.default_rng(seed)
    t = np.arange(256) / 30.0
    x = rng.normal(0.0, sigma, (64, 256, 3))
    x[10:20] += strong * np.sin(2 * np.pi * 0.3 * t)[None, :, None]
    x[40:50] += faint * np.sin(2 * np.pi * 0.5 * t + 1.0)[None, :, None]
    return (x + 120.0).astype(np.float32)  # a wall level that both versions remove


@pytest.mark.parametrize("prep", list(NORMALIZATION_TEXT))
def test_layout_and_scale_invariance(prep):
    x = _window(50.0, 3.0)
    zero = np.zeros((64, 3), np.float32)  # the windows carry their level themselves
    y = normalize_window(x, prep, zero)
    assert y.shape == (3, 64, 256) and y.dtype == np.float32
    if prep == NORMALIZATION:  # (asinh of a zero-mean signal need not be zero-mean)
        assert np.allclose(y.mean(axis=-1), 0.0, atol=1e-3) and np.isclose(np.sqrt(np.mean(y**2)), 1.0, atol=1e-3)
    # exposure or gain scale every value alike: the input must not change
    assert np.allclose(normalize_window(7.0 * (x - 120.0) + 30.0, prep, zero), y, atol=1e-3)
    batch = normalize_window(np.stack([x, _window(0.0, 0.0, seed=1)]), prep, np.stack([zero, zero]))
    assert batch.shape == (2, 3, 64, 256) and np.allclose(batch[0], y, atol=1e-6)


def test_v2_is_in_units_of_the_frame_noise():
    y = normalize_window(_window(0.0, 0.0, sigma=3.0), NORMALIZATION_V2)
    # pure white noise: x / sigma ~ N(0, 1), asinh of which has RMS ~0.8
    assert 0.75 < float(np.sqrt(np.mean(y**2))) < 0.85


def test_v2_keeps_a_faint_second_mover_that_v1_scales_away():
    x = _window(strong=300.0, faint=6.0)  # 50 dB above the noise, and 15 dB

    def ratio(prep):
        y = normalize_window(x, prep)
        return float(np.abs(y[:, 40:50]).max() / np.abs(y[:, 10:20]).max())

    assert ratio(NORMALIZATION) < 0.05  # the faint mover is a few % of the input's range
    assert ratio(NORMALIZATION_V2) > 0.3  # over a third of it: the net can see it


def test_unknown_preprocessing_is_refused():
    with pytest.raises(ValueError, match="unknown preprocessing"):
        normalize_window(_window(1.0, 0.0), "v9")


def test_v2_survives_a_window_without_frame_noise():
    x = np.zeros((64, 256, 3), np.float32)
    x[5] = np.linspace(0, 1, 256)[:, None]  # a smooth ramp, no noise at all
    assert np.all(np.isfinite(normalize_window(x, NORMALIZATION_V2)))
    assert np.all(normalize_window(np.zeros((64, 256, 3), np.float32), NORMALIZATION_V2) == 0)


def _lit_wall(flicker: float, person: float, seed: int = 0):
    """(window relative to its first sample's level, that level): a wall with a level profile
    (vignetting, a lamp's gradient) whose whole light flickers, plus a person's moving shadow."""
    rng = np.random.default_rng(seed)
    t = np.arange(256) / 30.0
    level = (80 + 60 * np.exp(-((np.arange(64) - 25) / 30.0) ** 2))[:, None] * np.array([1.0, 0.9, 0.7])
    gain = 1 + flicker * np.sin(2 * np.pi * 2.0 * t)  # mains flicker aliased to 2 Hz
    raw = level[:, None, :] * gain[None, :, None] + rng.normal(0, 0.3, (64, 256, 3))
    centre = 10 + 40 * t / t[-1]
    raw -= person * np.exp(-((np.arange(64)[:, None] - centre[None]) / 5.0) ** 2)[..., None]
    off = raw[:, 0, :].copy()
    return (raw - off[:, None, :]).astype(np.float32), off.astype(np.float32)


def test_v3_removes_a_change_of_the_whole_rooms_light():
    # 1 % flicker is ~1 code value here, many times the person's 0.3: v1 sees mostly flicker
    with_flicker, off = _lit_wall(flicker=0.01, person=0.3)
    without, off0 = _lit_wall(flicker=0.0, person=0.3)
    a, b = normalize_window(with_flicker, NORMALIZATION_V3, off), normalize_window(without, NORMALIZATION_V3, off0)
    assert np.corrcoef(a.ravel(), b.ravel())[0, 1] > 0.95
    v1a, v1b = normalize_window(with_flicker, NORMALIZATION), normalize_window(without, NORMALIZATION)
    assert np.corrcoef(v1a.ravel(), v1b.ravel())[0, 1] < 0.5
    # the offset is what v3 needs: without it, a plot could not be told from its light
    with pytest.raises(ValueError):
        normalize_window(with_flicker, NORMALIZATION_V3)


def test_signal_db_measures_people_not_light_changes():
    flicker_only, off = _lit_wall(flicker=0.01, person=0.0)
    person, off_p = _lit_wall(flicker=0.01, person=3.0)
    quiet = window_signal_db([(flicker_only, off)])
    loud = window_signal_db([(person, off_p)])
    assert quiet < -10 and loud > 5
    # two plots add their powers; a batch gives one figure per window
    both = window_signal_db([(np.stack([person, flicker_only]), np.stack([off_p, off]))])
    assert both.shape == (2,) and both[0] > both[1]


def _wall(noise: np.ndarray, person: float, seed: int = 0):
    """(window relative to its level, the level) of a flat lit wall with ``noise`` (64, 256, 3)
    and a person's shadow, ``person`` codes deep, crossing it."""
    t = np.arange(256) / 30.0
    level = np.full((64, 3), 120.0)
    centre = 10 + 40 * t / t[-1]
    shadow = person * np.exp(-((np.arange(64)[:, None] - centre[None]) / 8.0) ** 2)[..., None]
    raw = level[:, None, :] + noise - shadow
    return (raw - level[:, None, :]).astype(np.float32), level.astype(np.float32)


def _blend(x: np.ndarray, a: float) -> np.ndarray:
    """A camera's temporal noise reduction along time: y = (1 - a) x + a y_prev."""
    y = np.empty_like(x)
    y[:, 0] = x[:, 0]
    for i in range(1, x.shape[1]):
        y[:, i] = (1 - a) * x[:, i] + a * y[:, i - 1]
    return y


def test_a_codecs_held_residue_is_not_read_as_a_signal():
    # each bin's noise held for 10-20 frames, then stepped (a codec's skipped blocks), bin by bin
    rng = np.random.default_rng(3)
    held = np.zeros((64, 256, 3))
    for b in range(64):
        edges = np.cumsum(rng.integers(10, 21, 30))
        steps = np.repeat(rng.normal(0, 1.0, (31, 3)), np.diff(np.concatenate([[0], edges, [10 ** 6]]))[:31].clip(0), 0)
        held[b] = steps[:256]
    empty = _wall(held + rng.normal(0, 0.05, held.shape), person=0.0)
    # the whole power over frame-to-frame differences reads the steps as a strong signal
    assert window_power_db([empty])[()] > 5
    assert window_signal_db([empty])[()] < -3
    # a person stays a signal with the same residue
    someone = _wall(held + rng.normal(0, 0.05, held.shape), person=3.0)
    assert window_signal_db([someone])[()] > window_signal_db([empty])[()] + 8


def test_a_temporal_noise_blend_does_not_raise_the_signal():
    rng = np.random.default_rng(4)
    white = rng.normal(0, 1.0, (64, 256, 3))
    clean = _wall(white, person=4.0)
    blended = _wall(_blend(white, 0.65), person=4.0)
    # the blend takes noise off the high frequencies only: the frame-to-frame figure rises 11 dB
    assert window_power_db([blended])[()] > window_power_db([clean])[()] + 6
    assert abs(window_signal_db([blended])[()] - window_signal_db([clean])[()]) < 3


def test_on_white_noise_the_coherent_signal_is_the_whole_signal():
    rng = np.random.default_rng(5)
    for person in (4.0, 8.0, 16.0):  # 1-13 dB
        w = _wall(rng.normal(0, 1.0, (64, 256, 3)), person=person)
        assert abs(window_signal_db([w])[()] - window_power_db([w])[()]) < 1.5
