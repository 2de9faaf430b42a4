"""The windows stage: a plot's or a stream's rows cut into windows, the camera's nuisances taken
out of each, each through the nets; out come, per window, its start, the nets' raw output, its
measured signal (dB) and what the corrections found. Nothing here judges or words an answer.

Windows of ``model.window`` samples at the model's canonical rate (30 fps) every ``stride``
samples, the last one aligned to the end of the clip (``window_starts``).  Each window goes
through ``normalize_window`` (the version the model's card names) exactly as in training.
"""
from __future__ import annotations

import numpy as np

from wallcli.camera import corrections as corr
from wallcli.errors import WallcliError
from wallcli.signal.window import StreamWindower, resample, run_window_starts, window_signal_db

CHUNK = 64  # windows normalised and run at a time, bounding memory on long clips


def too_short(source: str, frames: int, model, fps: float | None = None) -> WallcliError:
    """``frames``: the file's own frames, as decoded (what snr and the report quote), at its own
    rate ``fps`` (None: the model's), not the resampled samples the windows are cut from."""
    fps = float(fps) if fps else float(model.fps)
    return WallcliError(
        f"{source} is too short: {frames} frame(s) decoded ({frames / fps:.2f} s at {fps:g} fps); "
        f"one window needs {model.window} frames at {model.fps:g} fps ({model.window / model.fps:.2f} s)")


def plot_fps(plot, source: str) -> float | None:
    """The frame rate of a space-time plot's video (:func:`wallcli.io.rates.plot_rate`: the one rule
    of count, activity and track), refusing one outside the rates wallcli reads."""
    from wallcli.io.rates import plot_rate

    rate = plot_rate(plot.meta, plot.time, source)
    return None if rate is None else float(rate)


def video_fps(reader) -> float:
    """A video's rate as the frames read so far say it (VideoReader.fps: the timestamps' where they
    contradict the container's), else its container's: what stplot records, and so the one rule of a
    video's answers and its plot's."""
    return float(getattr(reader, "fps", None) or reader.info.fps)


def resampled_plots(model, plot, both: bool = False) -> tuple[dict[str, np.ndarray], np.ndarray]:
    """The plot's inputs for ``model`` at its canonical rate: ({name: (bins, T', 3)}, time (T',));
    ``both``: both plots, whatever the model reads (for the corrections)."""
    if plot.bins != model.bins:
        raise WallcliError(f"the space-time plot has {plot.bins} bins, the model needs {model.bins}",
                           hint=f"recompute it with 'wallcli stplot --bins {model.bins}'")
    out, grid = {}, None
    for name in (("horizontal", "vertical") if both else model.input_names):
        out[name], grid = resample(getattr(plot, name), plot.time, model.fps)
    return out, grid


def corrected(model, wins: dict, offsets: dict, native, options, starts=None, shifts=None):
    """(windows, findings per window): ``wins`` {name: (n, bins, W, 3)} with the whole-frame light
    nuisances of :mod:`wallcli.camera.corrections` divided out (all of a window's parts together),
    and the camera's shake regressed out where ``shifts`` (n, W, 2) were measured."""
    names = list(wins)
    if not options.any:
        return wins, [[] for _ in range(next(iter(wins.values())).shape[0])]
    parts, found = corr.correct_windows([wins[n] for n in names], [offsets[n] for n in names], model.fps,
                                        lines=corr.mains_lines(native, model.fps), options=options, starts=starts,
                                        vertical_index=names.index("vertical") if "vertical" in names else None,
                                        shifts=shifts)
    return dict(zip(names, parts)), found


def plot_windows(model, plot, *, stride: int, source: str, corrections: corr.Options):
    """(starts (s), raw outputs (n, ...), signals (n,) dB, findings per window) of a whole
    space-time plot, ``CHUNK`` windows at a time."""
    rate = plot_fps(plot, source)  # refused as its video would be, whichever command reads it
    plots, grid = resampled_plots(model, plot, both=corrections.light)
    shifts = None
    if corrections.shake and getattr(plot, "shift", None) is not None and plot.frames >= 2:
        # resampled as the profiles are, as the stream's extra row is (RowStream)
        ext = np.zeros((1, plot.frames, 3), np.float32)
        ext[0, :, :2] = plot.shift
        shifts = resample(ext, plot.time, model.fps)[0][0, :, :2].astype(np.float64)
    # the plot is its clip mean removed; that mean is the level offset normalisation v3 needs
    offsets = {"horizontal": np.asarray(plot.h_mean, np.float32), "vertical": np.asarray(plot.v_mean, np.float32)}
    starts = run_window_starts(grid, model.fps, model.window, stride)  # none spans a gap
    if not starts:
        raise too_short(source, getattr(plot, "decoded", plot.frames), model, rate)  # the video's frames, repeats too
    probs, signal, found = [], [], []
    native = rate
    for i in range(0, len(starts), CHUNK):
        chunk = starts[i:i + CHUNK]
        wins = {name: np.stack([p[:, s:s + model.window] for s in chunk]) for name, p in plots.items()}
        wins, f = corrected(model, wins, {n: offsets[n][None] for n in wins}, native, corrections,
                            starts=[grid[s] for s in chunk],
                            shifts=None if shifts is None else np.stack([shifts[s:s + model.window] for s in chunk]))
        found += f
        wins = {name: wins[name] for name in model.input_names}
        probs.append(model.classify(wins, {name: offsets[name][None] for name in wins}))
        signal.append(window_signal_db([(w, offsets[name][None]) for name, w in wins.items()]))
    return [grid[s] for s in starts], np.concatenate(probs), np.concatenate(signal), found


