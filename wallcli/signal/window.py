"""What the networks see: 256-sample windows of space-time plots at a canonical 30 fps.

Training (simulated clips) and inference (any video) both go through these functions, so the
model sees at run time exactly what it saw in training.

Decisions (the paper is silent on them):
- Canonical rate 30 fps: 256 samples = 8.533 s. Other rates are resampled by linear
  interpolation on the frames' own timestamps (which also regularises variable frame rates).
  Any clip of >= 8.6 s therefore gives a window, whatever its frame rate.
- ``normalize_window`` (version 1): remove each (position, colour) mean over the window, then
  divide by the window's RMS over everything. Signals span orders of magnitude (distance^-4,
  light level, exposure); dividing by the RMS makes the input scale-free while keeping the
  relative strength of colours and positions.
- ``normalize_window`` version 2 (``--preprocessing v2`` in training; the card says which one a
  model needs): the same mean removal, then the window in units of its frame-to-frame noise
  (sigma^2 = half the mean square of the frame differences, paper suppl. §3.2), compressed
  by asinh. Version 1 lets the strongest mover set the scale, so a second person 20 dB fainter
  but well above the noise comes out tiny; in noise units every mover above the noise is of
  order one or more, and asinh keeps a mover 1000x over the noise within about 8.
"""

from __future__ import annotations

from collections import deque
from functools import lru_cache
from typing import Iterator

import numpy as np

CANONICAL_FPS = 30.0
WINDOW = 256
BINS = 64
DEFAULT_STRIDE = 64
NORMALIZATION = "wallcli.signal.window.normalize_window v1"  # the default, and what older cards say
NORMALIZATION_V2 = "wallcli.signal.window.normalize_window v2"
NORMALIZATION_V3 = "wallcli.signal.window.normalize_window v3"
NORMALIZATION_TEXT = {
    NORMALIZATION: "per (bin, colour) temporal mean over the window removed, then divided by the window's "
                   "global RMS; channels first (N, 3, bins, time)",
    NORMALIZATION_V2: "per (bin, colour) temporal mean over the window removed, divided by the window's "
                      "frame-to-frame noise sigma (sigma^2 = half the mean square of the differences between "
                      "consecutive samples, over all bins and colours), then asinh; channels first (N, 3, bins, time)",
    NORMALIZATION_V3: "per (bin, colour) temporal mean over the window removed; then, per sample and colour, the "
                      "whole-wall light change (the least-squares fit of a constant plus the wall's mean level profile "
                      "over the bins) removed; then divided by the window's global RMS; channels first (N, 3, bins, time)",
}
# what each version needs besides the window: v3 needs the raw level the window is relative to
NEEDS_OFFSET = {NORMALIZATION_V3}


# A gap in the timestamps (frames lost) up to one window long is interpolated over like any
# resampling: the windows across it are flagged by the view check ('frame gap'), and it costs at most
# a window's rows. A longer one would put whole windows inside lost time, answered from invented
# samples, at a cost that grows with the gap (a 10,000 s jump: 300,000 rows): the grid restarts after it.
MAX_BRIDGE = WINDOW / CANONICAL_FPS  # s


def gap_starts(time: np.ndarray, bridge: float = MAX_BRIDGE) -> np.ndarray:
    """Indices of the frames that follow a jump of the timestamps longer than ``bridge`` seconds."""
    time = np.asarray(time, np.float64)
    return np.flatnonzero(np.diff(time) > bridge) + 1 if time.size > 1 else np.zeros(0, np.intp)


def resample(plot: np.ndarray, time: np.ndarray, fps: float = CANONICAL_FPS) -> tuple[np.ndarray, np.ndarray]:
    """Resample (bins, T, C) plot with timestamps ``time`` onto a uniform ``fps`` grid from time[0].

    A jump of the timestamps longer than :data:`MAX_BRIDGE` is not interpolated over: the grid
    restarts at the first frame after it (as :class:`StreamResampler` does when told of one), so it
    costs nothing and no sample is invented inside it; :func:`run_window_starts` keeps windows
    from spanning it."""
    plot = np.asarray(plot, np.float32)
    time = np.asarray(time, np.float64)
    cuts = gap_starts(time)
    if cuts.size:
        parts = [_resample_run(plot[:, a:b], time[a:b], fps)
                 for a, b in zip([0, *cuts], [*cuts, time.size])]
        return np.concatenate([p for p, _ in parts], axis=1), np.concatenate([g for _, g in parts])
    return _resample_run(plot, time, fps)


