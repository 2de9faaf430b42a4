"""Space-time plots (Sharma et al. 2021): the wall averaged over rows (horizontal plot) or columns
(vertical plot), one line per frame, each pixel's temporal mean removed.

Layout: ``horizontal`` and ``vertical`` are float32 arrays (bins, T, 3) = position x time x RGB,
in 8-bit code values. Horizontal position runs left to right, vertical position top to bottom.
Both plots are exact area means (integer sums) of the same ROI.
Mean removal commutes with spatial averaging (both are linear), so removing the mean from the
small plot equals removing it from every pixel first.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from fractions import Fraction
from typing import Callable

import numpy as np

from wallcli import __version__
from wallcli.signal.blocks import Roi, RgbProjector, check_roi
from wallcli.signal.mean import MODES, remove_mean_in_place

FORMAT = "wallcli.stplot"
FORMAT_VERSION = 1
MIN_FRAMES = 2


@dataclass
class StPlot:
    horizontal: np.ndarray  # (bins, T, 3) float32, mean removed
    vertical: np.ndarray  # (bins, T, 3) float32, mean removed
    time: np.ndarray  # (T,) float64 seconds from the first frame
    h_mean: np.ndarray  # (bins, 3) float32: the clip mean of the raw levels (what was removed, for 'clip')
    v_mean: np.ndarray
    meta: dict = field(default_factory=dict)
    # (T, 2) float32: each frame's measured camera shift (dx, dy) in luma pixels, where the frames were
    # registered (compute_stplot(register=True)): count and activity regress the shake out of the plot with it
    shift: np.ndarray | None = None

    @property
    def frames(self) -> int:
        return int(self.time.shape[0])

    @property
    def decoded(self) -> int:
        """The video's frames as decoded, repeats included (``meta["frames"]``, what every command
        quotes as its frames); :attr:`frames` counts the plot's columns, repeats left out."""
        n = (self.meta or {}).get("frames")
        return n if isinstance(n, int) and not isinstance(n, bool) and n >= self.frames else self.frames

    @property
    def bins(self) -> int:
        return int(self.horizontal.shape[0])


class RowReducer:
    """Per frame: the raw (not mean-removed) horizontal and vertical rows, float64 (bins, 3)."""

    def __init__(self, roi: Roi, bins: int = 64, vertical: bool = True, stabilize: bool = False,
                 register: bool = False):
        self.roi, self.bins = roi, int(bins)
        self._project = RgbProjector(roi, self.bins, vertical, stabilize, register)

    @property
    def shift(self) -> tuple[float, float]:
        """The last frame's measured (dx, dy) in luma pixels ((0, 0) unless registering)."""
        return self._project.shift

    @property
    def shifts(self):
        """What stabilisation found (:class:`wallcli.signal.blocks.ShiftLog`)."""
        return self._project.shifts

    def column_sums(self):
        """The last frame's column sums per plane over the ROI, or None (:meth:`RgbProjector.column_sums`)."""
        return self._project.column_sums()

    def __call__(self, planes) -> tuple[np.ndarray, np.ndarray]:
        return self._project(planes)


