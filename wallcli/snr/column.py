"""The headline figure, ``column_snr_db``: how far a person's light stands above the camera's noise
in one column of the wall (the unit a space-time plot is made of), in dB.

It is measured to mean what the labels' ``snr_db`` of the rendered recordings means (their
generator's definition: the clean column profile's change over time, squared, over the noise of
one column's mean in one frame), so that the README's bands read the same on a label and on an
output: under 0 dB a person is under the noise, from 10 dB up plain in the plot.

Measured on the luma of every column of the region, per chunk of CHUNK frames, with each
column's mean over the chunk removed, in spatial components along the wall (a DCT across the
columns) at each temporal frequency:
- signal = the power of the broad components (wavelengths over 2 x BROAD_PX pixels: a person's
  shade, not a codec's 16-pixel blocks) above the noise's level at that frequency, less the whole
  wall's common change (component 0: a light's flicker or drift, which an empty room shows too);
- noise = the fine components' power: one column's noise, including what a codec holds for
  frames (its level at a person's slow frequencies, which the frame-to-frame figure misses).
The chunks' powers are summed, so a clip's figure weighs every frame alike and memory stays flat.

CALIBRATION_DB: the labels measure the person's change in linear light, before the camera's tone
curve (which compresses it: about 6.8 dB at a gamma of 2.2), with all of the profile's change
(the broad components here keep most of it), against a noise from each pixel's own; this figure
reads the decoded codes. The constant is the median difference on the 191 rendered recordings
with people (16.1 dB); research/snr/README.md gives the agreement.
"""
from __future__ import annotations

import functools

import numpy as np

CHUNK = 256  # frames (8.5 s at 30 fps, a model window)
MAX_COLUMNS = 512  # wider regions are measured in groups of columns
BROAD_PX = 16.0  # a person's shade: components of wavelengths over 2 x 16 px (a codec's block: 16)
CALIBRATION_DB = 16.0
FLOOR_DB = -30.0
_MEDIAN_CHI2_2 = np.log(2.0)  # a periodogram bin's median over its mean, for white noise
NAME = "column SNR"  # what every terminal calls it


def _luma(planes, roi, lines=None) -> np.ndarray:
    """The region's column means of one frame (float64, one per column): exact integer sums.
    ``lines``: the region's column sums of each plane where the caller made them already (the
    projection's, :meth:`wallcli.signal.blocks.RgbProjector.column_sums`): the same integers."""
    x, y, w, h = roi
    kind = planes.y.dtype
    acc = (np.float64 if not np.issubdtype(kind, np.integer) else
           np.uint64 if h * int(np.iinfo(kind).max) >= 2 ** 32 else np.uint32)
    if lines is not None:
        def column(i, _):
            return lines[i].astype(np.float64)
    else:
        def column(_, p):
            return _column_sums(p[y:y + h, x:x + w], acc)
    if getattr(planes, "kind", "yuv") == "rgb":  # y, u, v hold R, G, B
        sums = sum(column(i, p) for i, p in enumerate((planes.y, planes.u, planes.v))) / 3.0
    else:
        sums = column(0, planes.y)
    return sums / h


def _column_sums(region: np.ndarray, acc) -> np.ndarray:
    # OpenCV's reduce sums 8-bit codes into exact int32 in C, a sixth of numpy's time on a 1080p
    # plane (0.05 against 0.31 ms): the same integers, so the same figure (it has no exact 16-bit path)
    if region.dtype == np.uint8 and region.shape[0] * 255 < 2 ** 31:
        import cv2

        return cv2.reduce(region, 0, cv2.REDUCE_SUM, dtype=cv2.CV_32S)[0].astype(np.float64)
    return np.sum(region, axis=0, dtype=acc).astype(np.float64)


def chunk_powers(cols: np.ndarray, fps: float, px_per_column: float = 1.0) -> tuple[float, float, int]:
    """(signal power, noise power, samples) of a (T, columns) chunk of column means; powers are
    summed over the chunk's samples (divide by the samples for a mean). ``px_per_column``: pixels
    each column stands for (a plot's bins average several)."""
    T, W = cols.shape
    if T < 8 or W < 4:
        return 0.0, 0.0, 0
    g = cols - cols.mean(axis=0, keepdims=True)
    z = _components(g)  # the spatial components but the mean (the whole wall's common change)
    taper = np.hanning(T)
    power = np.abs(np.fft.rfft(z * taper[:, None], axis=0)) ** 2 / np.sum(taper * taper)  # (F, W - 1)
    k = int(min(max(3, round(W * px_per_column / BROAD_PX)), W - 3))
    # the noise's level at each frequency, read where a broad shade is not (the fine components:
    # a codec's held noise is slow, and would pass for a person against a fast-noise level)
    level = np.median(power[:, k:], axis=1) / _MEDIAN_CHI2_2
    signal = float(np.sum(np.mean(power[:, :k] - level[:, None], axis=0))) / W
    noise = float(np.mean(power[:, k:]))  # one column's noise power (orthonormal components)
    return signal * T, noise * T, T


