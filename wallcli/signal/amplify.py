"""The amplified-signal pipeline (seed Figure 1), as a streaming state object.

Everything happens on a small grid of exact block means (``blocks.rgb_grid``), never on full
frames: spatial area-averaging and temporal mean removal are both linear, so averaging first and
removing the mean second equals the per-pixel order, at a tiny fraction of the cost, and memory is
a few grids whatever the video's length. Per frame:

1. ``grid``: the ROI's block means, float64 RGB code values (the caller computes it);
2. subtract a causal running mean (``ema`` by default, or a trailing ``window``);
3. optionally smooth in time (one-pole low-pass, time constant ``smooth_seconds``);
4. display = 128 + 127 tanh(gain x signal / 127), float32: linear (slope ``gain``) for a
   person's shade, bent smoothly towards 1 and 255 beyond the range, so nothing is cut flat to
   white or black, however strong (a hard clip turned strong shades into flat blobs). By default
   the display is grey, each block's luminance change (Rec. 709 weights): a shade darkens all
   colours together, and the colour noise of 4:2:0 chroma, three times the luma's, painted the
   wall in coloured blobs around it; ``colour=True`` shows each channel.

Warm-up. The ``ema`` mean is an expanding average until it has seen about ``mean_seconds`` of
video (weight max(1/n, 1 - exp(-dt/tau))), then a true EMA. Initialising an EMA from the first
frame alone would bake that frame's noise into the mean for many seconds, and a mean starting at
zero would make the first second blinding; the expanding average has neither problem. The
``window`` mean (``mean.RunningMean``) is an expanding average until its window fills, too.

Gain. Given, or automatic: the first ``calib_frames`` frames are held back (only their small
grids, plus whatever payload the caller attaches), the robust sigma (MAD) of their signal over
all cells, channels and frames is measured, and gain = 127 / (3 sigma), so +-3 robust sigma fill
the display range, as in the space-time plot PNGs. The gain then stays fixed for the whole video
(a constant gain keeps brightness comparable over time: a person entering later shows up as
stronger, instead of being normalised away). The sigma is floored at the quantisation noise of a
block mean, so a perfectly still calibration second cannot produce an absurd gain.

Block count and smoothing. Given, or chosen by :class:`AutoAmplifier` on the same calibration
frames: the SNR of the displayed blocks is measured for each step of :data:`AUTO_LADDER` (sharpest
first) and the first that reaches :data:`TARGET_SNR_DB` is used, else the best one.
"""

from __future__ import annotations

import math
from collections import deque
from typing import Any

import numpy as np

from wallcli.signal.mean import RunningMean

MEAN_MODES = ("ema", "window")
GREY = 128.0
# +-3 robust sigma onto +-127 display levels (same convention as plots.stplot.auto_gain).
SIGMAS_TO_FULL_SCALE = 3.0
LUMA = np.array([0.2126, 0.7152, 0.0722], np.float64)  # Rec. 709, as the space-time plot figures


def grid_shape(width: int, height: int, cells: int) -> tuple[int, int]:
    """(rows, cols) of a grid with ``cells`` blocks along the longer side and near-square blocks.

    Never more blocks than pixels: a block is at least one source pixel.
    """
    cells = max(1, int(cells))
    if width >= height:
        cols = min(cells, width)
        rows = max(1, min(height, round(cols * height / width)))
    else:
        rows = min(cells, height)
        cols = max(1, min(width, round(rows * width / height)))
    return int(rows), int(cols)


def quantisation_sigma(block_pixels: float, depth: int = 8) -> float:
    """Noise of a block mean of ``block_pixels`` uniformly quantised samples, in 8-bit code values."""
    step = 1.0 / float(1 << max(0, depth - 8))
    return step / math.sqrt(12.0) / math.sqrt(max(1.0, float(block_pixels)))


def robust_sigma(x: np.ndarray) -> float:
    """1.4826 x median absolute deviation: the spread of the bulk, blind to a few outliers."""
    x = np.asarray(x, np.float64).ravel()
    x = x[np.isfinite(x)]
    if x.size == 0:
        return 0.0
    s = 1.4826 * float(np.median(np.abs(x - np.median(x))))
    return s if s > 0 else float(np.std(x))