class _Growing:
    """An append-only float32 array. It starts at the frame count the container announces (capped)
    and grows by a quarter with ndarray.resize, a realloc: large blocks are remapped, not copied,
    so no second copy of the plot is ever made; :meth:`array` gives the slack back."""

    GROW = 1.25
    MAX_START = 256 << 20  # bytes: a header's frame count is a hint, not a promise

    def __init__(self, shape: tuple[int, ...], dtype=np.float32, expect: int | None = None):
        row = int(np.prod(shape, dtype=np.int64)) * np.dtype(dtype).itemsize or 1
        start = min(int(expect or 0) + 16, max(256, self.MAX_START // row))
        self._a = np.empty((max(256, start), *shape), dtype)
        self.n = 0

    def append(self, row) -> None:
        if self.n == self._a.shape[0]:
            self._a.resize((int(self.n * self.GROW) + 1, *self._a.shape[1:]), refcheck=False)
        self._a[self.n] = row
        self.n += 1

    def array(self) -> np.ndarray:
        self._a.resize((self.n, *self._a.shape[1:]), refcheck=False)
        return self._a


def _finish(h_raw, v_raw, times, meta, mean: str, mean_seconds: float, shift=None) -> StPlot:
    """The plots from the raw (T, bins, 3) float32 rows, which are mean-removed in place and kept
    as (bins, T, 3) views: the plot is never copied (a float64 copy of both made the peak 6x
    the plot, ~9.8 KB a frame)."""
    h_mean = remove_mean_in_place(h_raw, times, mean, mean_seconds)
    v_mean = remove_mean_in_place(v_raw, times, mean, mean_seconds)
    return StPlot(
        horizontal=h_raw.transpose(1, 0, 2),
        vertical=v_raw.transpose(1, 0, 2),
        time=np.asarray(times, np.float64),
        h_mean=h_mean.astype(np.float32),
        v_mean=v_mean.astype(np.float32),
        meta=meta,
        shift=None if shift is None else np.asarray(shift, np.float32),
    )


def channel_std(x: np.ndarray) -> np.ndarray:
    """(bins, T, 3) -> per-colour standard deviation (float64), one bin at a time (np.std would
    hold a full-size temporary)."""
    n = x.shape[0] * x.shape[1]
    s1 = sum(np.sum(b, axis=0, dtype=np.float64) for b in x)
    mean = s1 / max(n, 1)
    s2 = sum(np.sum(np.square(b - mean), axis=0) for b in x)
    return np.sqrt(s2 / max(n, 1))


def compute_stplot(
    reader,
    *,
    roi: Roi | None = None,
    bins: int = 64,
    mean: str = "clip",
    mean_seconds: float = 10.0,
    progress: Callable[[int], None] | None = None,
    register: bool = False,
    view=None,
) -> StPlot:
    """Stream ``reader`` (a :class:`wallcli.io.video.VideoReader`) once into space-time plots.

    ``register``: also measure each frame's camera shift (:attr:`StPlot.shift`), for the shake
    correction of answers read from the plot. ``view``: the :class:`wallcli.view.check.ViewCheck`
    fed the same frames (e.g. through a FrameTee); its record goes into the metadata ("view")."""
    from wallcli.errors import WallcliError

    if mean not in MODES:
        raise ValueError(f"mean must be one of {MODES}")
    info = reader.info
    requested = roi
    frame_size = [info.width, info.height]
    roi = check_roi(requested, info.width, info.height)
    reduce = RowReducer(roi, bins, register=register)
    n = getattr(info, "frame_count", None)
    h_rows, v_rows, times = _Growing((bins, 3), expect=n), _Growing((bins, 3), expect=n), _Growing((), np.float64, n)
    shifts = _Growing((2,), expect=n) if register else None
    for frame in reader.frames():
        if frame.index == 0 and (frame.planes.width, frame.planes.height) != (info.width, info.height):
            # the container's size was wrong or unknown (some streams): the decoded frame decides,
            # and the default ROI is then the whole decoded frame, not the announced one
            frame_size = [frame.planes.width, frame.planes.height]
            roi = check_roi(requested, *frame_size)
            reduce = RowReducer(roi, bins, register=register)
        h, v = reduce(frame.planes)
        if shifts is not None:
            shifts.append(reduce.shift)
        h_rows.append(h)
        v_rows.append(v)
        times.append(frame.time)
        if progress:
            progress(1)
    if times.n < MIN_FRAMES:
        raise WallcliError(f"{info.source} has {times.n} frame(s); a space-time plot needs at least "
                           f"{MIN_FRAMES} (the temporal mean of one frame is the frame itself)")
    # a camera pipeline's reader (wallcli.camera.pipeline) leaves repeats out of the columns: "frames"
    # stays the frames decoded, as snr, scan and the report count them, and what the decode found and
    # took out goes with the plot, so that an answer read from it lists what the video's lists
    decoded = getattr(reader, "decoded", None)
    found = getattr(reader, "corrections", None)
    # the rate the frames' own times run at where they contradict the container's
    fps = float(getattr(reader, "fps", info.fps))
    frac = info.fps if fps == float(info.fps) else Fraction(fps).limit_denominator(1001)
    meta = {
        "format": FORMAT,
        "format_version": FORMAT_VERSION,
        "source": str(info.source),
        "frame_size": frame_size,
        "fps": fps,
        "fps_fraction": f"{frac.numerator}/{frac.denominator}",
        "fps_source": getattr(info, "fps_source", "container") if fps == float(info.fps) else "timestamps",
        # the tick the times are exact to, for the rate check of whoever reads the plot (io.rates.plot_rate)
        "time_base": _ratio(getattr(info, "time_base", None)),
        "frames": int(decoded) if isinstance(decoded, int) and decoded >= times.n else times.n,
        "roi": list(roi),
        "bins": int(bins),
        "mean": mean,
        "mean_seconds": float(mean_seconds) if mean != "clip" else None,
        "units": "8-bit code values (0-255 scale), mean removed",
        "layout": "position x time x channel; horizontal: left->right, vertical: top->bottom",
        "channels": ["r", "g", "b"],
        "wallcli_version": __version__,
        "warnings": list(getattr(reader, "warnings", [])),
    }
    if callable(found):
        meta["corrections"] = [dict(c) for c in found()]
    if view is not None:
        meta["view"] = view.record()
    return _finish(h_rows.array(), v_rows.array(), times.array(), meta, mean, mean_seconds,
                   None if shifts is None else shifts.array())


def _ratio(value) -> str | None:
    return None if not value else f"{Fraction(value).numerator}/{Fraction(value).denominator}"


def to_arrays(plot: StPlot) -> tuple[dict[str, np.ndarray], dict]:
    """The ``.npz`` payload of a plot: ``save_npz(path, *to_arrays(plot))``."""
    arrays = {"horizontal": plot.horizontal, "vertical": plot.vertical, "time": plot.time,
              "h_mean": plot.h_mean, "v_mean": plot.v_mean}
    if plot.shift is not None:
        arrays["shift"] = plot.shift
    return arrays, plot.meta


_ARRAYS = ("horizontal", "vertical", "time", "h_mean", "v_mean", "shift")


def from_arrays(arrays: dict[str, np.ndarray], meta: dict, source: str = "file") -> StPlot:
    """Validate a loaded ``.npz`` payload: ``from_arrays(*load_npz(path, kind=FORMAT))``."""
    from wallcli.errors import WallcliError

    missing = [k for k in ("horizontal", "vertical", "time") if k not in arrays]
    if missing:
        raise WallcliError(f"{source} is not a complete space-time plot (missing {missing[0]!r})")
    odd = [k for k, a in arrays.items() if k in _ARRAYS and np.asarray(a).dtype.kind not in "biuf"]
    if odd:  # strings, complex, structured: not a plot, and a cast would fail or lose data
        raise WallcliError(f"{source}: array {odd[0]!r} is not real numbers ({np.asarray(arrays[odd[0]]).dtype})")
    with np.errstate(over="ignore"):  # a float64 beyond float32's range becomes inf, refused below
        h = np.asarray(arrays["horizontal"], np.float32)
        v = np.asarray(arrays["vertical"], np.float32)
        t = np.asarray(arrays["time"], np.float64)
    if h.ndim != 3 or v.ndim != 3 or h.shape[2] != 3 or v.shape[1:] != h.shape[1:] or t.shape != (h.shape[1],) \
            or min(h.shape[0], v.shape[0]) < 1:
        raise WallcliError(f"{source} has inconsistent space-time plot shapes "
                           f"(horizontal {h.shape}, vertical {v.shape}, time {t.shape})")
    with np.errstate(over="ignore"):
        hm = np.asarray(arrays.get("h_mean", np.zeros((h.shape[0], 3))), np.float32)
        vm = np.asarray(arrays.get("v_mean", np.zeros((v.shape[0], 3))), np.float32)
    if hm.shape != (h.shape[0], 3) or vm.shape != (v.shape[0], 3):
        raise WallcliError(f"{source} has clip means of the wrong shape (h_mean {hm.shape}, v_mean {vm.shape})")
    if not all(np.all(np.isfinite(x)) for x in (h, v, t, hm, vm)):
        raise WallcliError(f"{source} contains non-finite values")
    if t.size > 1 and np.any(np.diff(t) <= 0):
        raise WallcliError(f"{source} has timestamps that do not increase")
    shift = None
    if "shift" in arrays:
        with np.errstate(over="ignore"):
            shift = np.asarray(arrays["shift"], np.float32)
        if shift.shape != (t.size, 2) or not np.all(np.isfinite(shift)):
            raise WallcliError(f"{source} has a malformed 'shift' array (shape {shift.shape}, needs ({t.size}, 2))")
    found = meta.get("corrections")
    if found is not None and not (isinstance(found, list) and all(isinstance(c, dict) and isinstance(c.get("kind"), str)
                                                                   for c in found)):
        raise WallcliError(f"{source} has a malformed corrections list in its metadata")
    view = meta.get("view")
    if view is not None and not (isinstance(view, dict) and isinstance(view.get("spans"), dict)):
        raise WallcliError(f"{source} has a malformed view record in its metadata")
    roi = meta.get("roi")
    if roi is not None and not (isinstance(roi, list) and len(roi) == 4
                                and all(isinstance(x, int) and not isinstance(x, bool) for x in roi)):
        raise WallcliError(f"{source} has a malformed roi in its metadata ({roi!r:.60})")
    return StPlot(h, v, t, hm, vm, dict(meta), shift)
