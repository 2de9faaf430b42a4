"""People as streaks: where along the wall each moving person's light change is, over time.

A person out of view darkens the part of the wall they shade from the room's light; as they walk,
that shade travels along the wall and draws a dark streak in the horizontal space-time plot. The
tracker reads the streaks: in chunks of the rows (so memory does not grow with the clip's length),
each sample's profile relative to the chunk's per-position median (a person standing still draws
nothing), the whole wall's change removed (a light change is not a person), smoothed, in units of
the noise that changes bin by bin; then the best path through the darkness (Viterbi, with a speed
limit), its whole dip masked, and the next best, up to MAX_PATHS; a path holds a track where its
darkness stays over THRESHOLD (and, for the further paths, RELATIVE of the first's) for at least
MIN_SECONDS. Chunks overlap, and a track that ends at a chunk's end continues in the next when the
two agree on the place.

Positions are the streak's, as a fraction of the plot's width (0 = the first bin's edge, the view's
left; 1 = the last bin's edge); a shade outside the view is not seen, so x stays within 0-1. A shade falls where the light's direction puts it, so the streak
can be offset from, or move faster than, the person, and a side window mirrors it
(research/track/README.md measures it on the rendered recordings' motion-capture truth): ``sigma``
is the streak's own half width (``shade``: where the shade is) combined with that geometric spread
at the shade's strength (GEOMETRY_BY_STRENGTH: where the person is, 68 % of the time out of fold).
"""
from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

CHUNK_SECONDS = 16.0  # the median background is taken over a chunk this long
OVERLAP_SECONDS = 4.0  # chunks overlap by this much, so a track is linked across them
SMOOTH_SECONDS = 0.1  # time smoothing of the darkness map (a walker's shade lasts ~0.5 s on a bin)
SMOOTH_BINS = 1.5  # of 64 bins; scaled with the plot's bins
MAX_SPEED = 0.5  # view widths a second a streak moves without penalty (chosen out of fold: research/track/tune.py)
MAX_PATHS = 3
GUARD = 0.1  # of the width: the next path keeps this far from the ones found
THRESHOLD = 6.0  # darkness, in units of the noise left after smoothing, that holds a track (empty rooms: 95 % under it)
RELATIVE = 0.35  # a further path holds a track only where it is this share of the strongest path's darkness
BRIDGE_SECONDS = 1.5  # a path's runs this close are one track (a shade fades as a person turns)
MIN_SECONDS = 1.0  # shorter runs over the threshold are not tracks
OUT_HZ = 10.0  # samples per second in a track
LINK_WIDTH = 0.12  # of the width: two tracks meeting at a chunk boundary are one when this close
GAP_STEPS, GAP_MIN = 5.0, 0.25  # rows this many steps and seconds apart have frames lost between them (as io's reader)
# How far the streak's place is from the person's (view widths): the 68th percentile of the error on
# the rendered recordings' single walkers, 0.34-0.55 fold by fold, covering 66 % out of fold
# (research/track/README.md). A shade falls where the light puts it, so this is large. It is the
# pooled figure; each sample's own uses GEOMETRY_BY_STRENGTH.
GEOMETRY_SIGMA = 0.45
# The same percentile by the shade's strength (darkness in noise units; centres of the recordings'
# thirds of samples): a strong shade is a person near a bright light (a lamp, a window), whose shade
# falls far from them and magnified, a faint one a person lit broadly, whose shade is under them.
# Between the centres it is interpolated on log strength, beyond them held. Out of fold (each
# fold's table from the other four) it covers 66 % of the samples (research/track/sigma.py).
GEOMETRY_BY_STRENGTH = ((6.5, 0.337), (19.3, 0.396), (77.8, 0.571))


def geometry_sigma(strength) -> np.ndarray:
    """The shade-to-person part of sigma at each sample's ``strength`` (view widths)."""
    s, g = (np.array(v, np.float64) for v in zip(*GEOMETRY_BY_STRENGTH))
    return np.interp(np.log10(np.maximum(np.asarray(strength, np.float64), 1.0)), np.log10(s), g)


@dataclass
class Track:
    id: int
    t: list[float] = field(default_factory=list)
    x: list[float] = field(default_factory=list)
    sigma: list[float] = field(default_factory=list)
    strength: list[float] = field(default_factory=list)
    shade: list[float] = field(default_factory=list)  # the streak's own half width: where the shade is

    @property
    def duration(self) -> float:
        return (self.t[-1] - self.t[0]) if self.t else 0.0

    def as_dict(self, view_width: float | None = None) -> dict:
        samples = []
        for t, x, s, w in zip(self.t, self.x, self.sigma, self.shade):
            d = {"t": round(float(t), 3), "x": round(float(x), 4), "sigma": round(float(s), 4),
                 "sigma_shade": round(float(w), 4)}
            if view_width is not None:
                d["x_m"] = round(float((x - 0.5) * view_width), 4)
            samples.append(d)
        # most of a walker's samples spread over the wall; a person in place stays, while the path
        # may stray where their shade fades between movements
        moved = float(np.subtract(*np.percentile(self.x, [90, 10]))) if self.x else 0.0
        return {"id": self.id, "start": round(float(self.t[0]), 3), "end": round(float(self.t[-1]), 3),
                "moving": moved >= 0.25, "strength": round(float(np.median(self.strength)), 2), "samples": samples}


