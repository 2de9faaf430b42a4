"""Whole-frame light nuisances found and removed before analysis: aliased mains flicker (whole-frame
and rolling-shutter bands) and auto-exposure steps and slow drift.

Works on the raw per-frame profiles of the ROI (the space-time plots' rows, or any per-frame
profile such as the SNR estimator's row means), never on pixels, one stretch of frames at a time
(a 256-sample window of the classifiers, or a block of the SNR estimator's frames): memory is
bounded and ``--follow`` still works.

What a nuisance is, and what a person is. A person changes the wall by 0.1-1 % unevenly along
it and not periodically. The nuisances here are whole-frame and multiplicative, and each has a
shape a person does not make:

- **flicker**: lamps on mains power flicker at twice the mains frequency (100 or 120 Hz); a
  camera samples that at its frame rate, so the video carries a *narrow line* at the alias
  frequency |2 f_mains - k fps| (10 Hz for 50 Hz mains at 30 fps, 5 Hz at 25 fps with 60 Hz
  mains). Only those predicted frequencies (within ``SEARCH_HZ``) are searched, and a line is
  removed only when its power summed over the bins stands ``LINE_RATIO`` times above its
  neighbourhood of the spectrum. Each bin's own sinusoid at that frequency is removed, so the
  rolling-shutter form (bands whose phase advances down the frame, the vertical bins' phases
  differing) goes as completely as the whole-frame one; a person loses one frequency bin out of
  128 at most.
- **exposure**: steps and slow drift of the whole frame's gain, found in
  :mod:`wallcli.camera.exposure`.

``correct`` divides the found gains out and returns what was found; ``merge`` sums a clip's
findings into the JSON ``corrections`` list (``{"kind": "flicker", "hz", "amplitude", ...}``,
``{"kind": "exposure", "steps": [{"time", "size"}...]}``, ``{"kind": "drift", "amplitude"}``; a
step cut by a window's end, taken as a ramp there, ``"partial": True``; ``white_balance``: :mod:`~.whitebalance`).
Camera shake (``kind: "shake"``) is regressed out first, where the stream measured each frame's
shift (:mod:`wallcli.camera.shake`, in :func:`correct_windows`).
"""
from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np

from wallcli.camera.exposure import _steps_and_drift, solve
from wallcli.camera.whitebalance import balance, merge as merge_white_balance

MAINS_HZ = (50.0, 60.0)
MIN_LINE_HZ = 0.5  # slower aliases are drift's business
SEARCH_HZ = 0.3  # mains and camera clocks wander: search this far around each predicted alias
LINE_RATIO = 25.0  # line power over the median of its +-3 Hz neighbourhood
MIN_SAMPLES = 64  # shorter stretches are left alone


@dataclass(frozen=True)
class Options:
    deflicker: bool = True
    exposure: bool = True
    shake: bool = True  # regression on the measured shifts (shake.py), where a stream measured them

    @property
    def any(self) -> bool:
        return self.deflicker or self.exposure or self.shake

    @property
    def light(self) -> bool:
        return self.deflicker or self.exposure


OFF = Options(False, False, False)


def fold(f: float, rate: float) -> float:
    """The frequency a sinusoid of ``f`` Hz shows when sampled at ``rate`` Hz (in [0, rate/2])."""
    x = float(f) % float(rate)
    return min(x, rate - x)


def mains_lines(native_fps: float | None, rate: float) -> list[float]:
    """Where aliased mains flicker can show in a series at ``rate`` made from video at
    ``native_fps`` (twice the mains frequency, folded by the camera, then by any resampling)."""
    fps = float(native_fps) if native_fps and native_fps > 0 else float(rate)
    out = []
    for mains in MAINS_HZ:
        f = fold(fold(2 * mains, fps), rate)
        if f >= MIN_LINE_HZ and f < rate / 2 - SEARCH_HZ and all(abs(f - g) > 2 * SEARCH_HZ for g in out):
            out.append(f)
    return out


