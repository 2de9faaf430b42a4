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
        self._seen: deque = deque(maxlen=5)  # the last frames' _fields
        self._mean = None  # running means of the ratio and the rates, both sides: (3, 2, groups, columns)
        self._rows = None  # (plane height, the rows read, groups of four)
        self._n = 0
        self._sums = np.zeros((2, 6))  # per side: sum xy, xx, yy, the samples, zy and zx, over the frames

    def __getattr__(self, name: str):
        return getattr(self.reader, name)

    def _fields(self, y: np.ndarray) -> np.ndarray:
        """(4, groups, columns): the top field at the bottom rows, the bottom field, the bottom field
        at the top rows, the top field; sides 0 and 1 at [0::2] (the references) and [1::2] (what is
        read against them), so each step of :meth:`_observe` is one numpy call for both sides."""
        step = max(1, -(-y.shape[1] // MAX_COLUMNS))
        if self._rows is None or self._rows[0] != y.shape[0]:
            n = min((y.shape[0] - 1) // 2, y.shape[0] // 2 - 1)
            i = np.arange(0, n, max(1, -(-n // MAX_PAIRS)))  # groups of rows 2i..2i+3 (every row of them read)
            # rows 2i, 2i+1, 2i+3, 2i+2 (top, bottom, bottom1, top1) of every group, each kind's together
            self._rows = (y.shape[0], (2 * i[None, :] + np.array([0, 1, 3, 2])[:, None]).ravel(), len(i))
        _, rows, groups = self._rows
        f = y[rows, ::step].astype(np.float32).reshape(4, groups, -1)  # one gather, one conversion
        ref = f[0::2] + f[3::-2]  # top + top1, bottom1 + bottom
        ref *= 0.5
        np.maximum(ref, 1.0, out=f[0::2])
        return f

    def _observe(self, y: np.ndarray, fps: float) -> None:
        if y.shape[0] < 8 or self.delta is not None or self.progressive:  # decided: nothing more to read
            return
        cur = self._fields(y)
        if self._seen and cur.shape != self._seen[-1].shape:
            self._seen.clear()
            self._mean = None
        self._seen.append(cur)
        if len(self._seen) < 5:
            return
        self._n += 1
        self._fps = fps
        a = max(1.0 / (TAU * fps), 1.0 / self._n)
        # both sides at once: the bottom field against the top, and the top against the bottom
        far0, before, now_f, after, far1 = (f[0::2] for f in self._seen)
        ref, other = now_f, self._seen[2][1::2]
        now = np.empty((3,) + ref.shape, np.float32)  # the ratio, the rate, the rate over 4 frames
        np.divide(other, ref, out=now[0])
        now[0] -= 1.0
        np.subtract(after, before, out=now[1])
        now[1] /= 2.0 * ref
        np.subtract(far1, far0, out=now[2])
        now[2] /= 4.0 * ref
        if self._mean is None:
            self._mean = now.copy()
        else:
            self._mean *= 1 - a
            self._mean += a * now
        if self._n < 3:
            return
        now -= self._mean
        for side in (0, 1):
            # yy (the ratio), xx (the rate), zz (over 4 frames) against each other: dot products in
            # float64 (a matrix product of the three takes 4 times as long at these sizes)
            yy, xx, zz = now[:, side].reshape(3, -1).astype(np.float64)
            self._sums[side] += (np.dot(xx, yy), np.dot(xx, xx), np.dot(yy, yy), xx.size,
                                 np.dot(zz, yy), np.dot(zz, xx))
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
