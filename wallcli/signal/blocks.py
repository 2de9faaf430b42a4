"""Precise block averaging of image planes.

Sums are exact integers (OpenCV's integral image, int32 for 8-bit planes, float64 otherwise), so
a wall signal of a fraction of a code value survives averaging; a uint8 resize would round it
away. Block edges may be fractional: the integral image of box-shaped pixels is exactly bilinear
inside each pixel, so interpolating it gives exact area averages for any number of bins, even
bins smaller than a pixel (as with 4:2:0 chroma of a small ROI).
"""

from __future__ import annotations

import math
from contextlib import contextmanager

import numpy as np

from wallcli.errors import WallcliError

Roi = tuple[int, int, int, int]
MIN_ROI = 2  # pixels on each side of a requested ROI


def check_roi(roi: Roi | None, width: int, height: int) -> Roi:
    """Full frame when ``roi`` is None; otherwise it must lie inside the frame and be non-empty."""
    if roi is None:
        return (0, 0, int(width), int(height))
    x, y, w, h = (int(v) for v in roi)
    if w <= 0 or h <= 0:
        raise WallcliError(f"ROI {x},{y},{w},{h} is empty; the frame is {width}x{height}")
    if w < MIN_ROI or h < MIN_ROI:  # one rule for every command (snr needs a whole chroma sample)
        raise WallcliError(f"ROI {x},{y},{w},{h} is smaller than {MIN_ROI}x{MIN_ROI} pixels (one chroma sample of "
                           f"4:2:0 video); the frame is {width}x{height}")
    if x < 0 or y < 0 or x + w > width or y + h > height:
        raise WallcliError(f"ROI {x},{y},{w},{h} is outside the {width}x{height} frame "
                           f"(x+w must be <= {width}, y+h <= {height})")
    return (x, y, w, h)


def bin_edges(start: float, stop: float, bins: int) -> np.ndarray:
    """``bins`` equal-width (possibly fractional) edges spanning [start, stop]."""
    return np.linspace(float(start), float(stop), int(bins) + 1)


def _interp_integral(integral: np.ndarray, rows: np.ndarray, cols: np.ndarray) -> np.ndarray:
    """Bilinear interpolation of an integral image at fractional (rows x cols) positions."""
    h1, w1 = integral.shape
    r0 = np.clip(np.floor(rows).astype(np.intp), 0, h1 - 2)
    c0 = np.clip(np.floor(cols).astype(np.intp), 0, w1 - 2)
    fr = (rows - r0)[:, None]
    fc = (cols - c0)[None, :]
    a = integral[np.ix_(r0, c0)].astype(np.float64)
    b = integral[np.ix_(r0, c0 + 1)].astype(np.float64)
    c = integral[np.ix_(r0 + 1, c0)].astype(np.float64)
    d = integral[np.ix_(r0 + 1, c0 + 1)].astype(np.float64)
    return a * (1 - fr) * (1 - fc) + b * (1 - fr) * fc + c * fr * (1 - fc) + d * fr * fc


def integral_image(plane: np.ndarray) -> np.ndarray:
    import cv2

    if plane.dtype == np.uint8 and plane.size * 255 < 2**31:
        return cv2.integral(plane, sdepth=cv2.CV_32S)
    return cv2.integral(np.ascontiguousarray(plane) if plane.dtype != np.uint8 else plane, sdepth=cv2.CV_64F)


def block_means(plane: np.ndarray, row_edges: np.ndarray, col_edges: np.ndarray) -> np.ndarray:
    """Exact area means of ``plane`` over the grid of (possibly fractional) edges, float64.

    Edges are in the plane's pixel coordinates; only the spanned rectangle is integrated.
    """
    r_lo, r_hi = int(np.floor(row_edges[0])), int(np.ceil(row_edges[-1]))
    c_lo, c_hi = int(np.floor(col_edges[0])), int(np.ceil(col_edges[-1]))
    sub = plane[r_lo:r_hi, c_lo:c_hi]
    integ = integral_image(sub)
    j = _interp_integral(integ, np.asarray(row_edges, np.float64) - r_lo, np.asarray(col_edges, np.float64) - c_lo)
    sums = j[1:, 1:] - j[:-1, 1:] - j[1:, :-1] + j[:-1, :-1]
    area = np.diff(row_edges)[:, None] * np.diff(col_edges)[None, :]
    return sums / area


