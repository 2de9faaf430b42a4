"""Auto-exposure steps and slow drift of the whole frame's gain (one of the light nuisances of
:mod:`wallcli.camera.corrections`, which finds mains flicker, calls :func:`_steps_and_drift` and
divides the gains out).

The whole frame's gain, robustly (the median over the bins of each bin's relative change, so that
a shadow over part of the wall does not move it): steps (jumps of at least ``STEP_MIN`` and
``STEP_SIGMA`` times the gain's frame noise, within ``RAMP_S`` seconds: beyond what a hidden person
does to the whole wall in a few frames) and drift (a cubic over the stretch, slower than about one
cycle in 8 s; removed only when it exceeds ``DRIFT_MIN`` peak to peak). Works on logarithms of the
levels: gains add.
"""
from __future__ import annotations

from functools import lru_cache

import numpy as np

STEP_MIN = 0.003  # relative size of the smallest exposure step removed
STEP_SIGMA = 10.0  # and in units of the gain's frame-to-frame noise
RAMP_S = 0.33  # seconds an exposure step may take
SPAN_S = 0.5  # seconds averaged on each side of a step
EDGE_S = 0.17  # or as little as this where the window ends or another step begins
MAX_STEPS = 4
DRIFT_DEGREE = 3
DRIFT_MIN = 0.002  # relative peak-to-peak of the slow gain change removed
DRIFT_AGREE = True  # drift only where most bins drifted alike
UNEVEN = 0.2  # a bin's change within this fraction of the common one (plus its noise) is alike
UNEVEN_DRIFT = 0.4  # the same for drift: a passing shadow bends a bin's slow curve (a cubic) a little
AGREE = 0.7  # fraction of the bins (mean over the profiles) that must change alike for a step or drift
AGREE_EACH = 0.5  # and in each profile
AGREE_GROUPS = 8  # the fewest groups of neighbouring bins a profile is judged on


def solve(design: np.ndarray, y: np.ndarray) -> np.ndarray:
    """Least squares for a few columns and many right-hand sides: the pseudo-inverse of the small
    design once, then one product (numpy's lstsq of 128 series took 50 ms a window)."""
    return np.linalg.pinv(design) @ y


