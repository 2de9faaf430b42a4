"""Frame rates and frame times: which rates wallcli reads, the rate a container states, and each
decoded frame's time (from its timestamp, exact in the stream's time base), gaps and measured rate."""

from __future__ import annotations

import math
import statistics
from collections import deque
from fractions import Fraction

import numpy as np

from wallcli.errors import WallcliError

# The frame rates wallcli reads. The models see 8.5 s windows resampled to 30 fps, trained on 15-60 fps
# videos, and the SNR estimator (paper suppl. 3.2) takes what lasts from one frame to the next as
# signal: far below 10 fps a person moves across the wall between two frames and both would be
# answering about interpolated samples (a 0.5 fps file gave eight windows and 32 dB, snr -99 dB);
# far above 240 fps, the timestamps of slow-motion files are rarely the capture's.
MIN_FPS, MAX_FPS = 10.0, 240.0
# The frame intervals whose median the rate check reads (the rest of a file is checked by then), and
# how far the frames' measured rate may stray from the container's before it is the one reported
RATE_PROBE = 16
RATE_TOLERANCE = 0.02


# how far a rate computed in floating point (1 / 0.004166...) may overshoot a bound and still be on it
_ROUNDING = 1e-9


def check_rate(fps: float, source: str) -> None:
    """Refuse a frame rate outside MIN_FPS-MAX_FPS: one line, the same for every command."""
    if not (MIN_FPS * (1 - _ROUNDING) <= float(fps) <= MAX_FPS * (1 + _ROUNDING)):
        raise WallcliError(f"{source}: {float(fps):.3g} fps; wallcli reads videos of {MIN_FPS:g} to {MAX_FPS:g} fps "
                           "(the models' windows and the SNR estimator assume frames a fraction of a second apart)")



# A jump of the timestamps over GAP_FACTOR typical frame intervals, and over GAP_MIN seconds, is frames
# lost (corruption, a dropped stretch of a stream), not a variable frame rate's slower frame (phones:
# up to about 2x; a few frames' pause is interpolated over like any resampling)
GAP_FACTOR = 5.0
GAP_MIN = 0.25
GAP_HISTORY = 16  # recent intervals whose median is the typical one

# FFmpeg's demuxers of bare elementary streams: no timestamps, and an average_rate that is only
# the demuxer's -framerate default (25), whatever the frames are; the codec's headers (H.264's
# VUI timing, MPEG-2's sequence header) are what knows the rate
RAW_DEMUXERS = frozenset({"h264", "hevc", "vvc", "m4v", "mpegvideo", "cavsvideo", "avs2", "avs3", "vc1", "dirac",
                          "mjpeg", "dnxhd"})
RAW_DEFAULT_FPS = 25  # what FFmpeg assumes for such a stream that states no rate


def container_rate(stream, container_name: str, source: str, warn) -> tuple[Fraction, str]:
    """The rate a stream states and where it came from ('container', 'codec' or 'assumed');
    ``warn(message, loud)`` records what was assumed (loud: also a VideoWarning)."""
    raw = container_name in RAW_DEMUXERS
    rate, fps_source = (None if raw else stream.average_rate), "container"
    if raw:
        stated = stream.codec_context.framerate
        if stated and stated > 0:
            rate, fps_source = stated, "codec"
            warn(f"{source}: a bare {container_name} stream has no timestamps; read at "
                 f"{float(stated):.4g} fps, the rate its codec headers state", False)
        else:
            rate, fps_source = Fraction(RAW_DEFAULT_FPS), "assumed"
            warn(f"{source}: a bare {container_name} stream states no frame rate; assuming "
                 f"{RAW_DEFAULT_FPS} fps (FFmpeg's default): times and rates are wrong if it is not", True)
    rate = rate or stream.guessed_rate or stream.base_rate
    if not rate or rate <= 0:
        rate, fps_source = Fraction(30), "assumed"
        warn(f"{source}: no frame rate in the stream; assuming 30 fps", False)
    fps = Fraction(rate).limit_denominator(1001)
    # the measured or stated rate only: a container that gives none leaves FFmpeg guessing
    # from its time base (Matroska's 1000), which says nothing of the frames
    if stream.average_rate or fps_source == "codec":
        check_rate(fps, source)
    return fps, fps_source


