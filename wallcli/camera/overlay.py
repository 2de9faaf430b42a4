"""Burned-in overlays (a CCTV clock, a camera name) found in the decode and masked out of every analysis.

A recorder draws its clock after the camera: the text's pixels hold one code value, frozen, and
change in steps (once a second), all at once and for one frame; a mover changes the picture over
many frames in a row, wherever it goes. So a change is an overlay's step when it is large (far over
the clip's frame-to-frame noise, and over ``ABS_STEP`` codes), compact (a line of text, not a
sizeable part of the frame, and not the whole frame stepping at once: a cut, a flash), alone in
time (nothing changed within its box for ``BEFORE`` frame pairs before it nor for ``AFTER`` pairs
after it), frozen on one side, and a text's (its changed samples hold one value on one side of
the step, beyond the wall's spread: a codec's keyframe or a shadow stepping in one frame leaves
values the wall has). A text that moves, or any object, changes its box in the frames next to
the step and is never taken for one.

A step found grows to its whole line of text: the samples of its rows either side that stand out
from the wall in the step's text colour, as far as they run on (a clock's other digits step later,
after a minute or an hour, and its date never within a clip).

Text that never changes (a camera name, the clock's date) is found by the same freezing: samples
that have hardly changed over ``STILL_RUN`` seconds (a codec touches them now and then), where the
wall's own noise keeps most of the frame changing, that stand out from their neighbourhood as a text's strokes do, and most of
which hold one code value (the text's colour).

A box found is filled, from the frame before it was found on, with what that frame showed there,
scaled by how the wall's light around the box has changed since: no analysis (the view check,
the plots, the SNR, the ROI) ever sees the step, while the box follows the light of the wall about
it. The filled planes are float32 (the fill is a gain, never rounded). Frames wait ``AFTER``
frames before they are handed on (they are the decoder's buffers, not copies), so memory stays
flat whatever the length. The clip's first ``HOLD_SECONDS`` (at most ``HOLD_BYTES`` of decoded
picture) wait until then: a box found in them is masked from the clip's first frame, so a clock's
steps before it was recognised are never read as signal or as a moving object (decoded once,
never re-read; ``view.masked``'s ``from`` is then the clip's start).
"""

from __future__ import annotations

import dataclasses
import statistics
from collections import deque
from typing import Iterator

import numpy as np

MAX_SIDE = 640  # luma samples along the long side that steps are looked for on (text stays legible)
K_STEP = 5.0  # a step's pixels changed by this many noise sigmas of a frame difference
ABS_STEP = 12.0  # and by this many 8-bit codes at least (a noise-free clip has no sigma)
MIN_PIXELS = 6  # changed samples that make a step
FROZEN = 0.7  # of them still (text stays text, wall stays wall) in the pair before or after: the overlay
# is drawn after the camera, without its noise
REL_FROZEN = 0.1  # still: changed by under this many noise sigmas (and half a code), frame to frame
BEFORE, AFTER = 3, 2  # frame pairs either side of a step in which its box must not change at all
PAD = 2  # samples: a step's box widened by this before the pairs either side are read
MAX_BOX = 0.08  # of the frame's area: an overlay's step (some digits), or a line of text, is no larger
STILL_RUN = 0.5  # seconds over which a static text's samples have hardly changed
STATIC_EVERY = 1.0  # seconds between looks for still text: it stays where it is, and a look costs
# a median over a wide neighbourhood of each still sample (about 1 ms at 640 samples where they are
# a few dozen, 3-6 ms over the whole frame where many; at 8 frames apart it was a third of the
# overlay check's time on a 1080p export, bench/RESULTS.md)
STILL_REL = 0.2  # hardly: by under this share of the frame's typical change (and 0.05 codes: not at all)
STATIC_CONTRAST = 24.0  # 8-bit codes from their neighbourhood's median (a codec leaves wall texture still too)
STATIC_PIXELS = 10  # such samples in a line of text
TEXT_LINE = 1 / 12  # of the frame's height: the tallest line of text looked for
FLAT, FLAT_SHARE = 3.0, 0.5  # and this share of them within this many codes of one value: a recorder's
# text is drawn in one colour, a wall's texture never is
STEP_FLAT = 4.0  # codes: a step's text side, the same (a codec's ringing about a stroke included)
MAX_STILL_SHARE = 0.5  # of the frame: where more is as still, stillness tells nothing (a codec's static blocks)
MAX_FRAME_STEP = 0.03  # of the frame's samples changed at once: more is the whole picture stepping
MAX_TOTAL = 0.2  # of the frame's area: boxes beyond it are not taken (the check judges the rest)
MAX_REGIONS = 32
RING = 3  # source pixels about a box whose light the box follows
HISTORY = 16  # recent noise sigmas whose median the thresholds use
HOLD_SECONDS = 8.0  # the clip's first seconds are held back (decoded once, not re-read), so that an
# overlay found in them is masked from the clip's start (a clock's digits were found 0.9-7 s in;
# before, their steps were read as signal or as a moving object)
HOLD_BYTES = 192 << 20  # and at most this much decoded picture (1080p 4:2:0: about 60 frames)