# ------------------------------------------------------------------------------------ flicker
def _find_line(rel: np.ndarray, rate: float, lines) -> tuple[float, float] | None:
    """(frequency, line ratio) of the strongest aliased mains line in ``rel`` (T, K) (relative
    changes, K series), or None."""
    t = rel.shape[0]
    pad = 8 * t
    win = np.hanning(t)[:, None]
    spec = np.abs(np.fft.rfft((rel - rel.mean(axis=0)) * win, n=pad, axis=0)) ** 2
    power = spec.sum(axis=1)
    freqs = np.fft.rfftfreq(pad, 1.0 / rate)
    best = None
    for f0 in lines:
        near = np.abs(freqs - f0) <= SEARCH_HZ
        around = (np.abs(freqs - f0) <= 3.0) & ~(np.abs(freqs - f0) <= SEARCH_HZ + 4.0 * rate / t) & (freqs >= MIN_LINE_HZ)
        if not near.any() or around.sum() < 8:
            continue
        i = int(np.flatnonzero(near)[np.argmax(power[near])])
        ratio = float(power[i] / max(np.median(power[around]), 1e-300))
        if ratio < LINE_RATIO:
            continue
        f = freqs[i]
        if 0 < i < len(power) - 1:  # parabolic interpolation of the log peak
            a, b, c = np.log(power[i - 1:i + 2] + 1e-300)
            den = a - 2 * b + c
            if den < 0:
                f += 0.5 * (a - c) / den * (freqs[1] - freqs[0])
        if best is None or ratio > best[1]:
            best = (float(f), ratio)
    return best


def _sinusoids(rel: np.ndarray, f: float, rate: float) -> tuple[np.ndarray, np.ndarray]:
    """Least-squares (cos, sin) amplitudes of ``f`` in each column of ``rel`` (T, K), fitted with a
    constant and a slope beside them; returns (basis (T, 2), coefficients (2, K))."""
    t = np.arange(rel.shape[0]) / rate
    ph = 2 * np.pi * f * t
    tt = (t - t.mean()) / max(t.std(), 1e-9)
    design = np.stack([np.cos(ph), np.sin(ph), np.ones_like(t), tt], axis=1)
    coef = solve(design, rel)
    return design[:, :2], coef[:2]


# ------------------------------------------------------------------------------------ the fit
@dataclass
class Fit:
    """Relative gains found on one stretch: multiply the raw levels by 1 / (1 + gain)."""

    gain: np.ndarray  # (T, K) per sample and series
    findings: list[dict[str, Any]]