def _resample_run(plot: np.ndarray, time: np.ndarray, fps: float) -> tuple[np.ndarray, np.ndarray]:
    if time.size < 2:
        return plot.copy(), time.copy()
    n = int(np.floor((time[-1] - time[0]) * fps + 1e-6)) + 1
    grid = time[0] + np.arange(n) / fps
    idx = np.clip(np.searchsorted(time, grid, side="right") - 1, 0, time.size - 2)
    w = ((grid - time[idx]) / (time[idx + 1] - time[idx])).astype(np.float32)
    w = np.clip(w, 0.0, 1.0)[None, :, None]
    out = plot[:, idx] * (1 - w) + plot[:, idx + 1] * w
    return out.astype(np.float32), grid


def window_starts(length: int, window: int = WINDOW, stride: int = DEFAULT_STRIDE) -> list[int]:
    """Start indices of every full window; the last one is aligned to the end so no tail is lost."""
    if length < window:
        return []
    starts = list(range(0, length - window + 1, max(1, int(stride))))
    if starts[-1] != length - window:
        starts.append(length - window)
    return starts


def run_window_starts(grid: np.ndarray, fps: float = CANONICAL_FPS, window: int = WINDOW,
                      stride: int = DEFAULT_STRIDE) -> list[int]:
    """:func:`window_starts` of each run of a :func:`resample` grid that has no gap in it: no
    window spans lost frames (each run's last window is aligned to the run's end)."""
    grid = np.asarray(grid, np.float64)
    cuts = np.flatnonzero(np.diff(grid) > 1.5 / fps) + 1 if grid.size > 1 else np.zeros(0, np.intp)
    return [a + s for a, b in zip([0, *cuts], [*cuts, grid.size]) for s in window_starts(int(b - a), window, stride)]


def normalize_window(x: np.ndarray, preprocessing: str = NORMALIZATION, offset: np.ndarray | None = None) -> np.ndarray:
    """(..., bins, WINDOW, 3) plot windows -> float32 (..., 3, bins, WINDOW) network input.

    ``preprocessing``: a model card's ``preprocessing`` (one of NORMALIZATION_TEXT's keys).
    ``offset`` (..., bins, 3): what was subtracted from the raw levels to give ``x`` (a plot's
    clip mean, a stream's first row); v3 needs it, the others ignore it.
    """
    axes = (-3, -2, -1)
    if preprocessing == NORMALIZATION_V3:
        return _normalize_v3(x, offset)
    if preprocessing == NORMALIZATION:
        # kept operation for operation as the shipped models were trained and their goldens recorded
        # (v2's faster channels-first order would move int8 inputs across quantisation steps)
        x = np.asarray(x, np.float32)
        x = x - x.mean(axis=-2, keepdims=True)
        rms = np.sqrt(np.mean(np.square(x, dtype=np.float64), axis=axes, keepdims=True)).astype(np.float32)
        x = x / np.maximum(rms, 1e-8)
        return np.ascontiguousarray(np.moveaxis(x, -1, -3))
    if preprocessing != NORMALIZATION_V2:
        raise ValueError(f"unknown preprocessing {preprocessing!r}")
    # channels first before reducing over time: the time axis is then contiguous (20x faster)
    x = np.ascontiguousarray(np.moveaxis(np.asarray(x, np.float32), -1, -3))
    x -= x.mean(axis=-1, keepdims=True)
    rms = np.sqrt(np.mean(np.square(x, dtype=np.float64), axis=axes, keepdims=True)).astype(np.float32)
    d = np.diff(x, axis=-1)
    sigma = np.sqrt(0.5 * np.mean(np.square(d, dtype=np.float64), axis=axes, keepdims=True)).astype(np.float32)
    # a window without frame noise (a synthetic or heavily filtered plot) must not divide by zero
    x /= np.maximum(sigma, np.maximum(1e-3 * rms, 1e-8))
    # asinh as log(|z| + sqrt(z^2 + 1)): numpy's float32 arcsinh is twice as slow; same to 3e-7
    a = np.abs(x)
    return np.copysign(np.log(a + np.sqrt(a * a + 1.0)), x).astype(np.float32, copy=False)


def _normalize_v3(x: np.ndarray, offset: np.ndarray | None) -> np.ndarray:
    """v3: v1 after removing, per sample and colour, the part of the profile that a change of the
    whole room's light explains.

    Mains flicker aliased to the frame rate, daylight drift and exposure steps multiply the whole
    wall's light: each sample's profile moves by a multiple of the wall's mean level profile
    (plus an offset for the camera's black level and tone curve). A person changes the light
    unevenly along the wall. Projecting every sample onto the complement of span{1, level}
    removes the first exactly, whatever its waveform, and keeps what differs from place to place,
    so no rule about frequencies or amplitudes is needed to tell flicker from a person. The price:
    a person so far away that the whole wall brightens evenly is removed too, as it cannot be
    told from a light change.
    """
    x = remove_light_changes(x, offset)
    rms = np.sqrt(np.mean(np.square(x), axis=(-3, -2, -1), keepdims=True))
    x = (x / np.maximum(rms, 1e-8)).astype(np.float32)
    return np.ascontiguousarray(np.moveaxis(x, -1, -3))