def rgb_grid(planes, roi: Roi, bins_y: int, bins_x: int) -> np.ndarray:
    """RGB means (0-255 scale, float64) of a ``bins_y`` x ``bins_x`` grid of equal blocks over ``roi``.

    Averages are taken on the decoded planes and converted to RGB afterwards: the YUV->RGB map is
    affine, so this equals converting every pixel first, at a fraction of the cost.
    """
    x, y, w, h = roi
    rows = bin_edges(y, y + h, bins_y)
    cols = bin_edges(x, x + w, bins_x)
    ym = block_means(planes.y, rows, cols)
    if planes.u is None:
        return planes.to_rgb(ym).astype(np.float64)
    # Chroma pixel k covers luma [k*2^s, (k+1)*2^s): scale the same edges down.
    crow = rows / (1 << planes.sub_y)
    ccol = cols / (1 << planes.sub_x)
    um = block_means(planes.u, crow, ccol)
    vm = block_means(planes.v, crow, ccol)
    return planes.to_rgb(ym, um, vm).astype(np.float64)


def _line_sums(plane: np.ndarray, axis: int) -> np.ndarray:
    """Exact integer sums along ``axis`` (0: one sum per column, 1: one per row), as float64."""
    import cv2

    if plane.dtype == np.uint8 and plane.shape[axis] * 255 < (1 << 24):
        # float32 holds every integer below 2^24 exactly, so these sums are exact, and OpenCV's
        # float accumulation is twice as fast as its int32 one.
        return cv2.reduce(plane, axis, cv2.REDUCE_SUM, dtype=cv2.CV_32F).ravel().astype(np.float64)
    return plane.sum(axis=axis, dtype=np.uint64).astype(np.float64)


class _Binner:
    """Per-bin means of per-pixel line sums over (possibly fractional) bin edges: the running sum
    of box-shaped pixels is exactly piecewise linear, so interpolating it at the edges gives each
    bin's covered share of every pixel, at the cost of a cumulative sum (a dense coverage matrix
    product cost 0.1-0.2 ms a 1080p frame, as much as the reductions themselves)."""

    def __init__(self, origin: int, n: int, edges: np.ndarray, across: float):
        e = np.asarray(edges, np.float64)
        self.at = e - origin  # edges in the sums' own pixel positions
        self.grid = np.arange(n + 1, dtype=np.float64)
        self.scale = 1.0 / (np.diff(e) * float(across))  # bin width x the other side's length
        self._run = np.zeros(n + 1, np.float64)

    def __call__(self, sums: np.ndarray) -> np.ndarray:
        np.cumsum(sums, out=self._run[1:])
        return np.diff(np.interp(self.at, self.grid, self._run)) * self.scale


def _fast_sums_fit(sub: np.ndarray) -> bool:
    return sub.dtype == np.uint8 and max(sub.shape) * 255 < (1 << 24)