def _components(g: np.ndarray) -> np.ndarray:
    """The orthonormal DCT-II of each row of ``g`` (T, W) but component 0, (T, W - 1)."""
    W = g.shape[1]
    if W % 2:  # OpenCV's transform takes even lengths only
        return g @ _dct(W)[1:].T
    import cv2

    from wallcli.signal.blocks import one_opencv_thread

    # a fast transform, the matrix product's components to 1e-13: the product of a 256-frame
    # chunk of 480 columns cost 5-20 ms (0.02-0.08 ms a frame), the transform 0.4 ms
    with one_opencv_thread():
        return cv2.dct(np.ascontiguousarray(g, np.float64), flags=cv2.DCT_ROWS)[:, 1:]


@functools.lru_cache(maxsize=4)
def _dct(n: int) -> np.ndarray:
    k = np.arange(n)[:, None]
    b = np.cos(np.pi * (np.arange(n)[None] + 0.5) * k / n)
    return b / np.linalg.norm(b, axis=1, keepdims=True)


def to_db(signal: float, noise: float) -> float | None:
    """The figure from summed powers: None when nothing was measured."""
    if noise <= 0:
        return None
    ratio = max(signal / noise, 1e-30)
    return round(max(10.0 * np.log10(ratio) + CALIBRATION_DB, FLOOR_DB), 2)


class ColumnSnr:
    """A frame tap (:class:`wallcli.io.video.FrameTee`): feed decoded frames, read :meth:`db`."""

    wants_fps = True  # classify_video tells it the video's frame rate

    def __init__(self, roi=None, fps: float | None = None):
        self.requested, self.fps = roi, fps
        self.roi = None
        self._rows: list[np.ndarray] = []
        self.signal = self.noise = 0.0
        self.samples = 0

    def __call__(self, frame) -> None:
        self.push(frame.planes)

    def push(self, planes, lines=None) -> None:
        """One frame; ``lines``: its region's column sums per plane where the caller has them (see
        :func:`_luma`), so that a decode does not sum the same frame twice."""
        if self.roi is None:
            from wallcli.errors import WallcliError
            from wallcli.signal.blocks import check_roi

            try:
                self.roi = check_roi(self.requested, planes.width, planes.height)
            except WallcliError:
                # a frame under one chroma sample each way (1x1000): the command's own checks
                # answer for it; the headline figure is then not measured, never an error
                self.roi = False
        if self.roi is False:
            return
        self._rows.append(_luma(planes, self.roi, lines))
        if len(self._rows) >= CHUNK:
            self._flush()

    def _flush(self) -> None:
        if self._rows:
            cols = np.stack(self._rows)
            # a wide frame in groups of columns (a DCT of 3840 columns is 118 MB), each group's
            # noise scaled back to one column's as for a plot's bins
            group = -(-cols.shape[1] // MAX_COLUMNS)
            if group > 1:
                n = cols.shape[1] // group
                cols = cols[:, :n * group].reshape(len(cols), n, group).mean(axis=2)
            s, n, t = chunk_powers(cols, float(self.fps or 30.0), float(group))
            n *= group
            self.signal, self.noise, self.samples = self.signal + s, self.noise + n, self.samples + t
        self._rows = []

    def db(self) -> float | None:
        # a short tail joins the figure if it holds 8 frames or more (chunk_powers)
        self._flush()
        return to_db(self.signal, self.noise)


def plot_column_snr_db(plot) -> float | None:
    """The figure from a space-time plot (a .npz): its horizontal bins stand for columns, their
    noise scaled up by the columns each bin averages (``meta['roi']``), as independent noise is."""
    t = np.asarray(plot.time, np.float64)
    fps = (len(t) - 1) / (t[-1] - t[0]) if len(t) > 1 and t[-1] > t[0] else 30.0
    roi = (plot.meta or {}).get("roi")
    return bins_column_snr_db(plot.horizontal, fps, float(roi[2]) if roi else None)


def bins_column_snr_db(horizontal, fps: float, roi_width: float | None) -> float | None:
    """The figure from horizontal plot bins (bins, T, channels), each bin averaging ``roi_width`` /
    bins columns: a whole plot's, or one window's (count --follow's lines)."""
    h = np.asarray(horizontal, np.float64).mean(axis=-1).T  # (T, bins)
    signal = noise = 0.0
    per_bin = max(float(roi_width) / h.shape[1], 1.0) if roi_width else 1.0
    for i in range(0, h.shape[0], CHUNK):
        s, n, _ = chunk_powers(h[i:i + CHUNK], fps, per_bin)
        signal, noise = signal + s, noise + n
    return to_db(signal, noise * per_bin)


def column_text(db) -> str:
    """The headline as a terminal prints it first, naming its figure and band."""
    from wallcli.wording import format_db

    if db is None:
        return f"{NAME}: not measured"
    band = ("under the noise" if db < 0 else "faint in the plot" if db < 10 else "plain in the plot")
    return f"{NAME} {format_db(db)} dB (labels' scale): {band}"