def _smooth(a: np.ndarray, sigma: float, axis: int) -> np.ndarray:
    """Gaussian smoothing along one axis (edges reflected); numpy only."""
    if sigma <= 0:
        return a
    r = max(1, int(np.ceil(3 * sigma)))
    k = np.exp(-0.5 * (np.arange(-r, r + 1) / sigma) ** 2)
    k /= k.sum()
    a = np.moveaxis(a, axis, -1)
    pad = np.pad(a, [(0, 0)] * (a.ndim - 1) + [(r, r)], mode="reflect" if a.shape[-1] > r else "edge")
    out = np.zeros_like(a, dtype=np.float64)
    for i, w in enumerate(k):
        out += w * pad[..., i:i + a.shape[-1]]
    return np.moveaxis(out, -1, axis)


def darkness(rows: np.ndarray, fps: float) -> np.ndarray:
    """(T, bins[, colours]) rows -> (T, bins) darkness: how much darker than its usual level each
    place is, in robust spreads of the map (a shade is positive)."""
    lum = np.asarray(rows, np.float64)
    if lum.ndim == 3:
        lum = lum.mean(axis=-1)
    lum = lum - lum.mean(axis=1, keepdims=True)  # the whole wall's change is the light's, not a person's
    d = lum - np.median(lum, axis=0, keepdims=True)
    bins = lum.shape[1]
    d = _smooth(d, SMOOTH_SECONDS * fps, 0)
    # the noise is what changes bin by bin (a person's light reaches many bins at once): the part
    # the spatial smoothing takes off, scaled to what it leaves. Frame-to-frame differences would
    # miss a codec's or a noise filter's slow noise, which then reads as streaks on empty walls.
    sb = SMOOTH_BINS * bins / 64.0
    ds = _smooth(d, sb, 1)
    fine = 1.4826 * np.median(np.abs(d - ds))
    g = _gain(sb)
    noise = fine * np.sqrt(g / max(1.0 - g, 1e-6))
    spread = 1.4826 * np.median(np.abs(ds - np.median(ds)))
    if noise <= 1e-3 * spread:  # bins that repeat pixels (a region narrower than the bins): no fine part to read
        noise = spread
    return -ds / max(noise, 1e-12)


def _gain(sigma: float) -> float:
    """The share of white noise's variance a Gaussian of ``sigma`` samples leaves."""
    if sigma <= 0:
        return 1.0
    r = max(1, int(np.ceil(3 * sigma)))
    k = np.exp(-0.5 * (np.arange(-r, r + 1) / sigma) ** 2)
    k /= k.sum()
    return float(np.sum(k * k))


def viterbi(score: np.ndarray, step: float) -> np.ndarray:
    """The path through (T, bins) ``score`` of greatest sum, moving at most ``step`` bins a sample
    freely and paying the square of any excess."""
    T, B = score.shape
    idx = np.arange(B)
    cost = np.maximum(np.abs(idx[:, None] - idx[None, :]) - step, 0.0) ** 2
    total = score[0].copy()
    back = np.zeros((T, B), np.int32)
    for t in range(1, T):
        m = total[None, :] - cost
        back[t] = m.argmax(axis=1)
        total = m[idx, back[t]] + score[t]
    path = np.zeros(T, np.int64)
    path[-1] = int(total.argmax())
    for t in range(T - 1, 0, -1):
        path[t - 1] = back[t, path[t]]
    return path


def _runs(mask: np.ndarray) -> list[tuple[int, int]]:
    """[start, end) of each run of True."""
    m = np.concatenate([[False], mask, [False]]).astype(np.int8)
    d = np.diff(m)
    return list(zip(np.flatnonzero(d == 1), np.flatnonzero(d == -1)))


def _width(dark_row: np.ndarray, b: int) -> float:
    """The half width at half depth of the dip at bin ``b`` (bins)."""
    half = dark_row[b] / 2.0
    lo = b
    while lo > 0 and dark_row[lo - 1] > half:
        lo -= 1
    hi = b
    while hi < len(dark_row) - 1 and dark_row[hi + 1] > half:
        hi += 1
    return (hi - lo + 1) / 2.0


