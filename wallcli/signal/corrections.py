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
- **exposure**: the whole frame's gain, robustly (the median over the bins of each bin's
  relative change, so that a shadow over part of the wall does not move it): steps (jumps of at
  least ``STEP_MIN`` and ``STEP_SIGMA`` times the gain's frame noise, within ``RAMP_S`` seconds:
  beyond what a hidden person does to the whole wall in a few frames) and drift (a cubic over
  the stretch, slower than about one cycle in 8 s; removed only when it exceeds ``DRIFT_MIN``
  peak to peak).

``correct`` divides the found gains out and returns what was found; ``merge`` sums a clip's
findings into the JSON ``corrections`` list (``{"kind": "flicker", "hz", "amplitude", ...}``,
``{"kind": "exposure", "steps": [{"time", "size"}...]}``, ``{"kind": "drift", "amplitude"}``; a
step that a window's end cut wherever it was seen, taken as a ramp there, carries ``"partial": True``).
Camera shake (``kind: "shake"``) is regressed out first, where the stream measured each frame's
shift (:mod:`wallcli.signal.shake`, in :func:`correct_windows`).
"""
from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np

MAINS_HZ = (50.0, 60.0)
MIN_LINE_HZ = 0.5  # slower aliases are drift's business
SEARCH_HZ = 0.3  # mains and camera clocks wander: search this far around each predicted alias
LINE_RATIO = 25.0  # line power over the median of its +-3 Hz neighbourhood
STEP_MIN = 0.003  # relative size of the smallest exposure step removed
STEP_SIGMA = 10.0  # and in units of the gain's frame-to-frame noise
RAMP_S = 0.33  # seconds an exposure step may take
SPAN_S = 0.5  # seconds averaged on each side of a step
EDGE_S = 0.17  # or as little as this where the window ends or another step begins
MAX_STEPS = 4
DRIFT_DEGREE = 3
DRIFT_MIN = 0.002  # relative peak-to-peak of the slow gain change removed
DRIFT_AGREE = True  # drift only where most bins drifted alike
MIN_SAMPLES = 64  # shorter stretches are left alone
UNEVEN = 0.2  # a bin's change within this fraction of the common one (plus its noise) is alike
UNEVEN_DRIFT = 0.4  # the same for drift: a passing shadow bends a bin's slow curve (a cubic) a little
AGREE = 0.7  # fraction of the bins (mean over the profiles) that must change alike for a step or drift
AGREE_EACH = 0.5  # and in each profile
AGREE_GROUPS = 8  # the fewest groups of neighbouring bins a profile is judged on


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


def _solve(design: np.ndarray, y: np.ndarray) -> np.ndarray:
    """Least squares for a few columns and many right-hand sides: the pseudo-inverse of the small
    design once, then one product (numpy's lstsq of 128 series took 50 ms a window)."""
    return np.linalg.pinv(design) @ y


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
    coef = _solve(design, rel)
    return design[:, :2], coef[:2]


# ------------------------------------------------------------------------------------ exposure
def _robust_gain(rel: np.ndarray) -> np.ndarray:
    """The whole frame's relative gain per sample: the median over the series of (T, K)."""
    return np.median(rel, axis=1)


def _legendre(t: int, degree: int) -> np.ndarray:
    x = np.linspace(-1.0, 1.0, t)
    return np.polynomial.legendre.legvander(x, degree)


def _agree(per_bin: np.ndarray, common: np.ndarray, tol: np.ndarray, part: np.ndarray | None = None,
           uneven: float = None) -> bool:
    """Whether a change (per_bin (K, ...)) is the light's: in every profile (``part`` (K,) says
    which bin is whose) at least ``AGREE_EACH`` and on average ``AGREE`` of the bins that can tell
    (their noise ``tol`` (K,) under half the change) changed as the common one (...), within
    ``UNEVEN`` of it plus their noise. A change of the light multiplies every bin alike; a person's
    shadow does not, though it can dim all the rows (or all the columns) of a wall alike.

    Where too few bins can tell (a small change, a noisy profile), neighbouring bins are averaged in
    pairs (their noise falls by sqrt 2) down to ``AGREE_GROUPS`` groups a profile: a shadow is
    broad, so it stays uneven over the groups."""
    uneven = UNEVEN if uneven is None else uneven
    part = np.zeros(per_bin.shape[0], int) if part is None else np.asarray(part)
    size = float(np.sqrt(np.mean(np.square(common))))
    fractions = []
    for p in np.unique(part):
        mine = part == p
        pb = per_bin[mine].reshape(int(mine.sum()), -1)
        tl = np.asarray(tol, np.float64)[mine]
        while True:
            tells = tl < 0.5 * size
            if tells.sum() >= max(4, 0.5 * tl.size):
                break
            if tl.size < 2 * AGREE_GROUPS:
                return False  # too noisy to tell a light's change from a person's
            m = tl.size // 2 * 2
            pb = 0.5 * (pb[0:m:2] + pb[1:m:2])
            tl = 0.5 * np.hypot(tl[0:m:2], tl[1:m:2])
        dev = np.sqrt(np.mean(np.square(pb - common.reshape(1, -1)), axis=1))
        fractions.append(float(np.mean(dev[tells] <= uneven * size + tl[tells])))
    return min(fractions) >= AGREE_EACH and float(np.mean(fractions)) >= AGREE


def _masked_means(r: np.ndarray, w: np.ndarray, idx: np.ndarray, half: int, span: int, least: int):
    """Means of ``r`` over the (up to) ``span`` samples before ``idx - half`` and after ``idx + half``
    where ``w`` (0/1) counts, the window's ends cutting the spans short; NaN where fewer than ``least``
    samples count on a side."""
    t = r.size
    cs = np.concatenate([[0.0], np.cumsum(r * w)])
    cn = np.concatenate([[0.0], np.cumsum(w)])
    b_hi = np.clip(idx - half, 0, t)
    b_lo = np.clip(idx - half - span, 0, t)
    a_lo = np.clip(idx + half, 0, t)
    a_hi = np.clip(idx + half + span, 0, t)
    nb, na = cn[b_hi] - cn[b_lo], cn[a_hi] - cn[a_lo]
    with np.errstate(invalid="ignore", divide="ignore"):
        before = np.where(nb >= least, (cs[b_hi] - cs[b_lo]) / np.maximum(nb, 1), np.nan)
        after = np.where(na >= least, (cs[a_hi] - cs[a_lo]) / np.maximum(na, 1), np.nan)
    return before, after


def _local_steps(rel: np.ndarray, w: np.ndarray, j: int, half: int, span: int) -> np.ndarray:
    """Each series' step at ``j``: a level, a slope and a step fitted to the (up to) ``span``
    samples on either side of the ramp that ``w`` counts (the slope takes up a person's slower
    change across it; other steps' ramps are left out)."""
    t = rel.shape[0]
    idx = np.r_[max(j - half - span, 0):max(j - half, 0), min(j + half, t):min(j + half + span, t)]
    idx = idx[w[idx] > 0]
    x = (idx - j) / max(span, 1)
    design = np.stack([np.ones_like(x), x, (idx >= j).astype(np.float64)], axis=1)
    coef = _solve(design, rel[idx])
    return coef[2]


def _fraction_of_change(g: np.ndarray, w: np.ndarray, j: int, reach: int, span: int):
    """(f, lo): ``g`` from ``lo`` to ``reach`` + ``span`` samples either side of ``j`` as the
    fraction of the way from the mean level before the change to the mean after it (a 3-sample
    running mean), or None where the levels are not both there or do not differ. Samples ``w``
    leaves out (other steps' ramps) are read as the level on their side of ``j``."""
    before, after = _masked_means(g, w, np.array([j]), reach, span, 2)
    before, after = float(before[0]), float(after[0])
    if not np.isfinite(before) or not np.isfinite(after) or after == before:
        return None
    lo, hi = max(j - reach - span, 0), min(j + reach + span, g.size)
    seg = g[lo:hi].copy()
    out = w[lo:hi] == 0
    pos = np.arange(lo, hi)
    seg[out & (pos < j)] = before
    seg[out & (pos >= j)] = after
    return (np.convolve(seg, np.ones(3) / 3, mode="same") - before) / (after - before), lo


def _rise(g: np.ndarray, w: np.ndarray, j: int, half: int, span: int) -> int:
    """Samples the change of ``g`` around ``j`` takes from 10 % to 90 % of the way between the
    means of the (up to) ``span`` samples before and after it that ``w`` counts (a light's step is
    quick; the whole wall dims or brightens as a person moves in front of a lamp over half a
    second or more). Samples ``w`` leaves out (other steps' ramps) are read as the nearest level."""
    where = _ramp(g, w, j, half, span)
    return g.size if where is None else where[1] - where[0]


def _ramp(g: np.ndarray, w: np.ndarray, j: int, half: int, span: int) -> tuple[int, int] | None:
    """(sample at 10 %, sample at 90 %) of the change of ``g`` around ``j`` (:func:`_rise`), or None."""
    change = _fraction_of_change(g, w, j, half, span)
    if change is None:
        return None
    seg = change[0][1:-1]
    above = np.flatnonzero(seg >= 0.9)
    if above.size == 0:
        return None
    end = int(above[0])
    below = np.flatnonzero(seg[:end] <= 0.1)
    start = int(below[-1]) if below.size else 0
    return change[1] + 1 + start, change[1] + 1 + end


def _pair(g: np.ndarray, w: np.ndarray, j: int, ramp: int, span: int) -> tuple[int, int] | None:
    """(first, end) samples of a change of ``g`` around ``j`` made of two quick ramps (each within
    ``ramp`` + 3 samples, 10 % to 90 % of the whole) with a level between them (3 samples that move
    by under 5 % of the change), or None. Two steps of the light a few tenths of a second apart look
    like one change too slow for a light's; a person's change over as long has no level in it."""
    change = _fraction_of_change(g, w, j, 2 * ramp, span)
    if change is None:
        return None
    f, lo = change
    f[0], f[-1] = f[1], f[-2]
    above = np.flatnonzero(f >= 0.9)
    if above.size == 0:
        return None
    end = int(above[0])
    below = np.flatnonzero(f[:end] <= 0.1)
    if below.size == 0:
        return None
    start = int(below[-1])
    for a in range(start + 1, end - 2):
        if abs(f[a + 2] - f[a]) < 0.05 and 0.15 < f[a] < 0.85:
            if a - start <= ramp + 3 and end - (a + 2) <= ramp + 3:
                return lo + start, lo + end + 1
    return None


def _open_ends(g, rel, w, basis, found, thr, noise, sigma, m, part) -> list[tuple[int, int, int, float]]:
    """[(first, end, index, size)] of the stretches at the window's ends where a step of the light
    began (or ended) too close to the end for a plateau to measure it on (within ``m`` samples):
    there the level leaves what the fit of the rest (the cubic and the steps) predicts by at least
    a step's threshold, quickly (back to within a tenth of that inside the ``m`` samples) and alike
    in the bins (:func:`_agree`). Left in, such a few samples of offset bend the cubic and reach
    the classifiers as a change of the whole wall at the window's edge; taken as a ramp (the
    model there is what was measured), they go. ``index``/``size``: where it begins and its size
    as seen at the end."""
    t = g.size
    if t < 4 * m:
        return []
    n = np.arange(t)
    ww = w.copy()
    ww[:m] = 0.0
    ww[-m:] = 0.0
    keep = ww > 0
    design = np.concatenate([basis] + [(n >= j).astype(np.float64)[:, None] for j in found], axis=1)
    pinv = np.linalg.pinv(design[keep])
    r = g - design @ (pinv @ g[keep])
    out = []
    for zone in (np.arange(t - 1, t - m - 1, -1), np.arange(m)):  # from the end inwards
        zone = zone[w[zone] > 0]
        if zone.size < 2 or abs(r[zone[0]]) < thr:
            continue
        d0 = r[zone[0]]
        away = (np.sign(r[zone]) == np.sign(d0)) & (np.abs(r[zone]) >= max(0.1 * abs(d0), 3 * noise))
        run = int(np.argmin(away)) if not away.all() else zone.size
        if run >= zone.size:
            continue  # not back within the zone: a slow change, or the fit bent, not a step's edge
        idx = zone[:run]
        rb = rel - design @ (pinv @ rel[keep])
        per_bin = rb[idx].mean(axis=0)
        common = float(r[idx].mean())
        tol = 4 * sigma * np.sqrt(1.0 / idx.size + 1.0 / keep.sum())
        if not _agree(per_bin[:, None], np.array([common]), tol, part):
            continue
        lo, hi = int(idx.min()), int(idx.max()) + 1
        j = lo if zone[0] > zone[-1] else hi
        out.append((lo, hi, j, float(d0 if zone[0] > zone[-1] else -d0)))
    return out


def _steps_and_drift(rel: np.ndarray, rate: float, part=None) -> tuple[np.ndarray, list, float]:  # noqa: C901
    """(model of the whole-frame gain (T,), steps [(index, size)], drift peak-to-peak) of relative
    changes ``rel`` (T, K): a cubic plus steps fitted jointly to the median over the bins.

    Steps are found one at a time on what the joint fit (the cubic and the steps found so far, each
    found step's ramp left out) leaves: where the means of the ``SPAN_S`` seconds on either side of
    a ``RAMP_S`` differ by more than STEP_MIN and STEP_SIGMA noise. A step may lie as close to
    another as a ramp (the spans reach across the other, which the fit holds), and as close to the
    window's ends as ``least`` samples of plateau. One is kept only where it is quick (``_rise``;
    or two quick ramps with a level between them, ``_pair``, taken as one step) and most bins
    stepped alike (``AGREE``) in every profile (``part`` (K,): which profile each bin
    is of; a person's shadow can dim all the rows of a wall alike, not also all its columns); so is
    the drift. Each step's size is the median of the bins' own (a shadow moves a fit of the median
    over the bins), each bin's fitted with the other steps taken out (close steps are sized again
    once all are found). Works on logarithms of the levels (:func:`fit`): gains add."""
    t = rel.shape[0]
    g = _robust_gain(rel)
    basis = _legendre(t, DRIFT_DEGREE)
    dg = np.diff(g)
    noise = 1.4826 * np.median(np.abs(dg - np.median(dg))) / np.sqrt(2.0)
    db = np.diff(rel, axis=0)
    sigma = 1.4826 * np.median(np.abs(db - np.median(db, axis=0)), axis=0) / np.sqrt(2.0)  # (K,) per bin
    ramp = max(2, int(round(RAMP_S * rate)))
    span = max(4, int(round(SPAN_S * rate)))
    half = ramp // 2
    least = max(3, int(round(EDGE_S * rate)))  # the shortest plateau a step is measured on
    thr = max(STEP_MIN, STEP_SIGMA * noise)
    w = np.ones(t)  # 0 on found steps' ramps, which the steps' model (a jump) does not describe
    found: list[int] = []
    sizes: list[float] = []
    halves: list[int] = []  # each step's half-width of ramp (two quick ramps together: wider)
    blocked: list[int] = []
    n = np.arange(t)

    def stepped(skip: int = -1) -> np.ndarray:
        return sum((s * (n >= j) for i, (j, s) in enumerate(zip(found, sizes)) if i != skip), np.zeros(t))

    def counts(j: int) -> tuple[float, float]:
        nb = w[max(j - half - span, 0):max(j - half, 0)].sum()
        na = w[min(j + half, t):min(j + half + span, t)].sum()
        return float(nb), float(na)

    idx = np.arange(half + least, t - half - least + 1)
    for _ in range(2 * MAX_STEPS):
        if len(found) >= MAX_STEPS or idx.size == 0:
            break
        design = np.concatenate([basis] + [(n >= j).astype(np.float64)[:, None] for j in found], axis=1)
        keep = w > 0
        coef = _solve(design[keep], g[keep])
        r = g - design @ coef
        before, after = _masked_means(r, w, idx, half, span, least)
        d = np.nan_to_num(after - before)
        for j in found:
            d[np.abs(idx - j) < ramp] = 0.0
        for j in blocked:  # one change is looked at once
            d[np.abs(idx - j) < ramp + span] = 0.0
        k = int(np.argmax(np.abs(d)))
        if abs(d[k]) < thr:
            break
        # the plateau of d is a ramp wide: the step is where the adjacent means differ most
        cand = np.arange(max(int(idx[k]) - half, 1), min(int(idx[k]) + half + 1, t - 1))
        b2, a2 = _masked_means(r, w, cand, 0, span, least)
        adj = np.nan_to_num(a2 - b2)
        j = int(cand[np.argmax(np.abs(adj))]) if np.any(adj) else int(idx[k])
        nb, na = counts(j)
        ok = min(nb, na) >= 2
        if ok:
            others = stepped()
            hj = half
            where = _ramp(g - others, w, j, half, span)
            if where is not None and where[1] - where[0] <= ramp:
                # the largest difference of adjacent means can sit at a slow ramp's end, so that
                # the ramp left out of the fits (a ramp's length, centred on the step) misses half
                # of it and the spans take it in: the step is where the level moves, if the change
                # measured across the ramp there is the larger (a step beside another one, not yet
                # found, moves the levels the middle is measured between) and its ramp does not
                # run into a found step's (a shared ramp is no one step's)
                mid = int(round(0.5 * (where[0] + where[1])))
                if (mid != j and abs(mid - j) <= half and idx[0] <= mid <= idx[-1]
                        and all(abs(mid - k) >= half + hk for k, hk in zip(found, halves))):
                    size_at = [abs(np.median(_local_steps(rel - others[:, None], w, i, half, span))) for i in (j, mid)]
                    if size_at[1] > size_at[0]:
                        j = mid
                        nb, na = counts(j)
            if _rise(g - others, w, j, half, span) > ramp + 3:
                two = _pair(g - others, w, j, ramp, span)
                hj = max(j - two[0], two[1] - j) if two is not None else -1
            ok = hj >= 0
            if ok:
                per_bin = _local_steps(rel - others[:, None], w, j, hj, span)
                common = np.array([np.median(per_bin)])
                tol = 4 * sigma * np.sqrt(1.0 / nb + 1.0 / na)
                ok = abs(common[0]) >= thr and _agree(per_bin[:, None], common, tol, part)
        if ok:
            found.append(j)
            sizes.append(float(common[0]))
            halves.append(hj)
            w[max(j - hj - 1, 0):min(j + hj + 1, t)] = 0.0
        else:
            blocked.append(j)  # uneven along the wall: someone's shadow, kept
    for _ in range(2 if len(found) > 1 else 0):
        # a step whose spans reached across another one, found after it, was sized with that one in
        # them: size it again with the others' sizes taken out
        for i, j in enumerate(found):
            if any(abs(j - k) < halves[i] + hk + span for k, hk in zip(found, halves) if k != j):
                sizes[i] = float(np.median(_local_steps(rel - stepped(i)[:, None], w, j, halves[i], span)))
    ends = _open_ends(g, rel, w, basis, found, thr, noise, sigma, half + least + 1, part)
    for lo, hi, _, _ in ends:
        w[lo:hi] = 0.0
    steps_g = stepped()
    keep = w > 0
    nb = basis.shape[1]
    coef = _solve(basis[keep], (g - steps_g)[keep])
    drift = basis[:, 1:] @ coef[1:]
    ptp = float(drift.max() - drift.min())
    if ptp >= DRIFT_MIN:
        cb = _solve(basis[keep], (rel - steps_g[:, None])[keep])
        per_bin = (basis[:, 1:] @ cb[1:nb]).T  # (K, T)
        tol = 3 * sigma * np.sqrt((nb - 1) / keep.sum())
        if DRIFT_AGREE and not _agree(per_bin, drift, tol, part, UNEVEN_DRIFT):
            ptp = 0.0
    model = drift.copy() if ptp >= DRIFT_MIN else np.zeros(t)
    model = model + steps_g
    order = sorted(zip(found, halves))
    ramps = [(max(j - hj - 1, 0), min(j + hj + 1, t)) for j, hj in order] + [(lo, hi) for lo, hi, _, _ in ends]
    for lo, hi in ramps:  # within a ramp the step's shape is what was measured, not a jump
        around = np.arange(max(lo - span, 0), min(hi + span, t))
        around = around[keep[around]]
        model[lo:hi] = g[lo:hi] - (np.median((g - model)[around]) if around.size else 0.0)
    # each step's size as the model has it: the change across its ramp (where two ramps touch, the
    # level between them is only seen there, not in the fitted jumps)
    steps = [(j, float(np.mean(model[min(j + hj + 1, t - 1):min(j + hj + 3, t)])
                        - np.mean(model[max(j - hj - 3, 0):max(j - hj - 1, 1)]))) for j, hj in order]
    steps += [(j, size, True) for _, _, j, size in ends]
    return model, sorted(steps), ptp if ptp >= DRIFT_MIN else 0.0


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
    first (:mod:`wallcli.signal.shake`), then the light's nuisances are fitted on what is left.
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
        # colours summed: the nuisances are grey; (T, K) with K the bins of every part used
        series = np.concatenate([r.sum(axis=-1).T for r in raws], axis=1)
        vs = None
        if vertical_index is not None and vertical_index in used:
            start = sum(raws[i].shape[0] for i in range(used.index(vertical_index)))
            vs = slice(start, start + raws[used.index(vertical_index)].shape[0])
        t0 = 0.0 if starts is None else float(starts[w])
        part = np.concatenate([np.full(r.shape[0], i) for i, r in enumerate(raws)])
        res = fit(series, rate, lines=lines, options=options, t0=t0, vertical=vs, part=part)
        if res is None and shaken is None:
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
    from wallcli.signal.shake import unshake

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