def median(x: np.ndarray, axis: int = -1) -> np.ndarray:
    """``np.median`` of real ``x`` along ``axis``, the same values, by a full sort: numpy sorts a
    contiguous last axis with SIMD, while its median partitions on two order statistics without
    (0.06 against 0.6-0.8 ms for a window's (256, 128) series)."""
    x = np.asarray(x, np.float64)
    if x.ndim == 0 or x.shape[axis] == 0:
        return np.median(x, axis=axis)
    s = np.sort(x, axis=axis)
    if axis not in (-1, s.ndim - 1):
        s = np.moveaxis(s, axis, -1)
    n = s.shape[-1]
    mid = s[..., n // 2] if n % 2 else (s[..., n // 2 - 1] + s[..., n // 2]) / 2.0
    # NaN sorts last; np.median is NaN wherever one was
    if s.ndim == 1:
        return np.float64(np.nan) if np.isnan(s[-1]) else mid
    return np.where(np.isnan(s[..., -1]), np.nan, mid)


def _robust_gain(rel: np.ndarray) -> np.ndarray:
    """The whole frame's relative gain per sample: the median over the series of (T, K)."""
    return median(rel, axis=1)


@lru_cache(maxsize=16)
def _legendre(t: int, degree: int) -> tuple[np.ndarray, np.ndarray]:
    """(Legendre basis (t, degree + 1), its pseudo-inverse): the same for every window of a length
    (read only)."""
    basis = np.polynomial.legendre.legvander(np.linspace(-1.0, 1.0, t), degree)
    pinv = np.linalg.pinv(basis)
    basis.flags.writeable = pinv.flags.writeable = False
    return basis, pinv


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
    cs = np.zeros(t + 1)
    np.cumsum(r * w, out=cs[1:])
    cn = np.zeros(t + 1)
    np.cumsum(w, out=cn[1:])
    # the four span ends at once (b_hi, b_lo, a_lo, a_hi): this runs some 400 times a window
    ends = np.minimum(np.maximum(np.asarray(idx)[None, :] + _ends_offsets(half, span), 0), t)
    c, n = cs[ends], cn[ends]
    nb, na = n[0] - n[1], n[3] - n[2]
    with np.errstate(invalid="ignore", divide="ignore"):
        before = np.where(nb >= least, (c[0] - c[1]) / np.maximum(nb, 1), np.nan)
        after = np.where(na >= least, (c[3] - c[2]) / np.maximum(na, 1), np.nan)
    return before, after


@lru_cache(maxsize=64)
def _ends_offsets(half: int, span: int) -> np.ndarray:
    return np.array([[-half], [-half - span], [half], [half + span]])


def _local_steps(rel: np.ndarray, w: np.ndarray, j: int, half: int, span: int) -> np.ndarray:
    """Each series' step at ``j``: a level, a slope and a step fitted to the (up to) ``span``
    samples on either side of the ramp that ``w`` counts (the slope takes up a person's slower
    change across it; other steps' ramps are left out)."""
    t = rel.shape[0]
    idx = np.r_[max(j - half - span, 0):max(j - half, 0), min(j + half, t):min(j + half + span, t)]
    idx = idx[w[idx] > 0]
    x = (idx - j) / max(span, 1)
    design = np.stack([np.ones_like(x), x, (idx >= j).astype(np.float64)], axis=1)
    coef = solve(design, rel[idx])
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


@lru_cache(maxsize=16)
def _ends_pinv(t: int, degree: int, m: int) -> np.ndarray:
    """The pseudo-inverse of the Legendre basis without its ``m`` samples at either end (read only)."""
    pinv = np.linalg.pinv(_legendre(t, degree)[0][m:t - m])
    pinv.flags.writeable = False
    return pinv


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
    if not found and w.all():  # most windows: the same fit for every window of a length
        pinv = _ends_pinv(t, basis.shape[1] - 1, m)
    else:
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


def _steps_and_drift(rel: np.ndarray, rate: float, part=None, degree: int = DRIFT_DEGREE) -> tuple[np.ndarray, list, float]:  # noqa: C901,E501
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
    basis, basis_pinv = _legendre(t, degree)  # degree: of the drift's polynomial
    dg = np.diff(g)
    noise = 1.4826 * median(np.abs(dg - median(dg))) / np.sqrt(2.0)
    rt = np.ascontiguousarray(rel.T)
    db = rt[:, 1:] - rt[:, :-1]  # (K, T - 1): each bin's differences along a contiguous axis, for the sort
    sigma = 1.4826 * median(np.abs(db - median(db)[:, None])) / np.sqrt(2.0)  # (K,) per bin
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
        coef = basis_pinv @ g if not found and keep.all() else solve(design[keep], g[keep])
        r = g - design @ coef
        before, after = _masked_means(r, w, idx, half, span, least)
        d = after - before
        d[np.isnan(d)] = 0.0
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
        adj = a2 - b2
        adj[np.isnan(adj)] = 0.0
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
                    size_at = [abs(median(_local_steps(rel - others[:, None], w, i, half, span))) for i in (j, mid)]
                    if size_at[1] > size_at[0]:
                        j = mid
                        nb, na = counts(j)
            if _rise(g - others, w, j, half, span) > ramp + 3:
                two = _pair(g - others, w, j, ramp, span)
                hj = max(j - two[0], two[1] - j) if two is not None else -1
            ok = hj >= 0
            if ok:
                per_bin = _local_steps(rel - others[:, None], w, j, hj, span)
                common = np.array([median(per_bin)])
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
                sizes[i] = float(median(_local_steps(rel - stepped(i)[:, None], w, j, halves[i], span)))
    ends = _open_ends(g, rel, w, basis, found, thr, noise, sigma, half + least + 1, part)
    for lo, hi, _, _ in ends:
        w[lo:hi] = 0.0
    steps_g = stepped()
    keep = w > 0
    nb = basis.shape[1]
    pinv = basis_pinv if keep.all() else np.linalg.pinv(basis[keep])
    coef = pinv @ (g - steps_g)[keep]
    drift = basis[:, 1:] @ coef[1:]
    ptp = float(drift.max() - drift.min())
    if ptp >= DRIFT_MIN:
        cb = pinv @ (rel - steps_g[:, None])[keep]
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
        model[lo:hi] = g[lo:hi] - (median((g - model)[around]) if around.size else 0.0)
    # each step's size as the model has it: the change across its ramp (where two ramps touch, the
    # level between them is only seen there, not in the fitted jumps)
    steps = [(j, float(np.mean(model[min(j + hj + 1, t - 1):min(j + hj + 3, t)])
                        - np.mean(model[max(j - hj - 3, 0):max(j - hj - 1, 1)]))) for j, hj in order]
    steps += [(j, size, True) for _, _, j, size in ends]
    return model, sorted(steps), ptp if ptp >= DRIFT_MIN else 0.0
