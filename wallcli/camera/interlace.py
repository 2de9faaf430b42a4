"""Interlaced video found in the decode and its fields brought to one instant.

An interlaced frame holds two fields: the even rows (the top field) captured at one instant and
the odd rows (the bottom field) at another, ``delta`` frame intervals later (earlier: negative).
Where the wall's light changes, the rows then alternate between the two instants (combing): the
bottom field over the top one interpolated to its rows, less one, is the wall's fixed texture
(which a change of light scales, leaving the ratio) plus ``delta`` times the relative rate at
which the light changes there. The rate is read on the top field, from the frames either side
(whose noise is not the ratio's). Both, less their running means over ``TAU`` seconds (the fixed
texture, and slow drifts that a static texture cannot be told from), are regressed on each
other over every sample and frame: the slope is ``delta``, about 1/2 for a camera's fields and
0 for a progressive clip, and its t statistic decides (``T_DECIDE``). A steady ramp of light
moves the ratio by a constant, which the running mean takes out: only changes of the rate (a
person moving, a shadow that comes and goes) tell, and a clip without them stays undecided.

Once decided, every frame's bottom field is moved in time to the top field's instant (see
:meth:`InterlaceFilter._align`): each frame is then one instant, at
the file's frame rate and times, every row where it was. Frames wait one frame (memory flat).
Until the decision the frames pass as decoded: a clip whose light hardly changes has combing too
small to matter and may never be decided.
"""

from __future__ import annotations

import dataclasses
from collections import deque
from typing import Iterator

import numpy as np

MAX_COLUMNS = 128  # luma columns compared (a lattice on wider frames)
MAX_PAIRS = 192  # groups of four neighbouring rows compared (spread over the frame's height)
T_DECIDE = 8.0  # t statistic of the slope
TAU = 1.0  # seconds: the running means' time constant
MIN_FRAMES = 12
MIN_DELTA = 0.3  # frames: a smaller offset between the fields is too small to correct
PROGRESSIVE = 0.02  # a slope held under this by T_DECIDE standard errors over PROGRESSIVE_AFTER
PROGRESSIVE_AFTER = 4.0  # seconds at least: shown progressive, the clip is not read further
OFFSETS = (-1.0, -0.5, 0.5, 1.0)  # what delta is snapped to (1/2: a camera's fields; 1: fields a frame apart)