def chunk_segments(rows: np.ndarray, times: np.ndarray, fps: float) -> list[dict]:
    """The track segments of one chunk: each {t, x, sigma, strength} arrays at the chunk's rate."""
    dark = darkness(rows, fps)
    T, B = dark.shape
    step = MAX_SPEED * B / fps
    guard = max(1, int(round(GUARD * B)))
    score = np.clip(dark, -THRESHOLD, None)
    hold = max(1, int(round(0.5 * fps)))
    out = []
    floor = THRESHOLD
    for k in range(MAX_PATHS):
        path = viterbi(score, step)
        s = dark[np.arange(T), path]
        held = np.convolve(s, np.ones(hold) / hold, mode="same")
        if k == 0:  # a strong person's shade has fainter echoes (other lights): not other people
            floor = max(THRESHOLD, RELATIVE * float(np.percentile(held, 90)))
        runs = _runs(held >= floor)
        merged = []
        for a, b in runs:  # one path's runs a short dip apart are one track
            if merged and (a - merged[-1][1]) / fps <= BRIDGE_SECONDS:
                merged[-1] = (merged[-1][0], b)
            else:
                merged.append((a, b))
        for a, b in merged:
            if (b - a) / fps < MIN_SECONDS:
                continue
            p = path[a:b]
            x = (p + 0.5) / B
            w = np.array([_width(dark[a + i], int(p[i])) for i in range(b - a)]) / B
            seen = held[a:b] >= floor
            if not seen.all():  # across a short fade the path strays: the place is drawn between its ends
                i = np.arange(b - a)
                x = np.interp(i, i[seen], x[seen])
                w = np.where(seen, w, np.maximum(w, np.abs(x - (p + 0.5) / B)))  # as far as the path strayed
            out.append({"t": times[a:b], "x": x, "sigma": np.sqrt(w ** 2 + geometry_sigma(held[a:b]) ** 2),
                        "shade": w, "strength": held[a:b]})
        for t in range(T):  # the next path keeps off this one's whole dip (a broad shade is one person)
            g = max(guard, int(np.ceil(2.0 * _width(dark[t], int(path[t])))))
            score[t, max(0, path[t] - g):path[t] + g + 1] = -1e6
    return out


class TrackBuilder:
    """Tracks from a stream of horizontal rows ``push(t, row (bins[, colours]))``, in memory that
    does not grow with the stream's length (one chunk of rows, and the tracks' 10 Hz samples)."""

    def __init__(self, fps: float, gaps=None):
        self.fps = float(fps)
        # frames lost: (time of the frame before, time of the frame after). A list, or a callable
        # giving the list so far (a decoder's, which knows of a gap before its rows arrive). Rows
        # inside one are interpolated, not seen: no sample is kept there and no track crosses one.
        self._given = gaps if callable(gaps) else (lambda g=list(gaps or []): g)
        self._jumps: list[tuple[float, float]] = []  # jumps of the pushed rows' own times
        self.chunk = max(8, int(round(CHUNK_SECONDS * self.fps)))
        self.overlap = int(round(OVERLAP_SECONDS * self.fps))
        self._rows: list[np.ndarray] = []
        self._t: list[float] = []
        self.tracks: list[Track] = []
        self._open: list[Track] = []  # tracks that reached the last chunk's end
        self._done_until = -np.inf  # samples up to here were reported by an earlier chunk
        self.samples = 0

    def push(self, t: float, row: np.ndarray) -> None:
        if self._t and t - self._t[-1] > max(GAP_STEPS / self.fps, GAP_MIN):
            self._jumps.append((self._t[-1], float(t)))
        self._rows.append(np.asarray(row, np.float32))
        self._t.append(float(t))
        self.samples += 1
        if len(self._rows) >= self.chunk:
            self._process(final=False)
            keep = self.overlap
            self._rows, self._t = self._rows[-keep:], self._t[-keep:]

    def finish(self) -> list[Track]:
        # the rows after the last chunk's end (a stream that ended on a chunk's end has none)
        if len(self._rows) >= max(8, int(MIN_SECONDS * self.fps)) and self._t[-1] > self._done_until:
            self._process(final=True)
        self._rows, self._t = [], []
        return [t for t in self.tracks if t.duration >= MIN_SECONDS - 1.5 / OUT_HZ]

    def _process(self, final: bool) -> None:
        rows = np.stack(self._rows)
        times = np.asarray(self._t)
        segs = chunk_segments(rows, times, self.fps)
        # what this chunk says from the last one's end on (the overlap was said before)
        start_new = self._done_until
        end_time = times[-1]
        still_open = []
        every = max(1, int(round(self.fps / OUT_HZ)))
        gaps = self.gaps()
        pieces = []
        for seg in segs:
            sel = np.arange(0, len(seg["t"]), every)
            cut = _split_at_gaps({k: seg[k][sel] for k in ("t", "x", "sigma", "strength", "shade")}, gaps)
            for c in cut:  # where each piece's rows end (a sample is every few rows)
                c["end"] = float(c["t"][-1])
            if cut and _piece(float(seg["t"][-1]), gaps) == _piece(cut[-1]["end"], gaps):
                cut[-1]["end"] = float(seg["t"][-1])
            pieces += cut
        for seg in sorted(pieces, key=lambda s: s["t"][0]):
            t, x, sg, st, sh = (seg[k] for k in ("t", "x", "sigma", "strength", "shade"))
            new = t > start_new
            track = self._link(t, x, gaps) if new.any() and t[0] <= start_new + 1.0 / OUT_HZ + 1e-9 else None
            if not new.any():
                continue
            if track is None:
                track = Track(id=len(self.tracks))
                self.tracks.append(track)
            for a, b, c, d, e in zip(t[new], x[new], sg[new], st[new], sh[new]):
                if track.t and a <= track.t[-1]:
                    continue
                track.t.append(float(a)), track.x.append(float(b)), track.sigma.append(float(c))
                track.strength.append(float(d)), track.shade.append(float(e))
            if not final and seg["end"] >= end_time - 1.5 / self.fps:
                still_open.append(track)
        self._open = still_open
        self._done_until = end_time

    def gaps(self) -> list[tuple[float, float]]:
        """The frames lost so far, given and found in the rows' times, in time order."""
        return sorted({(float(a), float(b)) for a, b in [*self._given(), *self._jumps]})

    def _link(self, t: np.ndarray, x: np.ndarray, gaps) -> Track | None:
        """The open track this chunk's segment continues, if any: the closest in place where it ended
        (none across frames lost)."""
        best, gap = None, LINK_WIDTH
        for tr in self._open:
            j = int(np.searchsorted(t, tr.t[-1]))
            if j >= len(t) or _piece(tr.t[-1], gaps) != _piece(float(t[0]), gaps):
                continue
            d = abs(x[j] - tr.x[-1])
            if d <= gap:
                best, gap = tr, d
        if best is not None:
            self._open.remove(best)
        return best