def remove_light_changes(x: np.ndarray, offset: np.ndarray | None) -> np.ndarray:
    """(..., bins, T, 3) windows relative to ``offset`` (..., bins, 3) -> float64 windows with each
    (bin, colour)'s temporal mean and, per sample and colour, the whole-wall light change removed
    (the projection of normalisation v3, before its scaling)."""
    x = np.asarray(x, np.float32)
    if offset is None:
        raise ValueError("normalisation v3 needs the windows' level offset")
    mean = x.mean(axis=-2, keepdims=True)  # (..., bins, 1, 3)
    level = (np.asarray(offset, np.float32)[..., None, :] + mean).astype(np.float64)  # raw mean level
    x = (x - mean).astype(np.float64)
    lc = level - level.mean(axis=-3, keepdims=True)
    norm = np.sqrt(np.sum(lc * lc, axis=-3, keepdims=True))
    # a flat wall (or a plot without its level) has no level direction beyond the constant
    lc = np.where(norm > 1e-6 * np.maximum(np.abs(level).mean(axis=-3, keepdims=True), 1e-9), lc / np.maximum(norm, 1e-30), 0.0)
    # both directions' components read before either is taken off (they are orthogonal); the
    # constant's is the mean over the bins; taken off in place, two (bins, T, 3) temporaries fewer
    along = np.sum(x * lc, axis=-3, keepdims=True)
    x -= x.mean(axis=-3, keepdims=True)
    x -= lc * along
    return x


SIGNAL_FLOOR_DB = -30.0
# The signal is what changes the wall coherently: a hidden person's light reaches many bins at
# once, so it lives in the plot's coarse spatial components (a DCT across the bins, under
# COARSE of them), while the fine ones (from COARSE on) hold what changes bin by bin: the camera's
# noise and a codec's residue. A codec that holds a block's noise for frames and then steps it
# changes slowly, so its residue survives the frame-to-frame noise estimate and was read as signal
# (HD CRF 23 exports of empty rooms: 0.4-15 dB); bin by bin, it is as strong in the fine
# components as in the coarse ones at every frequency, and is taken off with them.
COARSE = 0.25  # of the bins
MIN_BINS = 16  # fewer bins: no spatial split (the plot's whole power over its noise, as before)
# The noise that competes with a person is the noise at a person's frequencies. Frame-to-frame
# differences read it at the highest ones, which is the same only for white noise: a camera's
# temporal noise reduction, a codec's held blocks and the resampling of a 24 fps clip to 30 all
# take noise off the high frequencies and leave the low ones. How much is read where a person's
# light is not (the fine spatial components), at SLOW_HZ against frame to frame; the
# frame-to-frame figure is scaled up by that ratio where it is over 1 (:func:`_colour`).
SLOW_HZ = (0.3, 2.5)
# The fine components' power at one frequency is a mean over the three colours of two-degree
# chi-square variables (real, imaginary): its median is this share of its mean.
_MEDIAN_CHI2_6 = 0.8907


@lru_cache(maxsize=8)
def _dct_rows(n: int) -> np.ndarray:
    k = np.arange(n)[:, None]
    b = np.cos(np.pi * (np.arange(n)[None] + 0.5) * k / n)
    b = b / np.linalg.norm(b, axis=1, keepdims=True)
    b.setflags(write=False)  # shared by every window of a run
    return b


@lru_cache(maxsize=8)
def _taper(T: int) -> tuple[np.ndarray, float]:
    """The Hann taper of a window of ``T`` samples (as a (T, 1) column) and its power sum."""
    taper = np.hanning(T)
    col = taper[:, None].copy()
    col.setflags(write=False)
    return col, float(np.sum(taper * taper))


def _coarse(bins: int) -> int:
    """How many of ``bins`` DCT components are coarse (the mean among them)."""
    return max(2, int(round(COARSE * bins)))