def fit(levels: np.ndarray, rate: float, *, lines=(), options: Options = Options(), t0: float = 0.0,
        vertical: slice | None = None, part=None) -> Fit | None:
    """The nuisances of a stretch of raw levels (T, K) (K series: profile bins, colours summed or
    not; all positive levels of the same frames) sampled at ``rate``. ``lines``: the frequencies
    where aliased mains flicker may show (:func:`mains_lines`). ``vertical``: which series are
    the vertical profile (in order down the frame), for telling rolling-shutter bands; ``part``
    (K,) which profile each series belongs to (a change of the light is alike along each).
    None when nothing was found."""
    levels = np.asarray(levels, np.float64)
    t = levels.shape[0]
    if t < MIN_SAMPLES or not options.light:
        return None
    mean = levels.mean(axis=0)
    ok = mean > 1e-6 * max(float(np.abs(mean).max()), 1e-12)
    if not ok.any():
        return None
    rel = np.zeros_like(levels)
    rel[:, ok] = levels[:, ok] / mean[ok] - 1.0
    gain = np.zeros_like(rel)
    findings = []
    if options.deflicker and lines:
        line = _find_line(rel[:, ok], rate, lines)
        if line is not None:
            f, ratio = line
            basis, coef = _sinusoids(rel, f, rate)
            wave = basis @ coef
            wave[:, ~ok] = 0.0
            gain += wave
            rel = (1.0 + rel) / (1.0 + wave) - 1.0
            amp = np.hypot(coef[0], coef[1])[ok]
            found = {"kind": "flicker", "hz": round(float(f), 3), "amplitude": float(np.median(amp)),
                     "line_ratio": float(ratio)}
            if vertical is not None:
                v = np.arange(levels.shape[1])[vertical]
                v = v[ok[v]]
                if v.size >= 4:
                    ph = np.unwrap(np.arctan2(coef[1, v], coef[0, v]))
                    turn = float(abs(ph[-1] - ph[0]) / (2 * np.pi))
                    found["rolling_shutter"] = turn >= 0.25
                    found["bands"] = round(turn, 2)  # cycles of the bands over the profile's height
            findings.append(found)
    if options.exposure:
        # in logarithms the light's gains add (two steps of 2 % are 2 % each, whatever came before),
        # so the steps and the drift are fitted and sized alike wherever they fall in the stretch
        lrel = np.log(np.maximum(1.0 + rel[:, ok], 1e-9))
        lrel -= lrel.mean(axis=0)
        model, steps, drift = _steps_and_drift(lrel, rate, None if part is None else np.asarray(part)[ok])
        model = model - np.mean(model)
        if steps or drift:
            gain = (1.0 + gain) * np.exp(model)[:, None] - 1.0
            if steps:
                findings.append({"kind": "exposure", "steps": [
                    {"time": round(t0 + st[0] / rate, 3), "size": round(float(np.expm1(st[1])), 5)}
                    | ({"partial": True} if len(st) > 2 else {}) for st in steps]})
            if drift:
                findings.append({"kind": "drift", "amplitude": round(float(np.expm1(drift / 2)), 5)})
    if not findings:
        return None
    return Fit(gain, findings)


# ------------------------------------------------------------------------------------ windows
def correct_windows(parts: list[np.ndarray], offsets: list[np.ndarray], rate: float, *, lines=(),
                    options: Options = Options(), starts=None, vertical_index: int | None = None,
                    shifts: np.ndarray | None = None):
    """Correct plot windows in place of the classifiers' path.

    ``parts``: [(n, bins, T, 3) windows relative to ``offsets`` [(n or 1, bins, 3)]] (e.g.
    horizontal and vertical); all parts of a window are fitted together (a part that is all zero,
    such as a vertical plot not computed, is left out). ``shifts``: (n, T, 2) each sample's
    measured camera shift, when the stream registered its frames: the shake is regressed out
    first (:mod:`wallcli.camera.shake`), then the light's nuisances are fitted on what is left.
    Returns (corrected parts (float32), [findings per window]).
    """
    n = parts[0].shape[0]
    out = [np.array(p, np.float32, copy=True) for p in parts]
    found = [[] for _ in range(n)]
    if not options.any:
        return out, found
    for w in range(n):
        raws, used = [], []
        for k, (p, off) in enumerate(zip(parts, offsets)):
            x = p[w].astype(np.float64)
            if not np.any(x):
                continue
            o = np.asarray(off, np.float64)
            raw = x + o[min(w, o.shape[0] - 1)][:, None, :]  # (bins, T, 3)
            raws.append(raw)
            used.append(k)
        if not raws:
            continue
        shaken = None
        if options.shake and shifts is not None:
            shaken = _unshake(raws, shifts[w])
            if shaken is not None:
                found[w].append(shaken)
        part = np.concatenate([np.full(r.shape[0], i) for i, r in enumerate(raws)])  # what differs between
        # the colours first (white balance, divided out of raws), then the grey gain on what is left
        balanced = balance(raws, rate, part) if options.exposure and raws[0].shape[1] >= MIN_SAMPLES else None
        found[w] += [balanced] if balanced is not None else []
        # colours summed: the nuisances are grey; (T, K) with K the bins of every part used
        series = np.concatenate([(r[..., 0] + r[..., 1] + r[..., 2]).T for r in raws], axis=1)  # as sum(-1), 10x faster
        vs = None
        if vertical_index is not None and vertical_index in used:
            start = sum(raws[i].shape[0] for i in range(used.index(vertical_index)))
            vs = slice(start, start + raws[used.index(vertical_index)].shape[0])
        t0 = 0.0 if starts is None else float(starts[w])
        res = fit(series, rate, lines=lines, options=options, t0=t0, vertical=vs, part=part)
        if res is None and shaken is None and balanced is None:
            continue
        pos = 0
        for k, raw in zip(used, raws):
            b = raw.shape[0]
            g = 0.0 if res is None else res.gain[:, pos:pos + b].T[:, :, None]  # (bins, T, 1)
            pos += b
            o = np.asarray(offsets[k], np.float64)[min(w, np.asarray(offsets[k]).shape[0] - 1)][:, None, :]
            out[k][w] = (raw / (1.0 + g) - o).astype(np.float32)
        if res is not None:
            found[w] += res.findings
    return out, found