def predict_window(model, win: np.ndarray, ref: np.ndarray, *, start: float = 0.0, native=None,
                   options: corr.Options = corr.Options()) -> tuple[np.ndarray, float, list]:
    """(probabilities, signal dB, corrections found) of one (2*bins, window, 3) window, horizontal
    rows first; ``ref`` (2*bins, 3) is the level the stream's rows are relative to (RowStream.ref).
    A window of 2*bins + 1 rows carries each sample's measured camera shift (dx, dy) in its last
    (:func:`stream_row`)."""
    b = model.bins
    shifts = win[2 * b, :, :2][None].astype(np.float64) if win.shape[0] > 2 * b else None
    parts = {"horizontal": win[:b], "vertical": win[b:2 * b]}
    refs = {"horizontal": ref[None, :b], "vertical": ref[None, b:]}
    # the corrections read both profiles when the stream has them (a light's change is alike along
    # both; rolling-shutter bands run down the vertical one), whatever the model reads
    use = [n for n in ("horizontal", "vertical") if n in model.input_names or (options.any and np.any(parts[n]))]
    wins, found = corrected(model, {n: parts[n][None] for n in use}, refs, native, options, starts=[start],
                            shifts=shifts)
    probs = model.classify({n: wins[n] for n in model.input_names}, refs)[0]
    return probs, float(window_signal_db([(wins[n], refs[n]) for n in model.input_names])[0]), found[0]


def stream_row(row: np.ndarray, rows) -> np.ndarray:
    """A :class:`RowStream` row as the windows keep it: with the stream's measured shift (dx, dy)
    as one more row when it registers its frames, for the corrections' shake regression."""
    if rows.shift is None:
        return row
    return np.concatenate([row, np.array([[rows.shift[0], rows.shift[1], 0.0]], np.float32)])


class WindowStream:
    """The windows of a stream of rows, run through the nets as they complete.

    Rows are :class:`RowStream`'s (horizontal bins first, then vertical), pushed with that stream's
    ``ref`` (the level they are relative to). ``times``, ``probs``, ``signal`` and ``found`` grow by
    one per completed window; :meth:`windows` adds the end-aligned last one.
    """

    def __init__(self, model, stride: int, *, corrections: corr.Options = corr.Options(), native_fps=None):
        self.model, self.stride = model, int(stride)
        # native_fps: the video's own rate, or a callable giving it as the frames read so far say
        # (VideoReader.fps: the timestamps' where they contradict the container's), which is what
        # stplot records and a plot's windows are corrected at: the mains lines are the same on both
        self.corrections, self.native_fps = corrections, native_fps
        self.windower = StreamWindower(model.window, stride, model.fps)
        self.times, self.probs, self.signal, self.found = [], [], [], []
        self.ref = None
        self.last_rows = None  # the rows of the window completed last (valid until the next push)

    def push(self, t: float, row: np.ndarray, ref: np.ndarray) -> None:
        self.ref = ref
        done = self.windower.push(t, row)
        if done is not None:
            self.last_rows = done[2]
            p, db, f = predict_window(self.model, done[2], ref, start=done[0], native=self.native(),
                                      options=self.corrections)
            self.times.append(done[0])
            self.probs.append(p)
            self.signal.append(db)
            self.found.append(f)

    def native(self) -> float | None:
        """The video's own rate now (see ``native_fps``)."""
        n = self.native_fps() if callable(self.native_fps) else self.native_fps
        return float(n) if n else None

    @property
    def empty(self) -> bool:
        """No window so far, nor one at the end: the stream is too short to answer."""
        return not self.times and self.windower.pending() is None

    def windows(self, source: str, frames: int | None = None):
        """(starts, raw outputs (n, ...), signals (n,), findings) of every window, the end-aligned
        last one included; WallcliError when the stream was shorter than one window (quoting
        ``frames``, the video's decoded frames, where given)."""
        model, w = self.model, self.windower
        last = w.pending()
        if self.empty:
            raise too_short(source, w.count if frames is None else frames, model,
                            None if frames is None else self.native())
        times, probs, signal, found = list(self.times), list(self.probs), list(self.signal), list(self.found)
        if last is not None:  # window_starts' end-aligned window: the last `window` rows
            p, db, f = predict_window(model, last[2], self.ref, start=last[0], native=self.native(),
                                      options=self.corrections)
            times.append(last[0])
            probs.append(p)
            signal.append(db)
            found.append(f)
        return times, np.stack(probs), np.asarray(signal), found