@dataclasses.dataclass
class _Region:
    box: tuple[int, int, int, int]  # x, y, w, h in luma pixels, even where the chroma is subsampled
    first: float  # time of its first step (when it was found)
    patch: list  # the planes' crops (float32) from the frame before its first step
    ring: tuple[int, int, int, int]  # x0, y0, x1, y1: the band about the box whose light it follows
    ring_ref: np.ndarray  # that band's luma in the frame before the first step
    start: float = 0.0  # time of the first frame masked (the clip's start when found in its first seconds)


class OverlayFilter:
    """A reader whose :meth:`frames` hands on frames with burned-in overlays masked; everything
    else is the reader's. ``check`` (a :class:`wallcli.view.check.ViewCheck`) is told each box."""

    def __init__(self, reader, check=None) -> None:
        self.reader = reader
        self.checks = [check] if check is not None else []
        self.regions: list[_Region] = []
        self._waiting: deque = deque()  # frames not yet handed on (their pair index is theirs)
        self._big: deque = deque(maxlen=BEFORE + AFTER + 1)  # (pair index, changed samples) or None
        self._still: deque = deque(maxlen=AFTER + 2)  # (pair index, difference, the code it is still under)
        self._prev = None  # the previous frame's sampled luma
        self._frames: deque = deque(maxlen=AFTER + 2)  # the last frames' sampled luma (a step's either side)
        self._sig: deque = deque(maxlen=HISTORY)
        self._last = None  # the last frame handed on (masked)
        self._index = -1
        self._step = 1
        self._taken = None  # samples under a box (their steps are masked already)
        self._run = None  # per sample: its running mean frame-to-frame change (codes)
        self._run_n = 0
        self._stepped = None  # per sample: the _run_n at which it last changed by a step's size
        self._contrast = ABS_STEP  # codes: what a step changes (K_STEP noise sigmas, ABS_STEP at least)
        self._holding = True  # the clip's first frames are held back (HOLD_SECONDS, HOLD_BYTES)
        self._held_bytes = 0
        self._t0 = None
        self._rate = None  # the reader's frame rate (read once)

    def __getattr__(self, name: str):
        return getattr(self.reader, name)

    # ------------------------------------------------------------------ finding steps
    def _sample(self, planes) -> np.ndarray:
        import cv2

        y = planes.y
        h, w = y.shape
        self._step = max(1, -(-max(h, w) // MAX_SIDE))
        if self._step > 1:  # a lattice, not an average: a text's samples keep its one colour
            # the lattice's rows copied first (whole rows, a memcpy each), then its columns picked
            # (the same samples as resizing the whole plane, at half the cost: 0.11 ms, not 0.21, at 1080p)
            rows = np.ascontiguousarray(y[: h - h % self._step: self._step, : w - w % self._step])
            y = cv2.resize(rows, (w // self._step, h // self._step), interpolation=cv2.INTER_NEAREST)
        if y.dtype == np.uint8:  # 8-bit: compared as it is (OpenCV's saturating integer ops)
            return y
        return (y.astype(np.float32) / np.float32(1 << (planes.depth - 8))).astype(np.float32)

    def _observe(self, planes) -> None:
        h, w = planes.y.shape
        # a frame too thin for a line of text (4000x16, 1x1000), or whose sampling lattice would be
        # under two samples across (16384x16: one sample in 52 each way)
        if min(h, w) < 16 or min(h, w) // -(-max(h, w) // MAX_SIDE) < 2:
            self._big.append(None)
            return
        s = self._sample(planes)
        self._frames.append(s)
        prev, self._prev = self._prev, s
        if prev is None or prev.shape != s.shape:
            self._big.append(None)
            return
        import cv2

        d = cv2.absdiff(s, prev)
        # the noise of a difference: a codec zeroes most differences of a still wall, and the
        # median alone then reads its noise as a fraction of what the rest of the pixels show
        # (read on a lattice: a sixteenth of the samples tell the noise as well)
        median, p90 = _median_p90(d[::4, ::4])
        self._sig.append(max(1.4826 * median, p90 / 1.645))
        sigma = statistics.median(self._sig)  # np.median's value, without its overhead on 16 floats
        self._contrast = max(K_STEP * sigma, ABS_STEP)
        # which samples stayed still is read in _judge, only about a step found (rarely): the
        # difference is kept with its threshold, the same comparison made then
        self._still.append((self._index, d, _code(d, max(REL_FROZEN * sigma, 0.5))))
        # how much each sample changes, frame to frame, over the last STILL_RUN seconds (a running
        # mean): a codec touches a still text by a code now and then, the wall's noise always
        if self._run is None or self._run.shape != d.shape:
            self._run, self._run_n = np.zeros(d.shape, np.float32), 0
            self._stepped = np.zeros(d.shape, np.int32)
        self._run_n += 1
        a = max(1.0 / (STILL_RUN * self._fps()), 1.0 / self._run_n)
        cv2.accumulateWeighted(d, self._run, a)  # (1 - a) run + a d, one pass outside the GIL
        # most frames step nowhere: the largest difference tells, and the map is made only where
        # one did (its threshold is the comparison's own, so no sample over it is missed)
        big, threshold = None, _code(d, self._contrast)
        if cv2.minMaxLoc(d)[1] > threshold:
            big = d > threshold
            # when each sample last stepped (the frames since, in _static): a moving text's strokes step every few frames
            np.copyto(self._stepped, self._run_n, where=big)
            if self._taken is not None and self._taken.shape == big.shape:
                big &= ~self._taken
            if not big.any():
                big = None
        self._big.append((self._index, big))

    def _fps(self) -> float:
        if self._rate is None:
            self._rate = float(getattr(getattr(self.reader, "info", None), "fps", 0) or 30.0)
        return self._rate

    def _judge(self, j: int) -> list[tuple[int, int, int, int]]:
        """Boxes (sample coordinates, x0, y0, x1, y1) of the overlay steps at pair ``j``."""
        import cv2

        known = [e for e in self._big if e is not None]
        big = next((b for i, b in known if i == j), None)
        if big is None or int(big.sum()) < MIN_PIXELS or big.mean() > MAX_FRAME_STEP:
            return []  # (a cut, a flash, the camera jumping: the whole frame steps, no overlay)
        maps = dict(known)
        h, w = big.shape
        joined = cv2.dilate(big.astype(np.uint8), np.ones((3, 5), np.uint8))  # a text line's strokes
        n, _, stats, _ = cv2.connectedComponentsWithStats(joined, connectivity=8)
        found = []
        for x, y, bw, bh, _ in stats[1:n]:
            x0, y0, x1, y1 = max(x - PAD, 0), max(y - PAD, 0), min(x + bw + PAD, w), min(y + bh + PAD, h)
            if int(big[y0:y1, x0:x1].sum()) < MIN_PIXELS or (x1 - x0) * (y1 - y0) > MAX_BOX * h * w:
                continue
            near = [i for i in range(j - BEFORE, j + AFTER + 1) if i != j]
            # an overlay's box is still in the pairs either side; nothing known there (the clip's
            # first frames) is no evidence that it was
            if any(i not in maps and i >= 1 for i in near if i <= self._index):
                continue
            if any(maps[i] is not None and maps[i][y0:y1, x0:x1].any() for i in near if i in maps):
                continue
            changed = big[y0:y1, x0:x1]
            still = [m[y0:y1, x0:x1] <= t for i, m, t in self._still if i in (j - 1, j + 1)]
            if len(still) < 2 or (changed & (still[0] | still[1])).sum() < FROZEN * changed.sum():
                continue
            if not _text_step(self._frames[-(AFTER + 2)][y0:y1, x0:x1].astype(np.float32),
                              self._frames[-(AFTER + 1)][y0:y1, x0:x1].astype(np.float32), changed, self._contrast):
                continue
            found.append((x0, y0, x1, y1))
        return found

    def _static_every(self) -> int:
        return max(1, round(STATIC_EVERY * self._fps()))

    def _line(self, boxes) -> list[tuple[int, int, int, int]]:
        """Boxes (sample coordinates) of the rest of the text line each step box in ``boxes`` lies
        in: the samples of its rows, either side, that stand out from the wall in the step's text
        colour, as far as they run on with gaps under the line's height (a clock's other digits
        and its date step later, or never within the clip; the static finder misses them where a
        codec holds most of the frame still)."""
        import cv2

        s = self._frames[-(AFTER + 1)].astype(np.float32)  # the frame after the step
        h, w = s.shape
        k = int(max(5, (2 * h * TEXT_LINE) // 2 * 2 + 1))
        thr = max(self._contrast, STATIC_CONTRAST)
        found = []
        cover = np.zeros((h, w), bool) if self._taken is None or self._taken.shape != (h, w) else self._taken.copy()
        for x0, y0, x1, y1 in boxes:
            cover[y0:y1, x0:x1] = True
        for x0, y0, x1, y1 in boxes:
            b0, b1 = max(y0 - k, 0), min(y1 + k, h)
            ground = cv2.medianBlur(np.clip(s[b0:b1], 0, 255).astype(np.uint8), k).astype(np.float32)
            band, ground = s[y0:y1], ground[y0 - b0:y1 - b0]
            out = np.abs(band - ground) > thr
            if int(out[:, x0:x1].sum()) < MIN_PIXELS:
                continue
            colour = float(np.median(band[:, x0:x1][out[:, x0:x1]]))
            cols = (out & (np.abs(band - colour) <= STEP_FLAT)).any(axis=0)
            gap = y1 - y0
            lo = x0
            while True:
                near = np.flatnonzero(cols[max(lo - gap, 0):lo])
                if not near.size:
                    break
                lo = max(lo - gap, 0) + int(near[0])
            hi = x1
            while True:
                near = np.flatnonzero(cols[hi:min(hi + gap, w)])
                if not near.size:
                    break
                hi = hi + int(near[-1]) + 1
            most = int(MAX_BOX * h * w) // max(gap, 1)  # wide lines in pieces, each an overlay's box
            for a, b in ((max(lo - PAD, 0), x0), (x1, min(hi + PAD, w))):
                for c in range(a, b, max(most, 1)):
                    e = min(c + most, b)
                    if e > c and not cover[y0:y1, c:e].all():
                        found.append((c, y0, e, y1))
                        cover[y0:y1, c:e] = True
        return found

    def _static(self) -> list[tuple[int, int, int, int]]:
        """Boxes (sample coordinates) of text that has hardly changed over STILL_RUN seconds."""
        import cv2

        fps = self._fps()
        if self._run_n < max(2 * STILL_RUN * fps, 4):
            return []
        typical = float(np.median(self._run[::4, ::4]))
        calm = self._run_n - self._stepped  # frame pairs since each sample last stepped
        long = (self._run <= max(STILL_REL * typical, 0.05)) & (calm >= 2 * STILL_RUN * fps)
        if not long.any() or long.mean() > MAX_STILL_SHARE:
            return []
        s = self._prev.astype(np.float32)
        # against the wall about it: a neighbourhood twice a line of text's height (a bold
        # stroke is its own median in a small one)
        k = int(max(5, (2 * s.shape[0] * TEXT_LINE) // 2 * 2 + 1))
        # the median only where it is asked: at the still samples themselves where they are few (a
        # wall's scattered still samples: 4 ms over the whole band at 1080p, 1 ms at each), else
        # in the band of them and half a kernel about it (the same values: every one's whole
        # neighbourhood is inside, the frame's edges too)
        rows, cols = np.flatnonzero(long.any(axis=1)), np.flatnonzero(long.any(axis=0))
        r0, r1 = max(int(rows[0]) - k // 2, 0), min(int(rows[-1]) + k // 2 + 1, s.shape[0])
        c0, c1 = max(int(cols[0]) - k // 2, 0), min(int(cols[-1]) + k // 2 + 1, s.shape[1])
        eight = self._prev if self._prev.dtype == np.uint8 else np.clip(s, 0, 255).astype(np.uint8)
        rr, cc = np.nonzero(long)
        if rr.size * k * k <= 2 * (r1 - r0) * (c1 - c0):
            ground = _medians_at(eight, rr, cc, k)
        else:
            ground = cv2.medianBlur(np.ascontiguousarray(eight[r0:r1, c0:c1]), k)[rr - r0, cc - c0]
        out = np.abs(s[rr, cc] - ground.astype(np.float32)) > max(self._contrast, STATIC_CONTRAST)
        cand = np.zeros(long.shape, bool)  # still samples that stand out from the wall about them
        cand[rr[out], cc[out]] = True
        if self._taken is not None and self._taken.shape == cand.shape:
            cand &= ~self._taken
        if int(cand.sum()) < STATIC_PIXELS:
            return []
        h, w = cand.shape
        joined = cv2.dilate(cand.astype(np.uint8), np.ones((3, 5), np.uint8))
        n, _, stats, _ = cv2.connectedComponentsWithStats(joined, connectivity=8)
        found = []
        for x, y, bw, bh, _ in stats[1:n]:
            x0, y0, x1, y1 = max(x - PAD, 0), max(y - PAD, 0), min(x + bw + PAD, w), min(y + bh + PAD, h)
            values = s[y0:y1, x0:x1][cand[y0:y1, x0:x1]]
            if values.size < STATIC_PIXELS or (x1 - x0) * (y1 - y0) > MAX_BOX * h * w:
                continue
            mode = float(np.median(values))
            if np.mean(np.abs(values - mode) <= FLAT) >= FLAT_SHARE:
                found.append((x0, y0, x1, y1))
        return found

    def _take(self, boxes, t: float, before, start: float) -> None:
        """Mask ``boxes`` (found at time ``t``) from the first frame not yet handed on (time
        ``start``), each filled with what ``before`` (the frame before its step, masked as far as
        known) shows there."""
        planes = before.planes
        s = self._step
        h, w = planes.y.shape
        ax = 1 << max(planes.sub_x, 0) if planes.u is not None else 1
        ay = 1 << max(planes.sub_y, 0) if planes.u is not None else 1
        for x0, y0, x1, y1 in boxes:
            if len(self.regions) >= MAX_REGIONS or self.masked_share() >= MAX_TOTAL:
                return
            # source pixels, widened to whole chroma samples
            X0, Y0 = (x0 * s) // ax * ax, (y0 * s) // ay * ay
            X1, Y1 = min(-(-(x1 * s) // ax) * ax, w), min(-(-(y1 * s) // ay) * ay, h)
            box = (X0, Y0, X1 - X0, Y1 - Y0)
            patch = [_crop(p, box, planes, i) for i, p in enumerate(_arrays(planes))]
            X0, Y0, X1, Y1 = max(X0 - RING, 0), max(Y0 - RING, 0), min(X1 + RING, w), min(Y1 + RING, h)
            ring = np.array(planes.y[Y0:Y1, X0:X1], np.float32)
            self.regions.append(_Region(box, round(float(t), 4), patch, (X0, Y0, X1, Y1), ring, round(float(start), 4)))
            for check in self.checks:
                check.mask(box, t, start)
        self._taken = np.zeros_like(self._prev, bool)
        for r in self.regions:
            x, y, bw, bh = r.box
            self._taken[y // s: -(-(y + bh) // s), x // s: -(-(x + bw) // s)] = True

    # ------------------------------------------------------------------ masking
    def _fill(self, frame):
        if not self.regions:
            return frame
        planes = frame.planes
        arrays = [a.astype(np.float32) for a in _arrays(planes)]
        for r in self.regions:
            g = _gain(planes.y, r, self.regions)
            for i, (a, p) in enumerate(zip(arrays, r.patch)):
                x, y, bw, bh = _plane_box(r.box, planes, i)
                a[y:y + bh, x:x + bw] = p * np.float32(g) if i == 0 or planes.kind == "rgb" else p
        names = ("y", "u", "v")[: len(arrays)]
        return dataclasses.replace(frame, planes=dataclasses.replace(planes, **dict(zip(names, arrays))))

    def _release(self):
        frame = self._fill(self._waiting.popleft())
        self._last = frame
        return frame

    def _frame(self, i: int, fill: bool = True):
        """Frame ``i`` (of those this filter was given) as masked so far, if it is still known:
        waiting, or the last handed on (``fill`` False: whether it is, without masking it)."""
        pos = i - (self._index - len(self._waiting) + 1)
        if pos >= 0:
            return self._fill(self._waiting[pos]) if fill else True
        return self._last if pos == -1 else None

    def _hold(self, frame) -> None:
        """Whether the clip's first frames are still held back (see HOLD_SECONDS)."""
        if self._t0 is None:
            self._t0 = float(frame.time)
        self._held_bytes += sum(int(getattr(a, "nbytes", 0)) for a in _arrays(frame.planes))
        if float(frame.time) - self._t0 >= HOLD_SECONDS or self._held_bytes > HOLD_BYTES:
            self._holding = False

    def frames(self) -> Iterator:
        for frame in self.reader.frames():
            self._index += 1
            self._observe(frame.planes)
            self._waiting.append(frame)
            if self._holding:
                self._hold(frame)
            j = self._index - AFTER
            if j >= 1 and self._frame(j - 1, fill=False) is not None:
                boxes = self._judge(j)
                if boxes:
                    boxes += self._line(boxes)
                if self._run is not None and self._index % self._static_every() == 0:
                    boxes += self._static()
                if boxes:
                    found = self._waiting[j - (self._index - len(self._waiting) + 1)].time
                    self._take(boxes, found, self._frame(j - 1), self._waiting[0].time)
            while not self._holding and len(self._waiting) > AFTER:
                yield self._release()
        while self._waiting:
            yield self._release()

    # ------------------------------------------------------------------ reporting
    def masked_share(self) -> float:
        if self._prev is None:
            return 0.0
        h, w = self._prev.shape
        return sum(r.box[2] * r.box[3] for r in self.regions) / float(h * w * self._step ** 2)

    def masked(self) -> list[dict]:
        """The ``view.masked`` entries (docs/contract.md): the boxes, overlapping ones merged."""
        return merged([(r.box, r.first, r.start) for r in self.regions])


def merged(items) -> list[dict]:
    """[(box, first, start)] as ``view.masked`` entries, boxes that touch joined into one:
    ``from`` the time it was found, ``masked_from`` the time of the first frame masked."""
    groups: list[list] = []
    for item in sorted(items, key=lambda r: (r[0][1], r[0][0])):
        box, first = item[0], item[1]
        start = item[2] if len(item) > 2 else first
        x, y, w, h = box
        for g in groups:
            gx, gy, gw, gh = g[0]
            if x <= gx + gw + 2 and gx <= x + w + 2 and y <= gy + gh + 2 and gy <= y + h + 2:
                nx, ny = min(x, gx), min(y, gy)
                g[0] = (nx, ny, max(x + w, gx + gw) - nx, max(y + h, gy + gh) - ny)
                g[1] = min(g[1], first)
                g[2] = min(g[2], start)
                break
        else:
            groups.append([box, first, start])
    return [{"box": [int(v) for v in b], "kind": "overlay", "from": f, "masked_from": m} for b, f, m in groups]


def _code(d: np.ndarray, threshold: float):
    """``threshold`` for ``d > t`` and ``d <= t`` on integer differences ``d`` (not >= or <): its floor
    as the array's own type, so the comparison stays in 8 bits (against a float numpy widens every
    sample first: 0.04 ms a comparison of a 640x360 lattice, ten times the integer one)."""
    if d.dtype != np.uint8 or threshold < 0:
        return threshold
    return np.uint8(min(int(np.floor(threshold)), 255))


def _median_p90(a: np.ndarray) -> tuple[float, float]:
    """np.median and np.percentile(., 90) of ``a``; for 8-bit differences read off their histogram
    (exact: order statistics of integers), a tenth of sorting them."""
    if a.dtype != np.uint8:
        a = a.astype(np.float32)
        return float(np.median(a)), float(np.percentile(a, 90))
    import cv2

    cum = np.cumsum(cv2.calcHist([np.ascontiguousarray(a)], [0], None, [256], [0, 256]).ravel())
    n = a.size
    at = 0.9 * (n - 1)
    lo = int(np.floor(at))
    # the k-th smallest (0-based) of each order statistic asked, in one search
    mid0, mid1, low, high = map(float, np.searchsorted(
        cum, [(n - 1) // 2 if n % 2 else n // 2 - 1, n // 2, lo, min(lo + 1, n - 1)], side="right").tolist())
    median = mid0 if n % 2 else 0.5 * (mid0 + mid1)
    p90 = low + (at - lo) * (high - low)
    return median, p90


def _medians_at(eight: np.ndarray, rows: np.ndarray, cols: np.ndarray, k: int) -> np.ndarray:
    """``cv2.medianBlur(eight, k)[rows, cols]`` (8-bit, its border replicated as medianBlur's is),
    at those samples alone: each one's k x k neighbourhood sorted (a radix sort, for 8 bits)."""
    import cv2

    half = k // 2
    padded = cv2.copyMakeBorder(eight, half, half, half, half, cv2.BORDER_REPLICATE)
    near = np.lib.stride_tricks.sliding_window_view(padded, (k, k))[rows, cols].reshape(len(rows), -1)
    return np.sort(near, axis=1, kind="stable")[:, k * k // 2]


def _text_step(before: np.ndarray, after: np.ndarray, changed: np.ndarray, contrast: float) -> bool:
    """Whether a step's changed samples are a text's: each one either side of the step is the
    text's colour (strokes appear or go), so the side farther from the box's median holds one
    value for most of them, and that value lies beyond the wall's about it (white or black text);
    a codec's or a shadow's step leaves values the wall has."""
    b, a = before[changed], after[changed]
    mb, ma = float(np.median(before)), float(np.median(after))
    text = np.where(np.abs(a - ma) > np.abs(b - mb), a, b)
    colour = float(np.median(text))
    if np.mean(np.abs(text - colour) <= STEP_FLAT) < FLAT_SHARE:
        return False
    rest = np.concatenate([before[~changed], after[~changed]])
    if rest.size < changed.sum():
        return True  # a box of strokes alone: nothing of the wall to compare with
    # the wall's spread, robustly (the text's own unchanged strokes are a minority of the box)
    mid = float(np.median(rest))
    spread = 2 * 1.4826 * float(np.median(np.abs(rest - mid))) + contrast / 2
    return bool(abs(colour - mid) > spread)


def _arrays(planes) -> list:
    return [planes.y] if planes.u is None else [planes.y, planes.u, planes.v]


def _plane_box(box, planes, i: int):
    x, y, w, h = box
    if i == 0 or planes.kind == "rgb":
        return x, y, w, h
    sx, sy = planes.sub_x, planes.sub_y
    return x >> sx, y >> sy, max(w >> sx, 1), max(h >> sy, 1)


def _crop(a, box, planes, i: int) -> np.ndarray:
    x, y, w, h = _plane_box(box, planes, i)
    return np.array(a[y:y + h, x:x + w], np.float32)


def _gain(y: np.ndarray, region: _Region, regions) -> float:
    """How the light about ``region`` changed since its patch was taken: the band's luma now over
    then, on the band's pixels outside every box (a later box may cover part of the band)."""
    x0, y0, x1, y1 = region.ring
    keep = np.ones((y1 - y0, x1 - x0), bool)
    for r in regions:
        rx, ry, rw, rh = r.box
        keep[max(ry - y0, 0):max(ry + rh - y0, 0), max(rx - x0, 0):max(rx + rw - x0, 0)] = False
    if not keep.any():
        return 1.0
    then = float(region.ring_ref[keep].sum())
    now = float(np.asarray(y[y0:y1, x0:x1], np.float32)[keep].sum())
    return float(np.clip(now / then, 0.5, 2.0)) if then > 0 else 1.0