def _unshake(raws: list[np.ndarray], shifts: np.ndarray) -> dict[str, Any] | None:
    """Regress the shake out of one window's parts [(bins, T, 3)], in place, all together (one
    camera moved them all); the finding, or None when the shifts explain nothing."""
    from wallcli.camera.shake import unshake

    t = raws[0].shape[1]
    series = np.concatenate([r.transpose(1, 0, 2).reshape(t, -1) for r in raws], axis=1)
    fixed, finding = unshake(series, shifts)
    if finding is None:
        return None
    pos = 0
    for r in raws:
        n = r.shape[0] * r.shape[2]
        r[...] = fixed[:, pos:pos + n].reshape(t, r.shape[0], r.shape[2]).transpose(1, 0, 2)
        pos += n
    return finding


def merge(per_window: list[list[dict]]) -> list[dict[str, Any]]:
    """A clip's ``corrections``: what its windows (or blocks) found, one entry per kind.

    flicker: the median frequency and amplitude over the windows where it was found, and in how
    many; exposure: every step once (windows overlap: steps within 1 s are one); drift: the
    largest amplitude."""
    flick = [f for fs in per_window for f in fs if f["kind"] == "flicker"]
    out: list[dict[str, Any]] = []
    if flick:
        e = {"kind": "flicker", "hz": round(float(np.median([f["hz"] for f in flick])), 3),
             "amplitude": round(float(np.median([f["amplitude"] for f in flick])), 6),
             "windows": len(flick)}
        rs = [f["rolling_shutter"] for f in flick if "rolling_shutter" in f]
        if rs:
            e["rolling_shutter"] = sum(rs) * 2 > len(rs)
            e["bands"] = round(float(np.median([f["bands"] for f in flick if "bands" in f])), 2)
        out.append(e)
    steps = sorted((s for fs in per_window for f in fs if f["kind"] == "exposure" for s in f["steps"]),
                   key=lambda s: s["time"])
    if steps:
        kept: list[list[dict]] = []
        for s in steps:
            if kept and s["time"] - kept[-1][-1]["time"] < 1.0:
                kept[-1].append(s)
            else:
                kept.append([s])
        # a step seen whole in one window and cut by another's end is sized from the whole one
        kept = [[s for s in g if not s.get("partial")] or g for g in kept]
        out.append({"kind": "exposure", "steps": [
            {"time": round(float(np.median([s["time"] for s in g])), 3),
             "size": round(float(np.median([s["size"] for s in g])), 5)}
            | ({"partial": True} if all(s.get("partial") for s in g) else {}) for g in kept]})
    drift = [f["amplitude"] for fs in per_window for f in fs if f["kind"] == "drift"]
    if drift:
        out.append({"kind": "drift", "amplitude": round(float(max(drift)), 5), "windows": len(drift)})
    out += merge_white_balance(per_window)
    shake = [f for fs in per_window for f in fs if f["kind"] == "shake"]
    if shake:
        out.append({"kind": "shake", "rms_px": round(float(np.median([f["rms_px"] for f in shake])), 3),
                    "max_px": round(float(max(f["max_px"] for f in shake)), 3),
                    "explained": round(float(np.median([f["explained"] for f in shake])), 4),
                    "windows": len(shake)})
    return out