class ProjectionPlan:
    """Exact means over a rectangle of one plane, binned two ways (see :func:`projection_means`).

    The binning matrices depend only on the geometry, so a stream builds the plan once and each
    frame costs two ``cv2.reduce`` passes and two cumulative sums.
    """

    def __init__(self, row_edges: np.ndarray, col_edges: np.ndarray):
        self.r0, self.r1 = float(row_edges[0]), float(row_edges[-1])
        self.c0, self.c1 = float(col_edges[0]), float(col_edges[-1])
        self.ri0, self.ri1 = int(np.floor(self.r0)), int(np.ceil(self.r1))
        self.ci0, self.ci1 = int(np.floor(self.c0)), int(np.ceil(self.c1))
        self.col_bins = _Binner(self.ci0, self.ci1 - self.ci0, col_edges, self.r1 - self.r0)
        self.row_bins = _Binner(self.ri0, self.ri1 - self.ri0, row_edges, self.c1 - self.c0)
        # decided on the first plane: 8-bit and a rectangle of whole pixels (see _fast_call)
        self._fast = None if (self.r0, self.r1, self.c0, self.c1) == (self.ri0, self.ri1, self.ci0, self.ci1) else False
        self._col_sums = np.empty((1, self.ci1 - self.ci0), np.float32)
        self._row_sums = np.empty((self.ri1 - self.ri0, 1), np.float32)

    def _fast_call(self, sub: np.ndarray, rows: bool) -> tuple[np.ndarray, np.ndarray | None]:
        """The common case (8-bit plane, whole-pixel rectangle): OpenCV sums into buffers made
        once, straight into the binning; no per-frame arrays but the (bins,) results.
        float32 holds these sums exactly (each under 2^24, checked in _fast_sums_fit)."""
        import cv2

        cv2.reduce(sub, 0, cv2.REDUCE_SUM, dst=self._col_sums, dtype=cv2.CV_32F)
        col = self.col_bins(self._col_sums[0])
        if not rows:
            return col, None
        cv2.reduce(sub, 1, cv2.REDUCE_SUM, dst=self._row_sums, dtype=cv2.CV_32F)
        return col, self.row_bins(self._row_sums[:, 0])

    def __call__(self, plane: np.ndarray, rows: bool = True) -> tuple[np.ndarray, np.ndarray | None]:
        """(column-bin means, row-bin means); ``rows=False`` skips the second reduction (None)."""
        sub = plane[self.ri0:self.ri1, self.ci0:self.ci1]
        if self._fast is None:
            self._fast = _fast_sums_fit(sub)
        if self._fast:
            return self._fast_call(sub, rows)
        col = _line_sums(sub, 0)
        if self.r0 > self.ri0:
            col -= (self.r0 - self.ri0) * sub[0].astype(np.float64)
        if self.ri1 > self.r1:
            col -= (self.ri1 - self.r1) * sub[-1].astype(np.float64)
        if not rows:
            return self.col_bins(col), None
        row = _line_sums(sub, 1)
        # Pixels cut by a fractional edge count by the fraction of them inside the rectangle.
        if self.c0 > self.ci0:
            row -= (self.c0 - self.ci0) * sub[:, 0].astype(np.float64)
        if self.ci1 > self.c1:
            row -= (self.ci1 - self.c1) * sub[:, -1].astype(np.float64)
        return self.col_bins(col), self.row_bins(row)


