"""Decode a video once into resampled space-time rows, in memory that does not grow with its length.

Shared by ``wallcli count/activity`` on a video and by ``--follow``: both classify windows of
these rows as they complete, so neither needs the whole plot.
"""
from __future__ import annotations

from typing import Callable, Iterator

import numpy as np

from wallcli.signal.window import MAX_BRIDGE, StreamResampler


class RowStream:
    """Iterate (t, row (2*bins, 3) float32) at ``fps``: horizontal rows first, then vertical.

    Rows are the raw levels minus the first frame's (in float64, before storing float32): the
    offset is a constant per position and colour, which ``normalize_window`` removes with each
    window's mean anyway, and subtracting it keeps float32 precise for faint signals on bright walls.
    ``roi`` and ``frame_size`` are known once the first frame is decoded. ``vertical=False``
    leaves the vertical rows at zero without computing them (for models that do not read them).
    ``column``: a :class:`wallcli.snr.column.ColumnSnr` fed every frame with the projection's own
    column sums, where it made them (the figure's tap would sum the same frames' columns again).
    """

    def __init__(self, reader, *, roi=None, bins: int = 64, fps: float = 30.0,
                 progress: Callable[[int], None] | None = None, vertical: bool = True, stabilize: bool = False,
                 register: bool = False, column=None):
        self.column = column
        self.reader, self.requested, self.bins, self.fps, self.progress = reader, roi, int(bins), fps, progress
        self.vertical = vertical
        self.stabilize = stabilize
        # register: measure each frame's sub-pixel shift (both axes); ``shift`` is then the one of
        # the row last yielded, resampled with it, for the corrections' shake regression
        self.register = register
        self.shift = None
        self.shifts = None  # what stabilisation found, once frames are read (a ShiftLog)
        self.roi = None
        self.frame_size = None
        self.ref = None  # the first frame's raw row, subtracted from every row
        self.frames = 0

    def __iter__(self) -> Iterator[tuple[float, np.ndarray]]:
        from wallcli.signal.blocks import check_roi
        from wallcli.signal.stplot import RowReducer

        resampler = StreamResampler(self.fps)
        reduce = None
        for frame in self.reader.frames():
            if reduce is None:
                # the decoded frame decides the size, not the container's (wrong or unknown in some
                # streams), as in compute_stplot
                self.frame_size = [frame.planes.width, frame.planes.height]
                self.roi = check_roi(self.requested, *self.frame_size)
                reduce = RowReducer(self.roi, self.bins, self.vertical, self.stabilize, self.register)
                self.shifts = reduce.shifts
            row = np.concatenate(reduce(frame.planes))
            if self.column is not None:
                self.column.push(frame.planes, reduce.column_sums())
            if getattr(frame, "gap", 0.0) > MAX_BRIDGE:  # frames lost: a new grid from here, nothing invented inside
                resampler.restart()
            if self.ref is None:
                self.ref = row
            self.frames += 1
            if self.progress:
                self.progress(1)
            rel = (row - self.ref).astype(np.float32)
            if not self.register:
                yield from resampler.push(frame.time, rel)
                continue
            # the shift travels as one more row through the resampler, so it is interpolated
            # to the same grid times as the profiles it explains
            dx, dy = reduce.shift
            ext = np.concatenate([rel, np.array([[dx, dy, 0.0]], np.float32)])
            for t, r in resampler.push(frame.time, ext):
                self.shift = (float(r[-1, 0]), float(r[-1, 1]))
                yield t, r[:-1]


class PlotThumbnail:
    """A bounded copy of the resampled plot, for drawing only (``--plot``).

    At most ``cap`` columns, each the mean of ``factor`` consecutive rows; when the columns run
    out, neighbours merge in pairs and ``factor`` doubles. 2048 columns exceed the figure's
    width in pixels, so the drawing loses nothing visible while memory stays fixed.
    """

    def __init__(self, cap: int = 2048):
        self.cap, self.factor, self.n = int(cap) // 2 * 2, 1, 0
        self._sum = self._t = None

    def push(self, t: float, row: np.ndarray) -> None:
        if self._sum is None:
            self._sum, self._t = np.zeros((self.cap, *row.shape)), np.zeros(self.cap)
        i = self.n // self.factor
        if i == self.cap:  # every column holds `factor` rows: merge pairs
            half = self.cap // 2
            self._sum[:half] = self._sum[0::2] + self._sum[1::2]
            self._t[:half] = self._t[0::2] + self._t[1::2]
            self._sum[half:], self._t[half:] = 0.0, 0.0
            self.factor *= 2
            i = half
        self._sum[i] += row
        self._t[i] += t
        self.n += 1

    def mean(self) -> np.ndarray:
        """The mean of every row pushed (merging keeps the sums exact)."""
        return self._sum.sum(axis=0) / max(self.n, 1)

    def columns(self) -> tuple[np.ndarray, np.ndarray]:
        """(rows (m, *row_shape) float64, times (m,)), each the mean of its rows."""
        if self._sum is None:
            return np.zeros((0,)), np.zeros(0)
        full, rest = divmod(self.n, self.factor)
        counts = np.full(full + (rest > 0), float(self.factor))
        if rest:
            counts[-1] = rest
        m = counts.size
        return self._sum[:m] / counts.reshape(-1, *([1] * (self._sum.ndim - 1))), self._t[:m] / counts

    def plot(self, rows: RowStream, bins: int, fps: float):
        """The thumbnail as a :class:`~wallcli.signal.stplot.StPlot` of ``rows``' stream (for the
        figures), the clip mean removed as compute_stplot removes it."""
        from wallcli.signal.stplot import StPlot

        cols, t = self.columns()
        mean = self.mean()
        x = (cols - mean).transpose(1, 0, 2).astype(np.float32)  # clip mean removed, as compute_stplot
        raw_mean = (mean + rows.ref).astype(np.float32)
        meta = {"source": str(rows.reader.info.source), "roi": list(rows.roi), "bins": bins, "fps": float(fps),
                "downsample": self.factor}
        return StPlot(np.ascontiguousarray(x[:bins]), np.ascontiguousarray(x[bins:]), t, raw_mean[:bins],
                      raw_mean[bins:], meta)