class InterlaceFilter:
    """A reader whose :meth:`frames` hands on frames with their fields at one instant once the clip
    is found interlaced; everything else is the reader's."""

    def __init__(self, reader) -> None:
        self.reader = reader
        self.delta: float | None = None  # the bottom field's offset from the top one, frames
        self.since: float | None = None  # time of the first frame corrected
        self.progressive = False  # shown progressive: nothing more is read
        self._fps = 30.0
        self._seen: deque = deque(maxlen=5)  # (top field at the bottom rows, bottom field) of the last frames
        self._mean = None  # running means of the ratio and the rate
        self._n = 0
        self._sums = np.zeros((2, 6))  # per side: sum xy, xx, yy, the samples, zy and zx, over the frames

    def __getattr__(self, name: str):
        return getattr(self.reader, name)

    def _fields(self, y: np.ndarray):
        """(top field at the bottom rows, bottom field; bottom field at the top rows, top field)."""
        step = max(1, -(-y.shape[1] // MAX_COLUMNS))
        n = min((y.shape[0] - 1) // 2, y.shape[0] // 2 - 1)
        i = np.arange(0, n, max(1, -(-n // MAX_PAIRS)))  # groups of rows 2i..2i+3 (every row of them read)
        # one gather of the four rows of every group (lattice columns), one conversion
        g = y[(2 * i[:, None] + np.arange(4)).ravel(), ::step].astype(np.float32).reshape(len(i), 4, -1)
        top, bottom, top1, bottom1 = g[:, 0], g[:, 1], g[:, 2], g[:, 3]
        return np.maximum(0.5 * (top + top1), 1.0), bottom, np.maximum(0.5 * (bottom + bottom1), 1.0), top1

    def _observe(self, y: np.ndarray, fps: float) -> None:
        if y.shape[0] < 8 or self.delta is not None or self.progressive:  # decided: nothing more to read
            return
        cur = self._fields(y)
        if self._seen and cur[0].shape != self._seen[-1][0].shape:
            self._seen.clear()
        self._seen.append(cur)
        if len(self._seen) < 5:
            return
        self._n += 1
        self._fps = fps
        a = max(1.0 / (TAU * fps), 1.0 / self._n)
        for side in (0, 1):  # the bottom field against the top, then the top against the bottom
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
        if self.delta is None and self._n >= MIN_FRAMES and self._n % 4 == 0:
            self._decide()

    def _decide(self) -> None:
        # each field read against the other: the offset changes sign, while what the change's
        # own vertical shape reads into the ratio (a sharp shadow's edge curving the light between
        # rows, a codec's blocks) does not; half their difference is the offset's alone
        slopes, ses, ivs = [], [], []
        for sxy, sxx, syy, n, szy, szx in self._sums:
            if sxx <= 0 or szx <= 0:
                return
            slopes.append(sxy / sxx)
            ses.append(np.sqrt(max(syy - sxy * sxy / sxx, 0.0) / n / sxx))
            ivs.append(szy / szx)
        slope, se = (slopes[0] - slopes[1]) / 2, np.hypot(*ses) / 2
        if se > 0 and abs(slope) + T_DECIDE * se < PROGRESSIVE and self._n >= PROGRESSIVE_AFTER * self._fps:
            # the light's changes have shown the rows of both fields at one instant, beyond doubt:
            # a camera's fields read a slope near 1/2, flattened by noise but never to this
            self.progressive = True
            return
        if slope == 0 or (se > 0 and abs(slope) < T_DECIDE * se):
            return
        # the size: the rate's own noise flattens the slope; measured against the rate read on
        # other frames (whose noise is not the rate's nor the ratio's) it does not
        delta = (ivs[0] - ivs[1]) / 2
        if abs(delta) < MIN_DELTA or np.sign(delta) != np.sign(slope):
            return
        self.delta = min(OFFSETS, key=lambda d: abs(d - delta))

    def _align(self, before, frame, after):
        """``frame`` with its bottom field (odd rows, every plane) moved to its top field's instant.

        Fields a whole frame apart are paired again (the bottom field of the frame before or
        after). Half a frame apart, the bottom field is moved by the change the top field shows
        over the frames either side (half of it, times the offset): an average of two bottom
        fields would do the same for the light but halve their noise, and the noise estimate
        read from frame differences would then read the clip 2-4 dB stronger than it is; this
        adds a sixteenth of the noise's variance."""
        d = self.delta
        near = (before if d > 0 else after) if abs(d) >= 1 else None
        if (near is None and abs(d) >= 1) or (abs(d) < 1 and (before is None or after is None)):
            return frame
        planes = frame.planes
        if any(o is not None and o.planes.y.shape != planes.y.shape for o in (before, after)):
            return frame
        out = {}
        for name in ("y", "u", "v"):
            a = getattr(planes, name)
            if a is None:
                continue
            a = a.astype(np.float32)
            if near is not None:
                a[1::2] = np.asarray(getattr(near.planes, name)[1::2], np.float32)
            else:
                rate = _top_at_bottom(getattr(after.planes, name)) - _top_at_bottom(getattr(before.planes, name))
                a[1::2] -= np.float32(d / 2.0) * rate
            out[name] = a
        if self.since is None:
            self.since = round(float(frame.time), 4)
        return dataclasses.replace(frame, planes=dataclasses.replace(planes, **out))

    def frames(self) -> Iterator:
        before = current = None
        fps = float(getattr(getattr(self.reader, "info", None), "fps", 0) or 30.0)
        for frame in self.reader.frames():
            self._observe(frame.planes.y, fps)
            if current is not None:
                yield current if self.delta is None else self._align(before, current, frame)
            before, current = current, frame
        if current is not None:
            yield current if self.delta is None else self._align(before, current, None)

    def correction(self) -> dict | None:
        """The ``corrections`` entry (docs/contract.md), None for a clip not found interlaced."""
        if self.delta is None:
            return None
        return {"kind": "interlace", "field_order": "tff" if self.delta > 0 else "bff",
                "field_offset": self.delta, "from": self.since}


def _top_at_bottom(a: np.ndarray) -> np.ndarray:
    """The top field (even rows) of a plane, interpolated to the bottom field's rows."""
    top = np.asarray(a[0::2], np.float32)
    n = a[1::2].shape[0]
    below = np.concatenate([top[1:n + 1], top[len(top) - 1:]])[:n] if n else top[:0]
    return 0.5 * (top[:n] + below)