class _ExpandingEma:
    """EMA with time constant ``seconds`` whose first ~seconds are an expanding (cumulative) mean."""

    def __init__(self, seconds: float):
        self.seconds = float(seconds)
        self._mean: np.ndarray | None = None
        self._t = 0.0
        self._n = 0

    def update(self, t: float, x: np.ndarray) -> np.ndarray:
        self._n += 1
        if self._mean is None:
            self._mean = np.array(x, dtype=np.float64, copy=True)
        else:
            a = 1.0 - math.exp(-max(t - self._t, 0.0) / self.seconds)
            self._mean += max(a, 1.0 / self._n) * (x - self._mean)
        self._t = t
        return self._mean


class Amplifier:
    """Feed block-mean grids in time order with :meth:`push`; get display grids back.

    ``push`` returns a list of ``(payload, display)`` pairs: empty while the automatic gain is
    still calibrating, then everything held back at once, then one pair per call. Call
    :meth:`flush` at the end of the stream to get frames still held back (a clip shorter than
    the calibration). Payloads are returned untouched, in order (the CLI passes the original frame
    for ``--side-by-side``).
    """

    def __init__(
        self,
        *,
        mean: str = "ema",
        mean_seconds: float = 10.0,
        smooth_seconds: float = 0.0,
        gain: float | None = None,
        calib_frames: int = 60,
        sigma_floor: float = 0.0,
        colour: bool = False,
    ):
        if mean not in MEAN_MODES:
            raise ValueError(f"mean must be one of {MEAN_MODES}, got {mean!r}")
        if not mean_seconds > 0:
            raise ValueError("mean_seconds must be > 0")
        if smooth_seconds < 0:
            raise ValueError("smooth_seconds must be >= 0")
        self._mean = _ExpandingEma(mean_seconds) if mean == "ema" else RunningMean("window", mean_seconds)
        self.smooth_seconds = float(smooth_seconds)
        self.gain: float | None = None if gain is None else float(gain)
        self.auto_gain = gain is None
        self.sigma: float | None = None  # the robust sigma the automatic gain came from
        self.calib_frames = max(2, int(calib_frames))
        self.sigma_floor = float(sigma_floor)
        self.colour = bool(colour)
        self.frames = 0
        self._smooth: np.ndarray | None = None
        self._t_prev = 0.0
        self._held: deque = deque()

    def signal(self, t: float, grid: np.ndarray) -> np.ndarray:
        """Mean-removed (and optionally smoothed) signal of one grid, float64 code values."""
        grid = np.asarray(grid, dtype=np.float64)
        return self._smoothed(t, grid - self._mean.update(float(t), grid))

    def _smoothed(self, t: float, s: np.ndarray) -> np.ndarray:
        s = np.asarray(s, dtype=np.float64)
        if self.smooth_seconds > 0:
            if self._smooth is None:
                self._smooth = s.copy()
            else:
                b = 1.0 - math.exp(-max(t - self._t_prev, 0.0) / self.smooth_seconds)
                self._smooth += b * (s - self._smooth)
            s = self._smooth.copy()
        self._t_prev = float(t)
        return s

    def _shown(self, s: np.ndarray) -> np.ndarray:
        """What the display shows of a signal: each channel, or their luminance in all three."""
        if self.colour:
            return s
        lum = np.asarray(s, np.float64) @ LUMA
        return np.repeat(lum[..., None], 3, axis=-1)

    def _display(self, s: np.ndarray) -> np.ndarray:
        x = self.gain * self._shown(s)
        return (GREY + (GREY - 1.0) * np.tanh(x / (GREY - 1.0))).astype(np.float32)

    def _calibrate(self) -> None:
        signals = [s for _, s in self._held]
        # The first frame's signal is exactly zero (the mean is that frame): leave it out.
        sample = self._shown(np.stack(signals[1:] if len(signals) > 1 else signals))
        sigma = max(robust_sigma(sample), self.sigma_floor, 1e-6)
        self.sigma = float(sigma)
        self.gain = (GREY - 1.0) / (SIGMAS_TO_FULL_SCALE * sigma)

    def _release(self) -> list[tuple[Any, np.ndarray]]:
        out = [(p, self._display(s)) for p, s in self._held]
        self._held.clear()
        return out

    def push(self, t: float, grid: np.ndarray, payload: Any = None) -> list[tuple[Any, np.ndarray]]:
        return self._take(self.signal(t, grid), payload)

    def push_signal(self, t: float, s: np.ndarray, payload: Any = None) -> list[tuple[Any, np.ndarray]]:
        """:meth:`push` for a signal whose mean was already removed (by the mean this amplifier
        was given): it is smoothed, held or displayed as a grid pushed here would be."""
        return self._take(self._smoothed(t, s), payload)

    def _take(self, s: np.ndarray, payload: Any) -> list[tuple[Any, np.ndarray]]:
        self.frames += 1
        if self.gain is not None:
            return [(payload, self._display(s))]
        self._held.append((payload, s.astype(np.float32)))
        if len(self._held) < self.calib_frames:
            return []
        self._calibrate()
        return self._release()

    def flush(self) -> list[tuple[Any, np.ndarray]]:
        if not self._held:
            return []
        if self.gain is None:
            self._calibrate()
        return self._release()