def _spectrum(y: np.ndarray) -> np.ndarray:
    """(..., bins, T, 3) light-removed windows -> (..., bins - 1, T // 2 + 1) the power of each
    spatial component but the mean (a DCT across the bins) at each temporal frequency, per sample
    (tapered; the colours averaged)."""
    bins, T = y.shape[-3], y.shape[-2]
    # component 0 (the wall's mean) is gone; a matrix product over (bins, T*3) (einsum took 4x as
    # long; the CLI holds BLAS to one thread, so none spins on the decoder's cores)
    lead = y.shape[:-3]
    z = np.matmul(_dct_rows(bins)[1:], np.ascontiguousarray(y).reshape(*lead, bins, T * 3))
    z = z.reshape(*lead, bins - 1, T, 3)
    taper, taper_power = _taper(T)
    spec = np.fft.rfft(z * taper, axis=-2)
    return np.mean(spec.real ** 2 + spec.imag ** 2, axis=-1) / taper_power


def _fine_level(power: np.ndarray, bins: int) -> np.ndarray:
    """The fine components' level at each frequency of a :func:`_spectrum` (..., F): their median
    over components, for chi-square's median (read by :func:`_coherent` and :func:`_colour`)."""
    return np.median(power[..., _coarse(bins) - 1:, :], axis=-2) / _MEDIAN_CHI2_6


def _coherent(power: np.ndarray, bins: int, white: np.ndarray | None = None) -> np.ndarray:
    """The power of the windows' spatially coherent change, per sample and bin, from their
    :func:`_spectrum`: the coarse components' power at each frequency less the level the fine
    components show at it (:func:`_fine_level`, or ``white`` where already read)."""
    coarse = _coarse(bins)
    if white is None:
        white = _fine_level(power, bins)  # (..., F)
    return np.sum(np.mean(power[..., :coarse - 1, :] - white[..., None, :], axis=-1), axis=-1) / bins


def _colour(power: np.ndarray, bins: int, T: int, step: np.ndarray, fps: float,
            white: np.ndarray | None = None) -> np.ndarray | None:
    """How much more noise the windows hold at a person's frequencies (SLOW_HZ) than their
    frame-to-frame figure ``step`` says (1: white), read where a person's light is not: the fine
    spatial components' level in their :func:`_spectrum` (:func:`_fine_level`, or ``white`` where
    already read); None where the window has no such frequency."""
    f = np.fft.rfftfreq(T, 1.0 / fps)
    slow = (f >= SLOW_HZ[0]) & (f <= SLOW_HZ[1])
    if not slow.any():
        return None
    if white is None:
        white = _fine_level(power, bins)
    low = np.mean(white[..., slow], axis=-1)
    return low / np.maximum(step, 1e-30)


def window_power_db(parts: list[tuple[np.ndarray, np.ndarray]]) -> np.ndarray:
    """The plot windows' whole power less their frame-to-frame noise, over that noise, in dB (the
    estimator of paper suppl. §3.2, whole-wall light changes removed; floored at SIGNAL_FLOOR_DB).
    What ``signal_db`` was until 2026-11-27, kept as a feature (``wallcli.signal.features``) because
    the shipped models were trained on it; :func:`window_signal_db` is the figure reported."""
    total = noise = 0.0
    for x, off in parts:
        y = remove_light_changes(x, off)
        total = total + np.mean(np.square(y), axis=(-3, -2, -1))
        noise = noise + 0.5 * np.mean(np.square(np.diff(y, axis=-2)), axis=(-3, -2, -1))
    ratio = np.asarray(total - noise, np.float64) / np.maximum(np.asarray(noise, np.float64), 1e-30)
    return np.maximum(10 * np.log10(np.maximum(ratio, 1e-30)), SIGNAL_FLOOR_DB)


def window_signal_db(parts: list[tuple[np.ndarray, np.ndarray]], fps: float = CANONICAL_FPS) -> np.ndarray:
    """How strong the signal of plot windows is, in dB over their noise, after the whole-wall
    light changes are removed.

    ``parts``: [(windows (..., bins, T, 3), offsets (..., bins, 3))], e.g. the horizontal and the
    vertical plot, sampled at ``fps``. Signal power = the power of what changes the bins together
    (the coarse spatial components less the fine ones' level, :func:`_coherent`), so that a codec's
    residue, which changes bin by bin, is not read as a person. Noise power = half the mean square
    of the differences between consecutive samples (paper suppl. §3.2), scaled up where the noise
    at a person's frequencies is larger (what a blend, a codec or a resampling kept there,
    :func:`_colour`). Floored at SIGNAL_FLOOR_DB (a window of pure noise measures about 0 signal,
    whose ratio is meaningless).
    """
    signal = noise = 0.0
    colour = None
    for i, (x, off) in enumerate(parts):
        y = remove_light_changes(x, off)
        n = 0.5 * np.mean(np.square(np.diff(y, axis=-2)), axis=(-3, -2, -1))
        if y.shape[-3] >= MIN_BINS and y.shape[-2] >= 8:
            power = _spectrum(y)
            white = _fine_level(power, y.shape[-3])  # one median for both reads
            s = _coherent(power, y.shape[-3], white)
            if i == 0:
                # the noise's colour is the camera's; it is read on the first plot (the horizontal
                # one: a column averages the wall's rows, so a masked line of text, which fills
                # whole rows of the vertical plot, is a small part of each)
                colour = _colour(power, y.shape[-3], y.shape[-2], n, fps, white)
        else:
            s = np.mean(np.square(y), axis=(-3, -2, -1)) - n
        signal, noise = signal + s, noise + n
    if colour is not None:
        noise = noise * np.maximum(colour, 1.0)
    ratio = np.asarray(signal, np.float64) / np.maximum(np.asarray(noise, np.float64), 1e-30)
    return np.maximum(10 * np.log10(np.maximum(ratio, 1e-30)), SIGNAL_FLOOR_DB)