def projection_means(plane: np.ndarray, row_edges: np.ndarray, col_edges: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Means over the rectangle spanned by the edges, binned two ways, exact:

    ``cols``: for each column bin, the mean over all rows of the rectangle (len(col_edges)-1),
    ``rows``: for each row bin, the mean over all columns (len(row_edges)-1).
    Equal to averaging ``block_means`` over one axis, with two cheap reductions instead of an
    integral image (about 8x faster on 1080p; this is stplot's per-frame cost).
    """
    return ProjectionPlan(row_edges, col_edges)(plane)


@contextmanager
def one_opencv_thread():
    """Run OpenCV on one thread inside: per-frame reductions and small images (~0.1 ms) are too
    short for its pool to pay for its hand-offs, and the decoder thread already keeps every core
    busy. Measured on 1080p H.264, 2 cores: 0.25 ms a frame on one thread against 0.75 on two (2-3
    ms with other work on the cores); `wallcli count` 15 % and `stplot` 22 % less wall time
    (bench/RESULTS.md, session 10). Restored on leaving, so a program using wallcli as a library
    keeps its own OpenCV threading. A toggle is 0.2 us alone but 0.3-0.7 ms once the pool has
    worked (it is rebuilt), so :class:`wallcli.camera.pipeline.CameraPipeline` holds one thread
    for the whole decode and the per-frame calls inside find it set."""
    import cv2

    threads = cv2.getNumThreads()
    if threads == 1:  # already inside one (the camera pipeline holds it for a whole decode)
        yield
        return
    cv2.setNumThreads(1)
    try:
        yield
    finally:
        cv2.setNumThreads(threads)


class LineShift:
    """How far the picture moved along one axis since the first frame, from its line sums: a
    column-sum profile moves with the picture, so correlating the profile's fine structure (a
    31-pixel moving average removed: light changes, people's shadows and shading are smoother
    than that) with the first frame's gives the shift, to a few hundredths of a pixel by a
    parabola through the peak (17 dot products of one line, against a 2-D registration of frames).

    A shift is reported only where the fine structure matches the first frame's with a
    correlation of at least MATCH: a wall without features (a door frame, a switch, a corner)
    keeps its random texture under the noise once a column sums it, gives no shift, and is also
    the wall whose profiles a shake changes least. Searched within MAX pixels: larger motion is
    the view check's to refuse."""

    MAX = 8
    MATCH = 0.8
    SMOOTH = 31
    MIN = 0.0  # pixels: any shift found is applied (a deadband left edge bins jumping by codes)

    def __init__(self) -> None:
        self._ref = None
        self._window = None

    def _fine(self, sums: np.ndarray) -> np.ndarray:
        import cv2

        line = np.asarray(sums, np.float32).reshape(1, -1)
        fine = line - cv2.blur(line, (self.SMOOTH, 1), borderType=cv2.BORDER_REFLECT)
        if self._window is None or self._window.size != fine.size:
            # tapered only over its outer eighths: a Hann window all but hid features near the
            # frame's edges (a skirting board), so their motion was registered on others alone
            n = fine.size
            edge = max(2, n // 8)
            ramp = 0.5 - 0.5 * np.cos(np.pi * (np.arange(edge) + 0.5) / edge)
            self._window = np.concatenate([ramp, np.ones(n - 2 * edge), ramp[::-1]]).astype(np.float32)
        return (fine[0] * self._window).astype(np.float64)

    def __call__(self, sums: np.ndarray) -> float:
        if len(sums) < 4 * self.SMOOTH:
            return 0.0
        fine = self._fine(sums)
        energy = float(fine @ fine)
        m = self.MAX
        if self._ref is None or self._ref[0].shape[1] != fine.size:
            # the circular correlation at lags -m..m only, as one product with the first frame's
            # line rolled by each lag: two FFTs of the whole line cost three times as much
            self._ref = (np.stack([np.roll(fine, lag) for lag in range(-m, m + 1)]), energy)
            return 0.0
        ref, ref_energy = self._ref
        # the 17 values as Python floats: the same IEEE arithmetic as numpy's scalars, a tenth of the overhead
        near = ((ref @ fine) / max(math.sqrt(energy * ref_energy), 1e-30)).tolist()  # lags -m..m
        k = max(range(2 * m + 1), key=near.__getitem__)  # the first largest, as np.argmax
        if not 0 < k < 2 * m or near[k] < self.MATCH:
            return 0.0
        a, b, d = near[k - 1], near[k], near[k + 1]
        den = a - 2 * b + d
        frac = 0.5 * (a - d) / den if den < 0 else 0.0
        shift = float(k - m + min(max(frac, -0.5), 0.5))
        return shift if abs(shift) >= self.MIN else 0.0


class LumaShift:
    """A frame's (dx, dy) since the first frame, from its luma ROI's column and row sums
    (:class:`LineShift` on each), for callers that do not sum the lines already (the SNR
    estimator; the projector reuses its own sums)."""

    def __init__(self) -> None:
        self._x, self._y = LineShift(), LineShift()

    def __call__(self, luma: np.ndarray) -> tuple[float, float]:
        import cv2

        with one_opencv_thread():
            # every 4th row: a vertical feature's column profile is the same, at a quarter of the cost
            cols = cv2.reduce(luma[::4], 0, cv2.REDUCE_SUM, dtype=cv2.CV_32F)[0]
            rows = cv2.reduce(luma, 1, cv2.REDUCE_SUM, dtype=cv2.CV_32F)[:, 0]
        return self._x(cols), self._y(rows)


class _FusedProjection:
    """Both profiles of every 8-bit plane over whole-pixel rectangles, in one buffer: OpenCV sums
    each line into its slice, then one reduceat over the spans between all the bin edges and a
    cumulative sum of the spans give every bin mean (the per-plane path spent as long on six
    small binning steps as on the reductions). Returns (2 or 1, bins, planes) means; exact as
    :class:`ProjectionPlan`."""

    def __init__(self, rects, rows: bool, stabilize: bool = False, sub=(0, 0), register: bool = False):
        import cv2

        self._reduce, self._sum = cv2.reduce, cv2.REDUCE_SUM
        self.rects = rects  # per plane: (r0, r1, c0, c1, row_edges, col_edges), whole pixels
        axes = [0, 1] if rows else [0]
        layout = [(p, axis) for axis in axes for p in range(len(rects))]
        sizes = [(r[3] - r[2]) if axis == 0 else (r[1] - r[0]) for (p, axis), r in
                 ((pa, rects[pa[0]]) for pa in layout)]
        self.buf = np.empty(sum(sizes), np.float32)
        self._run = np.zeros(self.buf.size + 1, np.float64)
        self._grid = np.arange(self.buf.size + 1, dtype=np.float64)
        self.jobs, at, lo, scale, per_px, bounds, acr = [], [], [], [], [], [], []
        offset = 0
        self.lines = {}  # (plane, axis) -> that line-sum vector in the buffer (a view)
        for (p, axis), n in zip(layout, sizes):
            r0, r1, c0, c1, re, ce = rects[p]
            view = self.buf[offset:offset + n]
            self.lines[(p, axis)] = view
            self.jobs.append((p, axis, view.reshape((1, n) if axis == 0 else (n, 1))))
            edges, origin, across = (ce, c0, r1 - r0) if axis == 0 else (re, r0, c1 - c0)
            lo.extend(len(at) + np.arange(len(edges) - 1))
            at.extend(np.asarray(edges, np.float64) - origin + offset)
            scale.extend(1.0 / (np.diff(edges) * across))
            acr.extend([across] * (len(edges) - 1))
            # a luma shift in this plane's pixels (chroma is subsampled), along this axis
            sx, sy = (0, 0) if p == 0 else sub
            unit = np.zeros(2)
            unit[axis] = 1.0 / (1 << (sx if axis == 0 else sy))
            per_px.extend([unit] * len(edges))
            bounds.extend([(offset, offset + n)] * len(edges))
            offset += n
        self.at = np.asarray(at)
        self.lo = np.asarray(lo)
        self._hi = self.lo + 1
        # The running sum at the edges without a cumulative sum of the whole buffer (20 us a 1080p
        # frame): one reduceat sums the whole pixels between consecutive edges, a cumulative sum of
        # those ~200 spans gives the running sum at each edge's pixel, and a cut pixel adds its
        # share as np.interp adds it. The sums are exact integers in float64 and the share is the
        # same product and sum, so the means are bit-identical to interpolating the running sum.
        fl = np.floor(self.at).astype(np.intp)
        self._starts = fl[:-1]
        empty = np.flatnonzero(fl[1:] == fl[:-1])  # reduceat gives such a span its first pixel, not 0
        self._empty = empty if empty.size else None
        self._cum = np.zeros(len(self.at), np.float64)
        self._frac = self.at - fl
        self._cut = np.flatnonzero(self._frac)
        self._cut_px = fl[self._cut]
        self._cut_frac = self._frac[self._cut]
        self.scale = np.asarray(scale)
        self._across = np.asarray(acr, np.float64)
        self._per_px = np.asarray(per_px)  # (edges, 2): how far each edge moves per (dx, dy) pixel
        self._bounds = np.asarray(bounds, np.float64)
        self.stabilize = bool(stabilize)
        # register: measure the shift on both axes without re-binning (the corrections regress the
        # profiles on it, shake.py); a horizontal-only projection then sums the luma rows too
        self.register = bool(register) or self.stabilize
        self._shift_x = LineShift() if self.register else None
        self._shift_y = LineShift() if self.register and (rows or register) else None
        r0, r1, c0, c1 = rects[0][:4]
        self._luma_rows = np.empty((r1 - r0, 1), np.float32) if self._shift_y is not None and not rows else None
        self.shift = (0.0, 0.0)  # the last frame's (dx, dy) in luma pixels
        self.shape = (len(axes), len(rects), len(rects[0][5]) - 1)

    def __call__(self, planes) -> np.ndarray:
        for p, axis, dst in self.jobs:
            r0, r1, c0, c1 = self.rects[p][:4]
            self._reduce(planes[p][r0:r1, c0:c1], axis, self._sum, dst=dst, dtype=5)  # 5: CV_32F
        if self.register:
            dx = self._shift_x(self.lines[(0, 0)])
            dy = 0.0
            if self._luma_rows is not None:
                r0, r1, c0, c1 = self.rects[0][:4]
                self._reduce(planes[0][r0:r1, c0:c1], 1, self._sum, dst=self._luma_rows, dtype=5)
                dy = self._shift_y(self._luma_rows[:, 0])
            elif self._shift_y is not None:
                dy = self._shift_y(self.lines[(0, 1)])
            self.shift = (dx, dy)
            if self.stabilize and (dx or dy):
                return self._shifted(dx, dy)
        spans = np.add.reduceat(self.buf, self._starts, dtype=np.float64)
        if self._empty is not None:
            spans[self._empty] = 0.0
        at = self._cum
        np.cumsum(spans, out=at[1:])
        if self._cut.size:  # (never the first edge, which stays 0)
            at[self._cut] += self._cut_frac * self.buf[self._cut_px]
        means = (at[self._hi] - at[self.lo]) * self.scale
        return means.reshape(self.shape).transpose(0, 2, 1)

    def _shifted(self, dx: float, dy: float) -> np.ndarray:
        """Bin means of the picture as it was in the first frame: each edge read where the picture
        moved it (the running sum of box pixels is exact at fractional positions); a bin that the
        motion pushed past the frame's edge is averaged over the part still in view."""
        np.cumsum(self.buf, dtype=np.float64, out=self._run[1:])
        pos = np.clip(self.at + self._per_px @ np.array([dx, dy]), self._bounds[:, 0], self._bounds[:, 1])
        at = np.interp(pos, self._grid, self._run)
        width = (pos[self.lo + 1] - pos[self.lo]) * self._across
        means = (at[self.lo + 1] - at[self.lo]) / np.maximum(width, 1e-9)
        return means.reshape(self.shape).transpose(0, 2, 1)


def _fused_rects(planes, rows: np.ndarray, cols: np.ndarray):
    """The rectangles of :class:`_FusedProjection` when it applies (every plane 8-bit, edges on
    whole pixels, sums under 2^24 so float32 holds them exactly), else None."""
    arrays = [planes.y] if planes.u is None else [planes.y, planes.u, planes.v]
    rects = []
    for i, a in enumerate(arrays):
        sy, sx = (0, 0) if i == 0 else (planes.sub_y, planes.sub_x)
        re, ce = rows / (1 << sy), cols / (1 << sx)
        r0, r1, c0, c1 = re[0], re[-1], ce[0], ce[-1]
        if a.dtype != np.uint8 or any(v != int(v) for v in (r0, r1, c0, c1)) \
                or max(r1 - r0, c1 - c0) * 255 >= (1 << 24):
            return None
        rects.append((int(r0), int(r1), int(c0), int(c1), re, ce))
    return rects


class ShiftLog:
    """What stabilisation found over a stream, in memory that does not grow: frames moved (by at
    least LineShift.MIN), and the RMS and largest of their shifts (luma pixels)."""

    def __init__(self) -> None:
        self.frames = self.moved = 0
        self._sq = 0.0
        self.largest = 0.0

    def add(self, dx: float, dy: float) -> None:
        self.frames += 1
        r2 = dx * dx + dy * dy
        if r2:
            self.moved += 1
            self._sq += r2
            self.largest = max(self.largest, float(np.sqrt(r2)))

    def summary(self) -> dict | None:
        """The ``corrections`` entry, or None when no frame was moved."""
        if not self.moved:
            return None
        return {"kind": "shake", "frames": self.moved, "of": self.frames,
                "rms_px": round(float(np.sqrt(self._sq / self.moved)), 3), "max_px": round(self.largest, 3)}


class RgbProjector:
    """Per frame: the horizontal and vertical RGB profiles (bins, 3) of ``roi``, float64, 0-255.

    Plans are built for the first frame's plane geometry and rebuilt only if it changes.
    ``vertical=False`` skips the vertical profile (returned as zeros): a model that reads only the
    horizontal plot (count) saves half of the per-frame reductions.
    """

    def __init__(self, roi: Roi, bins: int, vertical: bool = True, stabilize: bool = False, register: bool = False):
        self.vertical = bool(vertical)
        self.stabilize = bool(stabilize)
        self.register = bool(register)
        self.shift = (0.0, 0.0)  # the last frame's measured (dx, dy), luma pixels (register or stabilize)
        self.shifts = ShiftLog()
        self._zeros = np.zeros((int(bins), 3))
        x, y, w, h = roi
        self.rows = bin_edges(y, y + h, bins)
        self.cols = bin_edges(x, x + w, bins)
        self._key = None

    def __call__(self, planes) -> tuple[np.ndarray, np.ndarray]:
        with one_opencv_thread():
            return self._project(planes)

    def column_sums(self) -> list[np.ndarray] | None:
        """The last frame's column sums over ``roi`` of each plane (float32 views of exact integers,
        valid until the next frame; chroma's over its own subsampled columns), or None where the
        projection took its per-plane path (not 8-bit, chroma edges inside pixels, or sums past
        float32's exact integers: see _fused_rects)."""
        f = self._fused
        return None if f is None else [f.lines[(p, 0)] for p in range(len(f.rects))]

    def _project(self, planes) -> tuple[np.ndarray, np.ndarray]:
        key = (planes.u is None, planes.sub_x, planes.sub_y, planes.kind, planes.depth, planes.matrix,
               planes.full_range)
        if key != self._key:
            self._key = key
            self._luma = ProjectionPlan(self.rows, self.cols)
            self._chroma = ProjectionPlan(self.rows / (1 << planes.sub_y), self.cols / (1 << planes.sub_x))
            # to_rgb as one affine map: its dozen numpy steps on (bins,) arrays cost more than the
            # reductions themselves (bench/RESULTS.md, issue 28)
            self._m, self._b = planes.rgb_affine()
            self._yuv = np.zeros((2, len(self.cols) - 1, 3))
            rects = _fused_rects(planes, self.rows, self.cols)
            self._fused = None if rects is None else _FusedProjection(
                rects, self.vertical, self.stabilize, (planes.sub_x, planes.sub_y), self.register)
        v = self.vertical
        if self._fused is not None:
            arrays = (planes.y,) if planes.u is None else (planes.y, planes.u, planes.v)
            m = self._fused(arrays)
            if self.stabilize or self.register:
                self.shift = self._fused.shift
                self.shifts.add(*self.shift)
            if planes.u is None:
                m = np.repeat(m, 3, axis=2)  # y alone: rgb_affine's chroma rows are then zero
            rgb = (m @ self._m + self._b).astype(np.float32).astype(np.float64)
            return rgb[0], (rgb[1] if v else self._zeros)
        yuv = self._yuv
        yuv[0, :, 0], r = self._luma(planes.y, v)
        if v:
            yuv[1, :, 0] = r
        if planes.u is not None:
            yuv[0, :, 1], r = self._chroma(planes.u, v)
            if v:
                yuv[1, :, 1] = r
            yuv[0, :, 2], r = self._chroma(planes.v, v)
            if v:
                yuv[1, :, 2] = r
        # float32 as to_rgb gives: the rows stored downstream are float32 anyway
        rgb = (yuv[: 2 if v else 1] @ self._m + self._b).astype(np.float32).astype(np.float64)
        return rgb[0], (rgb[1] if v else self._zeros)