# -- automatic --cells and --smooth -----------------------------------------------------------
# From finest and sharpest to coarsest and slowest: each step lowers the noise of a shown block
# further (bigger blocks average more pixels, a longer time constant more frames) and blurs more.
AUTO_LADDER = ((64, 0.0), (32, 0.0), (32, 0.1), (16, 0.1), (16, 0.2), (16, 0.3), (8, 0.3), (8, 0.5))
AUTO_CELLS = tuple(dict.fromkeys(c for c, _ in AUTO_LADDER))
AUTO_SMOOTH = tuple(sorted({s for _, s in AUTO_LADDER}))
# Signal power over noise power (per block and frame, as displayed) that a step must reach to be
# chosen: 12 dB = a signal 4x the noise's amplitude, so the +-3 sigma display range is mostly signal.
TARGET_SNR_DB = 12.0


def auto_steps(cells: int | None, smooth: float | None) -> list[tuple[int, float]]:
    """The (cells, smooth seconds) steps to choose from: the ladder, with a given value fixed."""
    if cells is not None and smooth is not None:
        return [(int(cells), float(smooth))]
    if cells is not None:
        return [(int(cells), t) for t in AUTO_SMOOTH]
    if smooth is not None:
        return [(c, float(smooth)) for c in AUTO_CELLS]
    return list(AUTO_LADDER)


def smoothing_noise_share(frame_seconds: float, smooth_seconds: float) -> float:
    """Share of white noise's power that the one-pole low-pass keeps: b / (2 - b)."""
    if smooth_seconds <= 0:
        return 1.0
    b = 1.0 - math.exp(-max(frame_seconds, 1e-9) / smooth_seconds)
    return b / (2.0 - b)


def measured_snr_db(times: np.ndarray, signals: np.ndarray, smooth_seconds: float) -> float:
    """Signal-to-noise of the displayed blocks (dB) if ``signals`` were smoothed with
    ``smooth_seconds``, as the SNR estimator measures it (wallcli.snr.estimate): the noise power is
    half the mean square frame-to-frame difference of the unsmoothed, mean-removed block signals,
    scaled by the share the low-pass keeps; the signal power is the smoothed signals' mean square
    less that noise. ``signals``: (frames, rows, cols, 3), the first frame (signal 0) left out."""
    x = np.asarray(signals, np.float32)
    if len(x) < 3:
        return -math.inf
    d = np.diff(x, axis=0)
    noise = 0.5 * float(np.mean(d * d, dtype=np.float64))
    if smooth_seconds > 0:
        y = np.empty_like(x)
        y[0] = x[0]
        for i in range(1, len(x)):
            b = 1.0 - math.exp(-max(float(times[i] - times[i - 1]), 0.0) / smooth_seconds)
            y[i] = y[i - 1] + np.float32(b) * (x[i] - y[i - 1])
        x = y
        noise *= smoothing_noise_share(float(np.median(np.diff(times))), smooth_seconds)
    total = float(np.mean(x * x, dtype=np.float64))
    if noise <= 0:
        return math.inf if total > 0 else -math.inf
    return 10.0 * math.log10(max(total - noise, 1e-30) / noise)


# The automatic gain never puts full scale under this many noise sigmas: on a clip with nothing but
# noise (an empty room) the display stays near grey, speckled at +-127/NOISE_FULL_SCALE levels,
# instead of stretching the noise into bright blobs that look like people.
NOISE_FULL_SCALE = 10.0


