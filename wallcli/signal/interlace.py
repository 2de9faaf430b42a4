"""Interlaced video found in the decode and its fields brought to one instant.

An interlaced frame holds two fields: the even rows (the top field) captured at one instant and
the odd rows (the bottom field) at another, half a frame interval later or earlier. Where the
wall's light changes, the rows then alternate between the two instants (combing). Each field is
compared with the other one interpolated to its rows, in the same frame and in the frames either
side: with the bottom field ``delta`` frames after the top one, the bottom field of frame k
resembles the top field of frame k + delta. In a progressive clip the two cross-frame comparisons
(bottom of k against top of k + 1, and against top of k - 1) differ by noise alone, whatever the
picture does; in an interlaced one, the one towards the later field's side is the closer. Their
difference, frame by frame, decides (a t statistic over the frames, ``T_DECIDE``), and its size
against the curvature of the three comparisons gives ``delta`` (about 1/2 for a camera's fields).

Once decided, every frame's bottom field is interpolated in time (between its own and the
neighbouring frame's bottom field) to the top field's instant: each frame is then one instant, at
the file's frame rate and times, every row where it was. Frames wait one frame (memory flat).
Until the decision the frames pass as decoded: a clip whose light hardly changes has combing too
small to matter and may never be decided.
"""

from __future__ import annotations

import dataclasses
from typing import Iterator

import numpy as np

MAX_COLUMNS = 256  # luma columns compared (a lattice on wider frames); every row is read
T_DECIDE = 8.0  # t statistic of the cross-frame asymmetry over the frames
MIN_FRAMES = 12
MIN_DELTA = 0.3  # frames: a smaller offset between the fields is too small to correct
OFFSETS = (-1.0, -0.5, 0.5, 1.0)  # what delta is snapped to (1/2: a camera's fields; 1: fields a frame apart)


class InterlaceFilter:
    """A reader whose :meth:`frames` hands on frames with their fields at one instant once the clip
    is found interlaced; everything else is the reader's."""

    def __init__(self, reader) -> None:
        self.reader = reader
        self.delta: float | None = None  # the bottom field's offset from the top one, frames
        self.since: float | None = None  # time of the first frame corrected
        self._prev = None  # (top field interpolated to the bottom rows, bottom field) of the last frame
        self._x: list[float] = []  # per frame: far-side minus near-side comparison (see the docstring)
        self._sums = np.zeros(3)  # e0, e+, e- summed over the frames

    def __getattr__(self, name: str):
        return getattr(self.reader, name)

    def _fields(self, y: np.ndarray):
        step = max(1, -(-y.shape[1] // MAX_COLUMNS))
        a = np.asarray(y[:, ::step], np.float32)
        top, bottom = a[0::2], a[1::2]
        n = min(top.shape[0] - 1, bottom.shape[0])
        return 0.5 * (top[:n] + top[1:n + 1]), bottom[:n]

    def _observe(self, y: np.ndarray) -> None:
        if y.shape[0] < 8:
            return
        cur = self._fields(y)
        prev, self._prev = self._prev, cur
        if prev is None or prev[0].shape != cur[0].shape:
            return
        e0 = float(np.mean((cur[1] - cur[0]) ** 2))
        ep = float(np.mean((prev[1] - cur[0]) ** 2))  # bottom of k-1 against top of k
        em = float(np.mean((cur[1] - prev[0]) ** 2))  # bottom of k against top of k-1
        self._sums += (e0, ep, em)
        self._x.append(em - ep)
        if self.delta is None and len(self._x) >= MIN_FRAMES and len(self._x) % 4 == 0:
            self._decide()

    def _decide(self) -> None:
        x = np.asarray(self._x)
        se = float(np.std(x, ddof=1)) / np.sqrt(x.size)
        if se <= 0 or abs(float(x.mean())) < T_DECIDE * se:
            return
        e0, ep, em = self._sums
        curve = em + ep - 2 * e0
        if curve <= 0:
            return
        delta = (em - ep) / (2 * curve)
        if abs(delta) < MIN_DELTA:
            return
        self.delta = min(OFFSETS, key=lambda d: abs(d - delta))

    def _align(self, before, frame, after):
        """``frame`` with its bottom field (odd rows, every plane) moved to its top field's instant."""
        d = self.delta
        other, w = (before, d) if d > 0 else (after, -d)  # weight of the neighbour's bottom field
        if other is None:
            return frame
        planes, near = frame.planes, other.planes
        if near.y.shape != planes.y.shape:
            return frame
        w = np.float32(min(w, 1.0))
        out = {}
        for name in ("y", "u", "v"):
            a = getattr(planes, name)
            if a is None:
                continue
            a = a.astype(np.float32)
            a[1::2] = (1 - w) * a[1::2] + w * np.asarray(getattr(near, name)[1::2], np.float32)
            out[name] = a
        if self.since is None:
            self.since = round(float(frame.time), 4)
        return dataclasses.replace(frame, planes=dataclasses.replace(planes, **out))

    def frames(self) -> Iterator:
        before = current = None
        for frame in self.reader.frames():
            self._observe(frame.planes.y)
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