def _piece(t: float, gaps) -> int:
    """How many gaps lie before time ``t`` (samples of one track share this)."""
    return sum(1 for a, _ in gaps if a < t - 1e-6)


def _split_at_gaps(seg: dict, gaps) -> list[dict]:
    """``seg`` without its samples inside a gap (no frame was there), cut where a gap lies between
    two of them: a track ends at frames lost, however close the shade is on either side."""
    t = seg["t"]
    if not gaps or not len(t):
        return [seg] if len(t) else []
    inside = np.zeros(len(t), bool)
    for a, b in gaps:
        inside |= (t > a + 1e-6) & (t < b - 1e-6)
    piece = np.array([_piece(float(v), gaps) for v in t])
    out = []
    for p in np.unique(piece[~inside]):
        keep = (piece == p) & ~inside
        out.append({k: v[keep] for k, v in seg.items()})
    return out


def track_rows(rows: np.ndarray, times: np.ndarray, fps: float, gaps=None) -> list[Track]:
    """The tracks of a whole (T, bins[, colours]) plot held in memory (a .npz from stplot);
    ``gaps``: frames lost, (time before, time after), besides the jumps of ``times``."""
    b = TrackBuilder(fps, gaps)
    for t, r in zip(times, rows):
        b.push(float(t), r)
    return b.finish()


def simultaneous(tracks: list[Track], min_seconds: float = 1.0, min_apart: float = 2 * GUARD) -> dict:
    """Evidence of two people from the tracks: how long two tracks ran at once, apart (seconds),
    and the weaker one's strength then."""
    best_t, best_s = 0.0, 0.0
    for i in range(len(tracks)):
        for j in range(i + 1, len(tracks)):
            a, b = tracks[i], tracks[j]
            ta, tb = np.round(np.asarray(a.t) * OUT_HZ), np.round(np.asarray(b.t) * OUT_HZ)
            common, ia, ib = np.intersect1d(ta, tb, return_indices=True)
            if not len(common):
                continue
            apart = np.abs(np.asarray(a.x)[ia] - np.asarray(b.x)[ib]) >= min_apart
            secs = apart.sum() / OUT_HZ
            if secs > best_t:
                best_t = secs
                best_s = float(np.median(np.minimum(np.asarray(a.strength)[ia], np.asarray(b.strength)[ib])[apart])) \
                    if apart.any() else 0.0
    return {"seconds": round(best_t if best_t >= min_seconds else 0.0, 2), "strength": round(best_s, 2)}
