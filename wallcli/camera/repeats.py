"""Repeated frames (a DVR's nominal-rate padding) found in the decode and left out as missing samples.

A DVR that records fewer frames than its nominal rate fills the gaps with copies of the previous
frame. A copy carries no new noise: its frame difference is zero, so the frame-difference noise
estimate (half the mean square of consecutive differences) falls with the share of copies and
the SNR reads too high; and the copies hold the light still for a frame, a stair in the time
base. Dropping them, timestamps too, leaves the frames that were really captured, at the times
they were captured; the resampling onto the analysis grid interpolates over the gap as over any
variable frame rate.

A repeat is a frame whose luma differs from the previous frame's by under ``REL`` of the clip's
own typical frame-to-frame difference (a codec may re-encode a copy with a tiny residue; a real
frame's sensor noise keeps the difference near its typical value). The typical value is the
median of the recent frames that were not repeats and differed at all, so a clip whose frames
never differ (noise-free synthetic video) has no typical value and nothing is ever dropped.
"""

from __future__ import annotations

import statistics
from collections import deque
from typing import Iterator

import numpy as np

REL = 0.01  # a repeat differs by under 1 % of the clip's typical difference (a low-noise clip's codec
# skips its noise in whole blocks: real frames there differed by 3 % of the typical one)
HISTORY = 16  # recent real differences whose median is the typical one
MIN_HISTORY = 4  # real differences seen before anything is called a repeat
LOOKAHEAD = 12  # frames held at the start at most, while the typical difference is not yet known
MAX_SAMPLES = 1 << 17  # luma pixels compared per frame (a lattice over larger frames)


def _sample(y: np.ndarray) -> np.ndarray:
    """The lattice, contiguous: its rows copied whole first (a memcpy each), then its columns
    picked (0.07 ms at 1080p; picking both at once strides through the plane, 0.10 ms)."""
    step = max(1, int(np.ceil(np.sqrt(y.size / MAX_SAMPLES))))
    return np.ascontiguousarray(np.ascontiguousarray(y[::step])[:, ::step])


class RepeatFilter:
    """A reader whose :meth:`frames` leaves out repeated frames; everything else is the reader's.

    Memory: one sampled luma plane, and up to LOOKAHEAD decoded frames at the start, whatever
    the length. ``decoded`` counts every frame read,
    ``repeats`` those left out.
    """

    def __init__(self, reader) -> None:
        self.reader = reader
        self.decoded = 0
        self.repeats = 0
        self.last_time = 0.0  # of the last frame decoded, a repeat or not
        self._prev = None
        self._recent: deque = deque(maxlen=HISTORY)
        self._kept = None  # time of the last frame passed on
        self._lost_gap = False  # a repeat left out came after a jump of the timestamps

    def __getattr__(self, name: str):
        return getattr(self.reader, name)

    def _difference(self, y: np.ndarray) -> float | None:
        """Mean absolute luma difference from the previous frame (None for the first)."""
        import cv2

        # one contiguous copy of the lattice, compared by OpenCV (exact: an integer L1 sum in a
        # double), outside the GIL and a fortieth of numpy's int32 round trip
        cur = _sample(y)
        prev, self._prev = self._prev, cur
        if prev is None or prev.shape != cur.shape or prev.dtype != cur.dtype:
            return None
        if cur.dtype in (np.uint8, np.uint16):
            return float(cv2.norm(cur, prev, cv2.NORM_L1)) / cur.size
        return float(np.mean(np.abs(cur.astype(np.int64) - prev)))

    def _judge(self, d: float | None) -> bool:
        if d is None:
            return False
        # (np.median's value, without its overhead on 16 floats)
        if len(self._recent) >= MIN_HISTORY and d < REL * statistics.median(self._recent):
            return True
        if d > 0:
            self._recent.append(d)
        return False

    def frames(self) -> Iterator:
        # The first frames wait (at most LOOKAHEAD, holding their decoded buffers) until the
        # clip's typical difference is known, so that a copy among them is found too
        waiting: list = []
        for frame in self.reader.frames():
            self.decoded += 1
            self.last_time = frame.time
            d = self._difference(frame.planes.y)
            if waiting is None:
                if self._judge(d):
                    self._drop(frame)
                    continue
                yield self._pass(frame)
                continue
            waiting.append((frame, d))
            if d:
                self._recent.append(d)
            if len(self._recent) >= MIN_HISTORY or len(waiting) >= LOOKAHEAD:
                yield from self._release(waiting)
                waiting = None
        if waiting:
            yield from self._release(waiting)

    def _release(self, waiting: list) -> Iterator:
        typical = float(np.median(self._recent)) if len(self._recent) >= MIN_HISTORY else None
        for frame, d in waiting:
            if typical is not None and d is not None and d < REL * typical:
                self._drop(frame)
                continue
            yield self._pass(frame)

    def _drop(self, frame) -> None:
        self.repeats += 1
        self._lost_gap = self._lost_gap or bool(getattr(frame, "gap", 0.0))

    def _pass(self, frame):
        """``frame``, carrying the gap of a repeat left out before it: the resampling restarts at
        a gap and the view check marks it, whichever frame after it they see first."""
        if self._lost_gap and not getattr(frame, "gap", 0.0) and self._kept is not None:
            import dataclasses

            frame = dataclasses.replace(frame, gap=frame.time - self._kept)
        self._lost_gap = False
        self._kept = frame.time
        return frame

    def correction(self) -> dict | None:
        """The ``corrections`` entry (docs/contract.md), None when no frame was a repeat."""
        if not self.repeats:
            return None
        return {"kind": "duplicates", "frames": int(self.repeats), "share": round(self.repeats / max(self.decoded, 1), 4)}