def noise_sigma(times: np.ndarray, signals: np.ndarray, smooth_seconds: float) -> float:
    """The displayed blocks' noise sigma after smoothing: as :func:`measured_snr_db` measures it."""
    x = np.asarray(signals, np.float32)
    if len(x) < 3:
        return 0.0
    d = np.diff(x, axis=0)
    noise = 0.5 * float(np.mean(d * d, dtype=np.float64))
    if smooth_seconds > 0:
        noise *= smoothing_noise_share(float(np.median(np.diff(times))), smooth_seconds)
    return math.sqrt(max(noise, 0.0))


def choose_step(steps, measured: dict) -> tuple[int, float]:
    """The first step whose measured SNR reaches :data:`TARGET_SNR_DB`, else the best one."""
    for step in steps:
        if measured[step] >= TARGET_SNR_DB:
            return step
    return max(steps, key=lambda st: measured[st])


class AutoAmplifier:
    """An :class:`Amplifier` whose block count (``cells``) and smoothing, where not given (None),
    are chosen from the clip's own signal and noise.

    The first ``calib_frames`` frames (the automatic gain's calibration, bounded by the caller)
    are held back as small grids at every block count still in question (:attr:`wanted`: the
    caller computes those grids from the same decoded frame, so nothing is decoded twice); each
    step of :func:`auto_steps` gets its SNR measured (:func:`measured_snr_db`), one is chosen
    (:func:`choose_step`), and the held frames go through the chosen amplifier, which goes on
    from there (same running mean, gain measured on the same frames). Memory: a few small grids
    per held frame, whatever the video's length or size.
    """

    def __init__(self, *, cells: int | None = None, smooth_seconds: float | None = None, mean: str = "ema",
                 mean_seconds: float = 10.0, gain: float | None = None, calib_frames: int = 60, sigma_floor=None,
                 colour: bool = False):
        self.steps = auto_steps(cells, smooth_seconds)
        self.auto_cells, self.auto_smooth = cells is None, smooth_seconds is None
        self._kw = dict(mean=mean, mean_seconds=mean_seconds, gain=gain, colour=colour)
        self.calib_frames = max(3, int(calib_frames))
        self._floor = sigma_floor or (lambda c: 0.0)  # cells -> the gain's sigma floor
        self.measured: dict[tuple[int, float], float] = {}
        self.cells: int | None = None
        self.smooth_seconds: float | None = None
        self.amp: Amplifier | None = None
        self._means = {c: Amplifier(mean=mean, mean_seconds=mean_seconds, gain=1.0)._mean for c in self.wanted}
        self._held: deque = deque()
        if len(self.steps) == 1:
            self._start(self.steps[0])

    @property
    def wanted(self) -> tuple[int, ...]:
        """The block counts whose grids the next :meth:`push` needs."""
        if self.cells is not None:
            return (self.cells,)
        return tuple(dict.fromkeys(c for c, _ in self.steps))

    @property
    def chosen(self) -> bool:
        return self.amp is not None

    def _start(self, step: tuple[int, float]) -> None:
        self.cells, self.smooth_seconds = step
        self.amp = Amplifier(smooth_seconds=self.smooth_seconds, calib_frames=self.calib_frames,
                             sigma_floor=self._floor(self.cells), **self._kw)

    def push(self, t: float, grids: dict, payload: Any = None) -> list[tuple[Any, np.ndarray]]:
        if self.amp is not None:
            return self.amp.push(t, grids[self.cells], payload)
        signals = {}
        for c in self.wanted:
            g = np.asarray(grids[c], np.float64)
            signals[c] = (g - self._means[c].update(float(t), g)).astype(np.float32)
        self._held.append((float(t), payload, signals))
        if len(self._held) < self.calib_frames:
            return []
        return self._choose()

    def _choose(self) -> list[tuple[Any, np.ndarray]]:
        times = np.array([t for t, _, _ in self._held], np.float64)
        for step in self.steps:
            c, tau = step
            # frame 0's signal is exactly 0 (the mean is that frame): left out
            self.measured[step] = measured_snr_db(times[1:], np.stack([s[c] for _, _, s in self._held][1:]), tau)
        self._start(choose_step(self.steps, self.measured))
        self.amp._mean = self._means[self.cells]
        noise = noise_sigma(times[1:], np.stack([s[self.cells] for _, _, s in self._held][1:]), self.smooth_seconds)
        self.amp.sigma_floor = max(self.amp.sigma_floor, NOISE_FULL_SCALE / SIGMAS_TO_FULL_SCALE * noise)
        out = []
        # the chosen amplifier holds them again until its gain is known (calib_frames of them,
        # or all of a shorter clip, at flush), then releases them in order
        while self._held:
            t, payload, signals = self._held.popleft()
            out += self.amp.push_signal(t, signals[self.cells], payload)
        self._means = {self.cells: self._means[self.cells]}
        return out

    def flush(self) -> list[tuple[Any, np.ndarray]]:
        if self.amp is None:
            if not self._held:
                return []
            out = self._choose()
        else:
            out = []
        return out + self.amp.flush()

    # what the summary reports, as the plain Amplifier has them
    @property
    def gain(self):
        return None if self.amp is None else self.amp.gain

    @property
    def sigma(self):
        return None if self.amp is None else self.amp.sigma

    @property
    def auto_gain(self) -> bool:
        return self._kw["gain"] is None