# ------------------------------------------------------------------------------------ streams
class LaggedGains:
    """:func:`fit` in a bounded running form, for consumers of whole frames (the SNR estimator):
    push one profile (K,) per frame; get back (frame index, gain (K,)) for earlier frames.

    Every ``hop`` frames the last ``window`` profiles are fitted and the gains of their middle
    part are final (the first fit's also from frame 0, :meth:`flush` the rest), so each frame's
    gain comes from a fit that saw ``(window - hop) / 2`` frames on either side of it; the lag
    is under ``window`` frames (``hop + (window - hop) / 2`` after the first fit), the memory
    ``window`` profiles.
    """

    def __init__(self, rate: float, *, lines=(), options: Options = Options(), window: int = 256,
                 hop: int = 64, vertical: slice | None = None):
        from collections import deque

        self.rate, self.lines, self.options = float(rate), list(lines), options
        self.window, self.hop, self.vertical = int(window), int(hop), vertical
        self.margin = (self.window - self.hop) // 2
        self._buf: deque = deque(maxlen=self.window)
        self.count = 0  # frames pushed
        self.done = 0  # frames whose gain was handed out
        self.found: list[list[dict]] = []
        self._flushed = False
        self._prev: tuple[int, np.ndarray] | None = None  # the last fit: (first frame, gains)

    def _fit(self, upto: int) -> list[tuple[int, np.ndarray]]:
        levels = np.stack(self._buf)
        first = self.count - levels.shape[0]
        part = None
        if self.vertical is not None:
            part = np.ones(levels.shape[1], int)
            part[self.vertical] = 0
        res = fit(levels, self.rate, lines=self.lines, options=self.options, t0=first / self.rate,
                  vertical=self.vertical, part=part)
        if res is not None:
            self.found.append(res.findings)
        gains = res.gain if res is not None else np.zeros_like(levels)
        # each fit's gains are relative to its own stretch's mean level; carry the previous fit's
        # level over their overlap, or a step would reappear at every hop (its size times the
        # change of the stretch's mean)
        if self._prev is not None:
            p0, prev = self._prev
            lo, hi = max(first, p0), min(first + len(gains), p0 + len(prev))
            if hi > lo:
                factor = float(np.median((1.0 + prev[lo - p0:hi - p0]) / (1.0 + gains[lo - first:hi - first])))
                gains = (1.0 + gains) * factor - 1.0
        self._prev = (first, gains)
        out = [(i, gains[i - first]) for i in range(self.done, upto)]
        self.done = upto
        return out

    def push(self, profile: np.ndarray) -> list[tuple[int, np.ndarray]]:
        self._buf.append(np.asarray(profile, np.float64))
        self.count += 1
        if self.count >= self.window and (self.count - self.window) % self.hop == 0:
            return self._fit(self.count - self.margin)
        return []

    def flush(self) -> list[tuple[int, np.ndarray]]:
        """The gains of every frame not handed out yet (once)."""
        if self._flushed or self.done >= self.count:
            self._flushed = True
            return []
        self._flushed = True
        if self.count < MIN_SAMPLES:
            out = [(i, np.zeros(len(self._buf[0]))) for i in range(self.done, self.count)]
            self.done = self.count
            return out
        return self._fit(self.count)

    def corrections(self) -> list[dict[str, Any]]:
        return merge(self.found)


def bands(n: int, most: int = 64) -> np.ndarray:
    """For ``n`` consecutive lines, the band (0..) each falls in, at most ``most`` bands."""
    k = min(n, most)
    return (np.arange(n) * k) // max(n, 1)