class FrameClock:
    """Each decoded frame's time in seconds from the first (its timestamp times the stream's time
    base, or its index over the stated rate where it has none), the jumps that are frames lost
    (:attr:`gaps`), and the frames' own rate (:attr:`measured_fps`). Refuses (check_rate) frames
    whose median spacing is outside the rates wallcli reads, whatever the container says."""

    def __init__(self, time_base, fps: Fraction, source: str) -> None:
        self.tb, self.fps, self.source = time_base, float(fps), source
        self.first_pts = None
        self.last_time = -np.inf
        self.recent: deque = deque(maxlen=GAP_HISTORY)
        self.gaps: list[tuple[float, float]] = []  # (time of the frame before, time of the frame after) per jump
        self.steady = [0, 0.0]  # frame intervals that are no gap: how many, their sum in seconds
        self.first_intervals: list[float] | None = []  # the first RATE_PROBE, then None (checked)

    def stamp(self, pts, index: int) -> tuple[float, float]:
        """(time, gap) of frame ``index``: gap is the seconds since the frame before where the
        timestamps jump there (frames lost), 0 otherwise."""
        fps, tb = self.fps, self.tb
        if pts is not None and tb is not None:
            if self.first_pts is None:
                self.first_pts = pts
            t = float((pts - self.first_pts) * tb)
        else:
            t = index / fps
        if t <= self.last_time:
            # Duplicate or out-of-order timestamps (broken muxers): keep time monotonic.
            t = self.last_time + 1.0 / fps
        gap = 0.0
        if index:
            dt = t - self.last_time
            # (np.median's value, without its overhead on 16 floats: it was most of a frame's stamp)
            typical = statistics.median(self.recent) if len(self.recent) >= 4 else 1.0 / fps
            if dt > GAP_FACTOR * typical and dt > max(GAP_FACTOR / fps, GAP_MIN):
                gap = dt
                self.gaps.append((round(self.last_time, 4), round(t, 4)))
            else:
                self.recent.append(dt)
                self.steady[0] += 1
                self.steady[1] += dt
            if self.first_intervals is not None:
                self.first_intervals.append(dt)
                if len(self.first_intervals) >= RATE_PROBE:
                    self.check_intervals()
        self.last_time = t
        return t, gap

    @property
    def measured_fps(self) -> float | None:
        """The frames' own rate so far: intervals counted, gaps (frames lost) not; None before two frames."""
        n, total = self.steady
        return n / total if n and total > 0 else None

    def check_intervals(self) -> None:
        """Refuse (check_rate) frames whose median spacing is outside the rates wallcli reads,
        whatever the container says (one frame an hour in a file labelled 30 fps); one tick of
        the time base either way is the timestamps' rounding (240 fps in milliseconds: 4 or 5)."""
        intervals, self.first_intervals = self.first_intervals, None
        check_intervals(intervals or [], float(self.tb or 0), self.source)


def check_intervals(intervals, tick: float, source: str) -> None:
    """Refuse frames whose median spacing is outside the rates wallcli reads, give or take one
    ``tick`` of their time base (their timestamps' rounding): the rule for a video's first frames
    and for a space-time plot's times alike."""
    if len(intervals) < 2:
        return
    m = float(np.median(intervals))
    fastest = 1.0 / max(m - tick, 1e-12)
    slowest = 1.0 / (m + tick) if m + tick > 0 else math.inf
    if fastest < MIN_FPS * (1 - _ROUNDING) or slowest > MAX_FPS * (1 + _ROUNDING):
        check_rate(1.0 / m if m > 0 else math.inf, source)


# The tick assumed for a plot that does not record its video's time base (one written before it
# did): a millisecond, Matroska's, the coarsest that timestamps of a 240 fps video come in
PLOT_TICK = Fraction(1, 1000)


def fraction(text, default=None) -> Fraction | None:
    """A positive rational written as "N/D" (or a number) in a plot's metadata; ``default`` where absent
    or malformed."""
    try:
        f = Fraction(str(text)) if text is not None and not isinstance(text, bool) else None
    except (ValueError, ZeroDivisionError):
        return default
    return f if f is not None and f > 0 else default


def plot_rate(meta: dict, times, source: str) -> Fraction | None:
    """The frame rate of a space-time plot, the one rule for every command that reads one: the video's
    rate as stplot recorded it (``fps_fraction``, exact), else what its times say (frames over their
    span, gaps and timestamp rounding averaged out); refused as the video would be (check_rate),
    and so are times whose median spacing is outside the rates read, give or take one tick of the
    video's time base (``time_base``; a millisecond where not recorded). None: too few times to say."""
    times = np.asarray(times, np.float64)
    rate = fraction((meta or {}).get("fps_fraction"))
    if rate is None and times.size >= 2 and times[-1] > times[0]:
        steps = np.diff(times)
        typical = float(np.median(steps))
        steady = steps[steps <= GAP_FACTOR * typical]  # frames lost are no slower rate
        rate = Fraction((steady.size / float(steady.sum()))).limit_denominator(1001)
    if rate is not None:
        check_rate(rate, source)
    check_intervals(np.diff(times), float(fraction((meta or {}).get("time_base"), PLOT_TICK)), source)
    return rate