class StreamResampler:
    """Online version of :func:`resample` for live input: push timestamped rows, get 30 fps rows.

    Grid times are ``t0 + k / fps`` with the same end tolerance as :func:`resample` (not a running
    sum, which drifts), so a stream yields exactly the rows the batch path computes.
    """

    def __init__(self, fps: float = CANONICAL_FPS):
        self.fps = float(fps)
        self.restart()

    def restart(self) -> None:
        """Frames were lost before the next row (a jump of the timestamps over :data:`MAX_BRIDGE`):
        start a new grid at it instead of interpolating over the gap."""
        self._prev = None  # (t, row)
        self._t0 = None
        self._k = 0  # index of the next grid time

    def push(self, t: float, row: np.ndarray) -> Iterator[tuple[float, np.ndarray]]:
        row = np.asarray(row, np.float32)
        if self._prev is None:
            self._prev, self._t0, self._k = (t, row), t, 1
            yield t, row
            return
        t0, r0 = self._prev
        if t <= t0:
            return
        while self._k <= (t - self._t0) * self.fps + 1e-6:
            g = self._t0 + self._k / self.fps
            w = np.float32(min(max((g - t0) / (t - t0), 0.0), 1.0))
            yield g, r0 * (1 - w) + row * w
            self._k += 1
        self._prev = (t, row)


class StreamWindower:
    """Collect resampled rows; emit (start_time, end_time, window (bins, WINDOW, C)) every ``stride``.

    Rows more than 1.5 grid steps apart (``fps``: the grid's rate) are either side of a gap (see
    :meth:`StreamResampler.restart`): a window never spans one. The run before it ends with its
    end-aligned window (as :func:`run_window_starts`), returned by the push that crosses the gap.
    """

    def __init__(self, window: int = WINDOW, stride: int = DEFAULT_STRIDE, fps: float = CANONICAL_FPS):
        self.window, self.stride = int(window), max(1, int(stride))
        if self.window < 2:
            raise ValueError("a window holds at least 2 rows")
        self.step = 1.0 / float(fps)
        self._rows: deque = deque(maxlen=self.window)
        self._times: deque = deque(maxlen=self.window)
        self._since = 0  # rows since the last window emitted (or since the run began)
        self._run = 0  # rows since the last gap
        self._count = 0
        self.emitted = 0  # windows returned by push

    def push(self, t: float, row: np.ndarray):
        """Add one (bins, C) row at time ``t``; returns a window tuple when one completes, else None."""
        done = None
        if self._times and float(t) - self._times[-1] > 1.5 * self.step:
            done = self.pending()  # the run before the gap: its end-aligned window
            self._rows.clear()
            self._times.clear()
            self._since = self._run = 0
        self._rows.append(np.asarray(row, np.float32))
        self._times.append(float(t))
        self._count += 1
        self._run += 1
        self._since += 1
        if done is None and self._run >= self.window and (self._run == self.window or self._since >= self.stride):
            self._since = 0
            done = self.last()
        self.emitted += done is not None
        return done

    @property
    def count(self) -> int:
        return self._count

    def pending(self):
        """The current run's end-aligned window when push has not returned it, else None."""
        return self.last() if self._since and self._run >= self.window else None

    def last(self):
        """The newest full window (start, end, window), emitted or not; None before ``window`` rows
        since the start or the last gap.

        The batch path's final window is aligned to the end of the clip: at the end of a stream
        it is this one (the buffer holds exactly the last ``window`` rows).
        """
        if self._run < self.window:
            return None
        return self._times[0], self._times[-1], np.stack(self._rows, axis=1)
