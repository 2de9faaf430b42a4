"""Signal and noise of a wall video (Sharma et al. 2021, supplementary §3.2); per grid cell: snr_map.py; predicted from physics (§3.1): snr_predict.py.

Estimator. V is the video with each pixel's temporal mean removed and T shifts it by one frame.
The signal is slow, so V - T(V) is (almost) noise alone and frame noise is independent:
    noise power  = 1/2 Var(V - T(V)),   signal power = Var V - 1/2 Var(V - T(V)).
Both are computed per pixel (or per block mean) over time, then averaged over pixels, per RGB
channel, in squared 8-bit code values.

One streaming pass: per frame the RGB values of the measured pixels (float32, never rounded) are
centred on the first frame, so squares stay small and float64 sums lose nothing to cancellation;
we keep sums, sums of squares and sums of squared frame differences. Memory is a few copies of
the measured pixels, whatever the video's length. Block sizes 2..32 come from a pyramid of 2x2
sums of the already converted frame; their sums are linear in the pixels, so only the squares
need accumulating per block size.

Which pixels: the whole ROI when it holds at most ``max_pixels`` pixels (exact); otherwise a
regular lattice of whole 32x32 tiles spread over the ROI, about ``max_pixels`` pixels in all.
All block sizes come from the same tiles, so the curve over block size compares like with like.
The powers are averages over pixels, so a spread sample is an unbiased estimate of them; this is
what keeps a 1080p video at decode speed (a float64 accumulator over 6 M values costs more per
frame than decoding it).

Chroma: a 4:2:0 pixel's colour is the chroma sample covering it (as in ``blocks.rgb_grid``, whose
area means this matches), so the ROI is shrunk to whole chroma samples (even x, y, w, h).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from wallcli.errors import WallcliError
from wallcli.signal.blocks import Roi

SCALES = (1, 2, 4, 8, 16, 32)
CHANNELS = ("r", "g", "b")
TILE = 32
DEFAULT_MAX_PIXELS = 1 << 15
CHUNK = 32  # frames summed in float32 before joining the float64 totals
MIN_FRAMES = 3
SHAKE_BLOCK = 2  # the block size from which the shake is regressed out (see SnrAccumulator)


# ---------------------------------------------------------------------------------- helpers
def affine_rgb(planes) -> np.ndarray:
    """(3, 3) matrix M with RGB = M @ (y, u, v) + offset, taken from ``Planes.to_rgb`` itself.

    Variances do not depend on the offset; asking to_rgb keeps one source for the matrices,
    ranges and bit-depth scaling.
    """
    if planes.u is None:
        rows = np.asarray(planes.to_rgb(np.array([0.0, 1.0])), np.float64)
        m = np.zeros((3, 3))
        m[:, 0] = rows[1] - rows[0]
        return m
    e = np.eye(4)[:, 1:]  # origin, then one unit step per plane
    rows = np.asarray(planes.to_rgb(e[:, 0], e[:, 1], e[:, 2]), np.float64)
    return (rows[1:] - rows[0]).T


def footprint(planes) -> tuple[int, int]:
    """Luma pixels per chroma sample (rows, cols); (1, 1) without subsampled chroma."""
    if planes.u is None or planes.kind != "yuv":
        return 1, 1
    return 1 << planes.sub_y, 1 << planes.sub_x


def snap_roi(roi: Roi, fy: int, fx: int) -> Roi:
    """Shrink ``roi`` inwards to whole chroma samples."""
    x, y, w, h = roi
    x1, y1 = -(-x // fx) * fx, -(-y // fy) * fy
    x2, y2 = (x + w) // fx * fx, (y + h) // fy * fy
    if x2 - x1 < fx or y2 - y1 < fy:
        raise WallcliError(f"ROI {x},{y},{w},{h} is smaller than one chroma sample ({fx}x{fy} pixels)")
    return (x1, y1, x2 - x1, y2 - y1)


def _pair(a: np.ndarray, axis: int) -> np.ndarray:
    """Sums of neighbouring pairs along ``axis`` (a trailing odd element is dropped)."""
    n = a.shape[axis] // 2 * 2
    lo = [slice(None)] * a.ndim
    hi = [slice(None)] * a.ndim
    lo[axis], hi[axis] = slice(0, n, 2), slice(1, n, 2)
    return a[tuple(lo)] + a[tuple(hi)]


def _halve(a: np.ndarray) -> np.ndarray:
    """(3, nty, th, ntx, tw) sums of NxN blocks -> sums of 2Nx2N blocks."""
    return _pair(_pair(a, 2), 4)


# ---------------------------------------------------------------------------------- sampling
@dataclass
class Lattice:
    """Where the measured pixels are: ``nty`` x ``ntx`` tiles of ``th`` x ``tw`` pixels."""

    roi: Roi
    nty: int
    ntx: int
    th: int
    tw: int
    step_y: int  # pixels between tile origins
    step_x: int
    oy: int  # first tile origin (frame pixels)
    ox: int

    @property
    def pixels(self) -> int:
        return self.nty * self.ntx * self.th * self.tw

    @property
    def exact(self) -> bool:
        return self.nty == 1 and self.ntx == 1 and (self.th, self.tw) == (self.roi[3], self.roi[2])

    @classmethod
    def plan(cls, roi: Roi, max_pixels: int) -> "Lattice":
        x, y, w, h = roi
        my, mx = h // TILE, w // TILE
        if max_pixels <= 0 or w * h <= max_pixels or my * mx == 0:
            return cls(roi, 1, 1, h, w, h, w, y, x)
        want = max(1, max_pixels // (TILE * TILE))
        step = max(1, math.ceil(math.sqrt(my * mx / want)))
        while math.ceil(my / step) * math.ceil(mx / step) > want and step < max(my, mx):
            step += 1
        nty, ntx = math.ceil(my / step), math.ceil(mx / step)
        # Centre the lattice in the ROI so the margins on both sides are alike; the margin is a
        # multiple of 4 so the tiles stay on whole chroma samples of the snapped ROI (4:2:0, 4:1:1),
        # or view() would pair luma rows with the chroma sample of their neighbours.
        oy = y + ((h - ((nty - 1) * step + 1) * TILE) // 8) * 4
        ox = x + ((w - ((ntx - 1) * step + 1) * TILE) // 8) * 4
        return cls(roi, nty, ntx, TILE, TILE, step * TILE, step * TILE, oy, ox)

    def view(self, plane: np.ndarray, fy: int = 1, fx: int = 1) -> np.ndarray:
        """(nty, th/fy, ntx, tw/fx) strided view of the tiles in a (possibly subsampled) plane."""
        sub = plane[self.oy // fy:, self.ox // fx:]
        rs, cs = sub.strides
        shape = (self.nty, self.th // fy, self.ntx, self.tw // fx)
        need_r = (self.nty - 1) * self.step_y // fy + self.th // fy
        need_c = (self.ntx - 1) * self.step_x // fx + self.tw // fx
        if sub.shape[0] < need_r or sub.shape[1] < need_c:
            raise WallcliError("the video's frame size changed mid-stream; wallcli snr needs a constant size")
        strides = (self.step_y // fy * rs, rs, self.step_x // fx * cs, cs)
        return np.lib.stride_tricks.as_strided(sub, shape, strides, writeable=False)


# ---------------------------------------------------------------------------------- results
@dataclass
class ScaleStats:
    block: int
    signal_power: np.ndarray  # (3,)
    noise_power: np.ndarray  # (3,)
    blocks: int  # blocks the average ran over

    @property
    def snr_db(self) -> np.ndarray:
        return snr_db(self.signal_power, self.noise_power)


SNR_DB_LIMIT = 99.0


def snr_db(signal, noise) -> np.ndarray:
    """10 log10(signal / noise), clipped to +-99 dB so the contract's fields stay numbers.

    -99 means no detectable signal (the estimated signal power is <= 0, which the estimator
    gives when frame-to-frame noise explains all the variance); +99 means no measurable noise
    (only in synthetic, noise-free video).
    """
    s = np.asarray(signal, np.float64)
    n = np.asarray(noise, np.float64)
    with np.errstate(divide="ignore", invalid="ignore"):
        out = 10.0 * np.log10(np.maximum(s, 0.0) / n)
    out = np.where(s <= 0, -SNR_DB_LIMIT, out)
    return np.clip(np.nan_to_num(out, nan=-SNR_DB_LIMIT), -SNR_DB_LIMIT, SNR_DB_LIMIT)


@dataclass
class SnrResult:
    frames: int
    roi: Roi
    scales: list[ScaleStats]
    sampled_pixels: int
    exact: bool
    warnings: list[str] = field(default_factory=list)

    def scale(self, block: int) -> ScaleStats:
        return next(s for s in self.scales if s.block == block)


def powers_from_sums(s1, s2, sd, dsum, frames: int, area: float, axes) -> tuple[np.ndarray, np.ndarray]:
    """Signal and noise power averaged over ``axes`` from per-block sums of centred values.

    s1, s2: sums over time of x and x^2; sd: of squared frame differences; dsum: sum of the
    differences (= last - first). ``area`` converts block sums to block means (pixels per block).
    Unbiased variances: T-1 degrees of freedom for values, T-2 for the T-1 differences.
    """
    t = float(frames)
    var_v = (s2 - s1 * s1 / t) / (t - 1.0)
    var_d = (sd - dsum * dsum / (t - 1.0)) / (t - 2.0)
    total = var_v.mean(axis=axes) / area**2
    noise = 0.5 * var_d.mean(axis=axes) / area**2
    return total - noise, noise


# ---------------------------------------------------------------------------------- estimator
class SnrAccumulator:
    """Feed decoded frames' planes with :meth:`update`; :meth:`result` gives every block size.

    With ``corrections`` (:class:`wallcli.camera.corrections.Options`) and the video's frame rate
    ``fps``, the whole-frame light nuisances (aliased mains flicker, exposure steps, drift) are
    found on the measured pixels' row and column means and divided out of every pixel before the
    sums (each pixel by the gain of its row band, so rolling-shutter bands go too). The gains are
    final a few seconds later (:class:`~wallcli.camera.corrections.LaggedGains`), so that many
    frames' measured pixels wait in memory; :attr:`corrections` says what was found.

    With ``corrections.shake``, each frame's sub-pixel shift is measured on the ROI's luma line
    sums and the camera's shake is regressed out of every pixel's series at the end, from sums
    (:class:`wallcli.camera.shake.ShakeSums`), as the classifiers do on their plots; from blocks
    of 2x2 pixels up (kept per pixel, its sums cost three times the estimator's own work; single
    pixels' SNR is left uncorrected).
    """

    def __init__(self, roi: Roi, *, max_pixels: int = DEFAULT_MAX_PIXELS, scales=SCALES, corrections=None,
                 fps: float | None = None):
        self.roi_requested = roi
        self.max_pixels = int(max_pixels)
        self.scales = tuple(scales)
        self.frames = 0
        self.warnings: list[str] = []
        self.options = corrections if corrections is not None and corrections.light and fps else None
        self.shake = corrections is not None and corrections.shake
        self._shake = None  # ShakeSums, set up with the first frame
        self._found_shake = None
        self.fps = fps
        self.gains = None
        self._waiting = None
        self._ready = False

    def _setup(self, planes) -> None:
        self.fy, self.fx = footprint(planes)
        self.roi = snap_roi(self.roi_requested, self.fy, self.fx)
        if self.roi != tuple(self.roi_requested):
            self.warnings.append(f"ROI {','.join(map(str, self.roi_requested))} shrunk to "
                                 f"{','.join(map(str, self.roi))} (whole {self.fx}x{self.fy} chroma samples)")
        self.lattice = Lattice.plan(self.roi, self.max_pixels)
        self.m = affine_rgb(planes).astype(np.float32)
        self.chroma = planes.u is not None
        lat = self.lattice
        self.levels = [n for n in self.scales if lat.th // n >= 1 and lat.tw // n >= 1]
        if self.shake and SHAKE_BLOCK in self.levels:
            from wallcli.signal.blocks import LumaShift
            from wallcli.camera.shake import ShakeSums

            self._register = LumaShift()
            self._shake = ShakeSums((3, lat.nty, lat.th // SHAKE_BLOCK, lat.ntx, lat.tw // SHAKE_BLOCK))
        if self.options is not None:
            from collections import deque

            from wallcli.camera import corrections as corr

            self.row_band = corr.bands(lat.nty * lat.th)
            self.col_band = corr.bands(lat.ntx * lat.tw)
            nr, nc = int(self.row_band[-1]) + 1, int(self.col_band[-1]) + 1
            self.gains = corr.LaggedGains(float(self.fps), lines=corr.mains_lines(self.fps, float(self.fps)),
                                          options=self.options, vertical=slice(0, nr))
            self._waiting = deque()
            self._nr, self._nc = nr, nc
            # the measured values leave out RGB's affine offset (variances do not need it); a
            # multiplicative change of the light multiplies the values with it
            self._offset = np.asarray(planes.rgb_affine(chroma=planes.u is not None)[1], np.float32)
            self._row_px = np.bincount(self.row_band, minlength=nr) * (lat.ntx * lat.tw)
            self._col_px = np.bincount(self.col_band, minlength=nc) * (lat.nty * lat.th)

    def _rgb(self, planes) -> np.ndarray:
        """The measured pixels as float32 RGB, shape (3, nty, th, ntx, tw)."""
        lat, m = self.lattice, self.m
        y = lat.view(planes.y).astype(np.float32)
        out = np.empty((3,) + y.shape, np.float32)
        if not self.chroma:
            for c in range(3):
                np.multiply(y, m[c, 0], out=out[c])
            return out
        fy, fx = self.fy, self.fx
        u = lat.view(planes.u, fy, fx).astype(np.float32)
        v = lat.view(planes.v, fy, fx).astype(np.float32)
        ny, nx = y.shape[1] // fy, y.shape[3] // fx
        for c in range(3):
            o = out[c].reshape(lat.nty, ny, fy, lat.ntx, nx, fx)
            np.multiply(y.reshape(o.shape), m[c, 0], out=o)
            # chroma is constant over its footprint: add it once per sample, broadcast
            o += (m[c, 1] * u + m[c, 2] * v)[:, :, None, :, :, None]
        return out

    @property
    def corrections(self) -> list[dict]:
        """What the corrections found and removed (the JSON ``corrections``), [] without them."""
        found = self.gains.corrections() if self.gains is not None else []
        return found + ([self._found_shake] if self._found_shake else [])

    def _profile(self, x: np.ndarray) -> np.ndarray:
        """Row-band then column-band sums of the measured pixels (colours summed)."""
        rows = x.sum(axis=(0, 3, 4)).reshape(-1)
        cols = x.sum(axis=(0, 1, 2)).reshape(-1)
        off = float(self._offset.sum())
        return np.concatenate([np.bincount(self.row_band, rows, self._nr) + off * self._row_px,
                               np.bincount(self.col_band, cols, self._nc) + off * self._col_px])

    def _release(self, ready) -> None:
        lat = self.lattice
        for _, g in ready:
            x, shift = self._waiting.popleft()
            if np.any(g):
                per_row = (1.0 + g[:self._nr])[self.row_band].reshape(lat.nty, lat.th).astype(np.float32)
                off = self._offset[:, None, None, None, None]
                x += off
                x /= per_row[None, :, :, None, None]
                x -= off
            self._add(x, shift)

    def update(self, planes) -> None:
        if not self._ready:
            self._setup(planes)
            self._ready = True
            from wallcli.snr.column import ColumnSnr

            self.column = ColumnSnr(self.roi, fps=self.fps)  # the headline figure, same frames
        self.column.push(planes)
        x = self._rgb(planes)
        x0, y0, w, h = self.roi
        shift = self._register(planes.y[y0:y0 + h, x0:x0 + w]) if self._shake is not None else None
        if self.gains is None:
            self._add(x, shift)
            return
        self._waiting.append((x, shift))
        self._release(self.gains.push(self._profile(x)))

    def finish(self) -> None:
        """Hand every frame still waiting for its gain to the sums (at the end of the video)."""
        if self.gains is not None and self._waiting is not None:
            self._release(self.gains.flush())

    def _add(self, x: np.ndarray, shift=None) -> None:
        if self.frames == 0:
            if shift is not None:
                self._shake.first(*shift)
            self.first = x
            self.prev = x
            # float32 sums over a chunk of frames (same-type adds cost about half of float32 ->
            # float64 ones), flushed into float64 totals every CHUNK frames; values are centred on
            # the first frame, so a chunk's sums are small and keep full precision
            self.s1 = np.zeros(x.shape, np.float64)
            self.c1 = np.zeros(x.shape, np.float32)
            self.s2, self.sd, self.c2, self.cd = {}, {}, {}, {}
            shape = x.shape
            for n in self.levels:
                if n > 1:
                    shape = (3, shape[1], shape[2] // 2, shape[3], shape[4] // 2)
                self.s2[n] = np.zeros(shape, np.float64)
                self.sd[n] = np.zeros(shape, np.float64)
                self.c2[n] = np.zeros(shape, np.float32)
                self.cd[n] = np.zeros(shape, np.float32)
            self._buf = np.empty(x.size, np.float32)
            self._pending = 0
            self.frames = 1
            return
        c = np.subtract(x, self.first)
        d = np.subtract(x, self.prev)
        self.prev = x
        self.c1 += c
        for n in self.levels:
            if n > 1:
                c, d = _halve(c), _halve(d)
            if n == SHAKE_BLOCK and shift is not None:
                self._shake.add(c, d, *shift)
            b = self._buf[: c.size].reshape(c.shape)
            np.multiply(c, c, out=b)
            self.c2[n] += b
            np.multiply(d, d, out=b)
            self.cd[n] += b
        self.frames += 1
        self._pending += 1
        if self._pending >= CHUNK:
            self._flush()

    def _flush(self) -> None:
        if self._pending == 0:
            return
        self.s1 += self.c1
        self.c1.fill(0)
        for n in self.levels:
            self.s2[n] += self.c2[n]
            self.sd[n] += self.cd[n]
            self.c2[n].fill(0)
            self.cd[n].fill(0)
        self._pending = 0

    def result(self) -> SnrResult:
        self.finish()
        if self.frames < MIN_FRAMES:
            raise WallcliError(f"only {self.frames} frame(s) decoded; the noise estimate needs at least "
                               f"{MIN_FRAMES} (it compares consecutive frames, over time)")
        self._flush()
        s1 = self.s1
        dsum = (self.prev - self.first).astype(np.float64)
        sh = self._shake
        per_level = {}  # block size -> (s1, dsum, sum(X c), sum(dX d)) block sums
        xc = dxd = None
        for n in self.levels:
            if n > 1:
                s1, dsum = _halve(s1), _halve(dsum)
                if xc is not None:
                    xc, dxd = np.stack([_halve(a) for a in xc]), np.stack([_halve(a) for a in dxd])
            if n == SHAKE_BLOCK and sh is not None:
                xc, dxd = sh.xc.reshape((-1,) + s1.shape), sh.dxd.reshape((-1,) + s1.shape)
            per_level[n] = (s1, dsum, xc, dxd)
        if sh is not None and self.levels:
            # judged on the largest blocks, whose noise is averaged as a plot bin's is (the
            # classifiers' bar); single pixels' noise would hide a shake's share
            top = self.levels[-1]
            self._found_shake = sh.finding(self.sd[top], per_level[top][1], per_level[top][3])
        scales = []
        for n in self.levels:
            s1, dsum, xc, dxd = per_level[n]
            sums = (s1, self.s2[n], self.sd[n], dsum)
            if self._found_shake and xc is not None:
                sums = sh.corrected(*sums, xc, dxd)
            sig, noi = powers_from_sums(*sums, self.frames, float(n * n), (1, 2, 3, 4))
            scales.append(ScaleStats(n, sig, noi, int(np.prod(s1.shape[1:]))))
        return SnrResult(self.frames, self.roi, scales, self.lattice.pixels, self.lattice.exact, list(self.warnings))


class FrameSnr:
    """:class:`SnrAccumulator` fed whole decoded frames, the ROI checked against the first one (as
    the space-time plots check theirs): a tap for :class:`wallcli.io.video.FrameTee`, so the SNR
    of a clip comes out of a decode that also feeds something else."""

    wants_fps = True  # classify_video tells it the video's frame rate (for the corrections)

    def __init__(self, roi: Roi | None = None, *, max_pixels: int = DEFAULT_MAX_PIXELS, corrections=None,
                 fps: float | None = None):
        self.requested, self.max_pixels = roi, int(max_pixels)
        self.corrections, self.fps = corrections, fps
        self.acc: SnrAccumulator | None = None

    def __call__(self, frame) -> None:
        planes = frame.planes
        if self.acc is None:
            from wallcli.signal.blocks import check_roi

            roi = check_roi(self.requested, planes.width, planes.height)
            self.acc = SnrAccumulator(roi, max_pixels=self.max_pixels, corrections=self.corrections, fps=self.fps)
        self.acc.update(planes)

    def result(self) -> SnrResult:
        if self.acc is None:
            raise WallcliError("no frame was decoded; the noise estimate needs at least 3")
        return self.acc.result()


def snr_report(acc: SnrAccumulator, *, source: str, fps: float, roi_mode: str, notes=()) -> dict:
    """The object of ``wallcli snr --json`` (docs/contract.md) from a fed accumulator.

    One builder for ``wallcli snr`` and ``wallcli scan`` (which feeds the accumulator from the
    decode that also makes the space-time plots), so both report the same fields, the one-line
    ``verdict`` (:func:`~wallcli.snr.verdict.snr_verdict`) included.  ``notes``:
    the reader's warnings, listed before the estimator's own.
    """
    acc.finish()
    if acc.frames < MIN_FRAMES:
        raise WallcliError(f"{source}: only {acc.frames} frame(s) decoded; the noise estimate needs at least "
                           f"{MIN_FRAMES} (it compares consecutive frames over time)")
    res = acc.result()
    top = res.scale(1)
    out = {
        "input": source,
        "column_snr_db": acc.column.db() if getattr(acc, "column", None) is not None else None,
        "roi": list(res.roi),
        "frames": res.frames,
        "channels": list(CHANNELS),
        "signal_power": top.signal_power.tolist(),
        "noise_power": top.noise_power.tolist(),
        "snr_db": top.snr_db.tolist(),
        "scales": [{"block": s.block, "signal_power": s.signal_power.tolist(), "noise_power": s.noise_power.tolist(),
                    "snr_db": s.snr_db.tolist(), "blocks": s.blocks} for s in res.scales],
        "fps": fps,
        "roi_mode": roi_mode,
        "sampled_pixels": res.sampled_pixels,
        "exact": res.exact,
        "warnings": [*notes, *res.warnings],
        "corrections": acc.corrections,
    }
    from wallcli.snr.verdict import snr_verdict

    out["verdict"] = snr_verdict(out)  # here, not in the command: scan's snr object is this one too
    return out