# -- display: from grids and planes to uint8 RGB panels -----------------------------------------
def render_panel(display: np.ndarray, width: int, height: int) -> np.ndarray:
    """Upsample a display grid (rows, cols, 3) bilinearly to ``width`` x ``height`` uint8 RGB.

    Interpolation happens in float; clipping to 0-255 is the very last step, so out-of-range cells
    do not bend the interpolation between their neighbours.
    """
    import cv2

    img = cv2.resize(np.ascontiguousarray(display, dtype=np.float32), (int(width), int(height)),
                     interpolation=cv2.INTER_LINEAR)
    np.rint(img, out=img)
    np.clip(img, 0.0, 255.0, out=img)
    return img.astype(np.uint8)


def _rgb_affine(planes) -> np.ndarray:
    """The 3x4 matrix of ``planes.to_rgb`` (affine in the plane values), for ``cv2.transform``."""
    if planes.u is None:
        z, e = np.zeros(1), np.ones(1)
        off = planes.to_rgb(z)[0].astype(np.float64)
        col = planes.to_rgb(e)[0] - off
        return np.column_stack([col, off])
    basis = np.array([[0, 0, 0], [1, 0, 0], [0, 1, 0], [0, 0, 1]], np.float64)
    out = planes.to_rgb(basis[:, 0], basis[:, 1], basis[:, 2]).astype(np.float64)
    return np.column_stack([out[1] - out[0], out[2] - out[0], out[3] - out[0], out[0]])


def original_panel(planes, roi: tuple[int, int, int, int], width: int, height: int) -> np.ndarray:
    """The ROI of the decoded frame as uint8 RGB at ``width`` x ``height`` (display only).

    Each plane is cropped and resized on its own, then the colour matrix is applied at panel size
    by ``cv2.transform`` (rounding and saturating in C): converting the full-size frame to float
    RGB first would cost more than everything else amplify does.
    """
    import cv2

    x, y, w, h = roi
    size = (int(width), int(height))

    def fit(plane: np.ndarray, sx: int, sy: int) -> np.ndarray:
        r0, r1 = y >> sy, -((-(y + h)) >> sy)
        c0, c1 = x >> sx, -((-(x + w)) >> sx)
        crop = plane[r0:r1, c0:c1]
        down = crop.shape[1] > size[0] or crop.shape[0] > size[1]
        return cv2.resize(crop, size, interpolation=cv2.INTER_AREA if down else cv2.INTER_LINEAR)

    yy = fit(planes.y, 0, 0)
    if planes.u is None:
        stack = yy[..., None]  # one channel in, three out (3x2 matrix)
    else:
        stack = cv2.merge([yy, fit(planes.u, planes.sub_x, planes.sub_y), fit(planes.v, planes.sub_x, planes.sub_y)])
    m = _rgb_affine(planes)
    if stack.dtype == np.uint8:
        return cv2.transform(stack, m)  # uint8 in, uint8 out: rounded and saturated
    rgb = cv2.transform(stack.astype(np.float32), m)
    np.rint(rgb, out=rgb)
    np.clip(rgb, 0.0, 255.0, out=rgb)
    return rgb.astype(np.uint8)
