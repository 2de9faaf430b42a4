"""Is this a usable view: a static camera on a diffuse surface, with nothing visible moving?

The method reads changes of 0.1-1 % of the wall's light; anything else that changes the picture
(the camera moving, a person or object crossing the view, a cut to another shot, pixels clipped
or crushed to black) is far larger and would be read as a hidden person. :class:`ViewCheck` is a
tap on the one decode (fed frame by frame, memory independent of the clip's length) that flags
frames where such things happen; :meth:`ViewCheck.view` says, for any time span, whether the view
was usable there.

Every threshold is in units of the noise the clip itself shows (frame-to-frame differences,
robustly estimated), except two floors that encode the method's own premise: a hidden person
changes the wall by a few per cent at most, so a change that is both far above the noise and over
``REL`` of the local level is no hidden person; and a displacement under ``MIN_SHIFT`` pixels is
the sub-pixel shake a tripod on a floor has, which corrections (not refusal) deal with.
"""
from __future__ import annotations

import math
import statistics
from collections import deque

import numpy as np

from wallcli.view.cut import CutWatch
from wallcli.view.image import (
    _block_rects, _block_side, _box_blocks, _broad_blur, _cells, _grey, _highpass, _inner_difference, _median, _pixels, _robust_sigma, _upper_median, _whole_blocks,
)
from wallcli.view.light import _chroma, _objects, _relative_texture
from wallcli.view.limits import (
    CHECK_RATE, CLIP_HI, DARK, DENSE, EDGE_LEVEL, FINE, GAP_EDGE, HISTORY, HOLD, HOLD_WITHIN, K_EDGE, K_MOVER, KINDS,
    MATCH_RATE, MAX_OBJECT_HITS, MAX_SIDE, MIN_CROP, MAX_SPANS, MIN_MOVER_BLOCKS, MIN_REGISTER_SIDE, MIN_SHIFT, MIN_USABLE, NOT_REFUSED, NOTES,
    REL, REL_EDGE,
    SHARP, SIGMA_FLOOR, TEX_TAU,
)
from wallcli.camera.overlay import merged
from wallcli.view.motion import _in_band, _motion_verdict, _shift_fits, _texture_match
from wallcli.wording import span_text

# what other modules import from here (the thresholds live in view_limits)
__all__ = ["KINDS", "MAX_SPANS", "NOTES", "NOT_REFUSED", "ViewCheck"]


class ViewCheck:
    """Per-frame tests of the view, remembered as time spans per kind of issue.

    Call it with decoded frames (a :class:`wallcli.io.video.FrameTee` tap) or :meth:`update` with
    (time, planes). Nothing of the frame is kept but a few small downscaled images.
    """

    def __init__(self, roi=None) -> None:
        self.roi = roi  # (x, y, w, h): only what the analysis reads needs to be a still wall
        self.frames = 0  # checked in full
        self.seen = 0  # fed (every decoded frame)
        self.fps: float | None = None  # the file's rate, where a caller that quotes frames sets it
        self.spans: dict[str, list[list[float]]] = {k: [] for k in KINDS}
        self.max_shift = 0.0
        self.min_usable = 1.0
        self._sig_b: deque = deque(maxlen=HISTORY)
        self._sig_h: deque = deque(maxlen=HISTORY)
        self._prev_b = self._prev_h = self._ref_h = self._ref_w = self._bg_h = self._bg_b = None
        self._bg_n = 0  # frames averaged into the background since the last reset
        self._t_prev = None
        self._t_checked = -np.inf
        self._dense_until = -np.inf
        self._gap = np.inf  # the shortest time between two checked frames: one frame interval
        self._scale = 1.0
        self._window = None
        self._cut = CutWatch()
        self._cut_reset = False
        self._shifts: deque = deque(maxlen=HOLD_WITHIN)  # recent significant shifts (inf: none)
        # where the view failed, per block (clipped, too dark, or a mover in it), OR-ed over the
        # checked frames, and where those blocks lie in source pixels: what `snr --roi auto` avoids
        self._bad = None
        self._bad_geometry = None
        self._tex = self._bg_c = None  # the wall's relative texture and colour ratios (see _objects)
        self._ref_rel = None  # the reference frame's relative texture (see _texture_match)
        # _texture_match on checked frames (the better of in place and moved by a shift found), in
        # the registration band and in the finest one
        self._match: deque = deque(maxlen=HISTORY)
        self._match_fine: deque = deque(maxlen=HISTORY)
        self._ref_fine = None
        self._t_tex = self._t_match = -np.inf
        self.note_spans: dict[str, list[list[float]]] = {k: [] for k in NOTES}
        self.trace: list | None = None  # a list: _objects appends what it judged on (research/view)
        self.masked: list = []  # (box, first seen): burned-in overlays masked out of the frames (signal/overlay)
        self.masked_from: list = []  # per box: the time of the first frame masked (the clip's start when held)
        # each 'moving object' flag's time and blocks, until too many to keep: an overlay is only
        # recognised after its text has stepped a few times, and those steps were flagged first
        self._object_hits: list | None = []

    def __call__(self, frame) -> None:
        gap = getattr(frame, "gap", 0.0)
        if gap:
            self.gap(frame.time - gap, frame.time)
        self.update(frame.time, frame.planes)

    def mask(self, box, first: float = 0.0, start: float | None = None) -> None:
        """The frames fed from now on have ``box`` (x, y, w, h, source pixels) masked: an overlay.
        Earlier 'moving object' flags whose blocks all lie in the overlays' boxes were the text's
        own steps, before it was recognised: they are taken back."""
        import cv2

        self.masked.append((tuple(int(v) for v in box), round(float(first), 4)))
        self.masked_from.append(round(float(first if start is None else start), 4))
        hits = self._object_hits
        if not hits or self._bad_geometry is None:
            return
        shape = hits[0][1].shape
        hidden = _box_blocks(self._bad_geometry, shape, [b for b, _ in self.masked])
        near = cv2.dilate(hidden.astype(np.uint8), np.ones((3, 3), np.uint8)).astype(bool)
        kept = [(t, b) for t, b in hits if b.shape != shape or (b & ~near).any()]
        if len(kept) == len(hits):
            return
        self._object_hits = kept
        self.spans["moving object"] = []
        for t, _ in kept:
            self._mark("moving object", t)

    def gap(self, start: float, end: float) -> None:
        """Frames are missing between ``start`` and ``end`` (the times of the frames either side)."""
        spans = self.spans["frame gap"]
        if len(spans) >= MAX_SPANS:
            spans[-1][1] = end
        else:
            spans.append([round(float(start), 4), round(float(end), 4)])

    # ------------------------------------------------------------------ per frame
    def update(self, t: float, planes) -> None:
        """Watch the frame at time ``t`` for a cut, and check it in full unless one was checked
        less than 1/CHECK_RATE s before (and nothing suspect was seen since)."""
        from wallcli.signal.blocks import one_opencv_thread

        self.seen += 1
        if self.roi is not None and min(self.roi[2], self.roi[3]) < MIN_CROP \
                and tuple(self.roi[2:]) != (planes.width, planes.height):
            # the images would be the whole frame's (image._crop): what the analysis reads is unchecked
            if t - self._t_checked >= 1.0 / CHECK_RATE - 1e-3:
                self._t_checked = t
                self.frames += 1
                self._mark("too small to check", t)
            return
        due = self._cut.due(t)
        if not due and self._idle(t):
            return  # most frames of a calm view: nothing is read of them
        # these images are too small for OpenCV's pool's hand-offs to pay (blocks.one_opencv_thread)
        with one_opencv_thread():
            cut = None
            if due:
                cut, busy = self._cut(t, planes, self.roi)
                if busy:
                    self._dense_until = t + DENSE
            if cut is not None:
                self._mark("scene cut", cut)
                self._cut_reset = True
            if self._idle(t):
                return
            self._t_checked = t
            self._update(t, planes)

    def _idle(self, t: float) -> bool:
        """Whether the frame at ``t`` goes unchecked: one was checked less than 1/CHECK_RATE s
        before, and nothing suspect (nor a cut) was seen since."""
        return t - self._t_checked < 1.0 / CHECK_RATE - 1e-3 and t > self._dense_until and not self._cut_reset

    def _update(self, t: float, planes) -> None:
        import cv2

        small, w = _grey(planes, self.roi, MAX_SIDE)
        self._scale = 1.0 / (small.shape[1] / w)
        full = small.shape
        small = _whole_blocks(small)
        bh, bw = (n // _block_side(small.shape) for n in small.shape)
        blocks = cv2.resize(small, (bw, bh), interpolation=cv2.INTER_AREA)
        if float(small.max()) >= CLIP_HI:
            clipped = cv2.resize((small >= CLIP_HI).astype(np.float32), (bw, bh), interpolation=cv2.INTER_AREA) > 0.01
        else:
            clipped = np.zeros(blocks.shape, bool)
        dark = (blocks < DARK) & ~clipped
        ok = ~(clipped | dark)
        self._note_bad(~ok, full, small.shape)
        # an overlay's box (burned-in text, masked in the frames) is neither wall nor fault: not judged
        hidden = _box_blocks(self._bad_geometry, ok.shape, [b for b, _ in self.masked]) if self.masked else None
        if hidden is not None and hidden.any() and not hidden.all():
            ok, clipped, dark = ok & ~hidden, clipped & ~hidden, dark & ~hidden
            usable = float(ok.sum()) / float((~hidden).sum())
        else:
            usable = np.count_nonzero(ok) / ok.size  # ok.mean(), to the bit
        self.min_usable = min(self.min_usable, usable)
        flags = set()
        if usable < MIN_USABLE:
            flags.add("too little usable area")
            if clipped.mean() >= (1 - MIN_USABLE) / 2:
                flags.add("clipped")
            if dark.mean() >= (1 - MIN_USABLE) / 2:
                flags.add("too dark")
        # registration reads a band: finer is mostly noise and codec residue, coarser is light
        hp = cv2.GaussianBlur(small, (0, 0), 1.5) - _broad_blur(small, 8.0)
        if self._prev_b is None or self._cut_reset:
            self._reset(hp, small, blocks, planes, full)
            self._cut_reset = False
        else:
            flags |= self._changes(t, blocks, hp, ok, small, clipped, planes, full)
        self._prev_b, self._prev_h, self._t_prev = blocks, hp, t
        self.frames += 1
        for kind in flags:
            self._mark(kind, t)

    def _note_bad(self, bad: np.ndarray, full: tuple[int, int], cropped: tuple[int, int]) -> None:
        """OR ``bad`` (per block) into the clip's map, and remember where the blocks lie: the
        block grid tiles the centre of the downscaled frame (see _whole_blocks)."""
        if self._bad is None or self._bad.shape != bad.shape:
            self._bad = np.zeros(bad.shape, bool)
            side = _block_side(cropped)
            x0, y0 = (self.roi[0], self.roi[1]) if self.roi is not None else (0, 0)
            sh, sw = full
            self._bad_geometry = (x0, y0, side, (sh - cropped[0]) // 2, (sw - cropped[1]) // 2, self._scale)
        self._bad |= bad

    def avoid(self, roi, rows: int, cols: int) -> np.ndarray:
        """(rows, cols) bool: the cells of a grid over ``roi`` (x, y, w, h in source pixels) that
        overlap a block where the view failed on some checked frame (clipped, too dark, or a
        moving object in it). A whole-frame failure (camera motion, a cut) marks no cell: no
        part of the frame escapes it."""
        rects = [(x, x + w, y, y + h) for (x, y, w, h), _ in self.masked]  # an overlay's box is no wall
        if self._bad is not None and self._bad.any():
            rects += _block_rects(self._bad_geometry, np.nonzero(self._bad))
        return _cells(rects, roi, rows, cols)

    def _reset(self, hp, small, blocks, planes, full) -> None:
        self._dense_until = max(self._dense_until, self._t_checked + DENSE)  # neighbours' noise first
        self._ref_h, self._bg_h, self._bg_b = hp, _highpass(small, FINE), blocks.copy()
        self._ref_w = None  # the reference windowed for the phase correlation
        self._tex = _relative_texture(small, self._bg_h)
        self._ref_rel = _in_band(hp, small, self._bg_h, self._tex)
        self._ref_fine = self._tex
        self._bg_c = _chroma(planes, self.roi, blocks, full)
        self._bg_n = 1
        self._t_tex, self._t_match = self._t_checked, -np.inf  # how registrable: from the next check
        self._match.clear()  # a new view (a cut): how registrable it is is its own
        self._match_fine.clear()

    def _changes(self, t, blocks, hp, ok, small, clipped, planes, full) -> set:
        import cv2

        flags = set()
        if not ok.any():
            return flags
        suspect = False
        # the noise is measured between neighbouring frames only: between checks a fifth of a
        # second apart a shake or a shadow has moved the picture too, and the thresholds built
        # on such a 'noise' let exactly those through
        gap = t - self._t_prev
        self._gap = min(self._gap, gap)
        if gap <= 1.5 * self._gap or not self._sig_b:
            self._sig_b.append(_robust_sigma((blocks - self._prev_b)[ok]))
            self._sig_h.append(_robust_sigma(_inner_difference(hp, self._prev_h, 4)) ** 2 if min(hp.shape) > 8 else 0.0)
        # statistics' median of these Python floats is numpy's to the bit, at a tenth of the cost
        sigma = max(statistics.median(self._sig_b), SIGMA_FLOOR)
        var_h = max(statistics.median(self._sig_h), SIGMA_FLOOR ** 2)
        level = np.maximum(blocks, DARK)
        # camera motion: a shift of the frame's fine structure against the reference frame that
        # explains more of the change than the noise could
        if min(hp.shape) < 2:
            # a frame one sample thin at the check's scale (4000x16, 1x1000) has no second dimension
            # to register on (OpenCV's window needs two): its motion cannot be judged, so say so
            flags.add("too thin to check")
            dx = dy = 0.0
        elif min(hp.shape) < MIN_REGISTER_SIDE:
            # no structure to register a shift on: a pan would pass as still, so say it was not checked
            flags.add("too small to check")
            dx = dy = 0.0
        else:
            if self._window is None or self._window.shape != hp.shape:
                self._window = cv2.createHanningWindow(hp.shape[::-1], cv2.CV_32F)
                self._ref_w = None
            # windowed here (OpenCV's own product, to the bit), the reference once until the next
            # reset: OpenCV would window copies of both on every check
            if self._ref_w is None:
                self._ref_w = self._ref_h * self._window
            (dx, dy), _ = cv2.phaseCorrelate(self._ref_w, hp * self._window)
        shift = float(np.hypot(dx, dy)) * self._scale
        moved = False
        # a shift of half the floor that fits is not motion yet, but a shake on its way to it:
        # every frame is then checked (see CHECK_RATE), as the old every-frame check did
        if shift >= MIN_SHIFT / 2 and min(hp.shape) >= MIN_REGISTER_SIDE:
            fits = _shift_fits(self._ref_h, hp, dx, dy, var_h)
            # and it must hold from one frame to the next: a camera moves smoothly, while the
            # correlation peaks of noise land anywhere
            suspect |= fits
            fits &= shift >= MIN_SHIFT
            if fits:
                # within a pixel, or half the shift: a shake of a few pixels moves that far between
                # checks (3 px rms shakes passed as still with a 1 px tolerance)
                near = [1 for x, y in self._shifts if np.hypot(dx - x, dy - y) * self._scale < max(1.0, 0.5 * shift)]
                moved = len(near) + 1 >= HOLD
            self._shifts.append((dx, dy) if fits else (np.inf, np.inf))
        else:
            self._shifts.append((np.inf, np.inf))
        # the wall's own texture, relative to its level, where nothing changed: still in its
        # place (the learnt texture at no shift) if the camera did not move, whatever light did
        # Python floats, not numpy's float64: the blends below then stay float32 (a float64 scalar
        # made each a float64 image and a rounding copy)
        a = 1.0 - math.exp(-max(float(t - self._t_prev), 1e-3) / 2.0)  # 2 s: a mover that stops fades out
        g = _median(blocks[ok] / np.maximum(self._bg_b[ok], 1e-3))
        dev = np.abs(blocks - g * self._bg_b)
        broad = dev > np.maximum(K_MOVER * sigma, REL * level)
        fine = _highpass(small, FINE)
        # something in view: a block far brighter or darker than its slow background (beyond
        # the noise and beyond any hidden person's few per cent) whose fine structure changed
        # too (an object's outline), by a fair part of the step it bounds (SHARP); a hidden
        # person's shadow, even a hard one from a window, has edges blurred by its penumbra and
        # changes the fine scale far less for its step
        # until it has 2 s of frames, the background is their plain mean: one frame's noise (the
        # first is often the codec's intra frame, coded unlike the rest) is not the wall's
        self._bg_n += 1
        a = max(a, 1.0 / self._bg_n)
        changed = broad & ok
        anything = bool(changed.any())
        if anything:
            # light falling on the wall scales its texture with it: compare with the background's
            # texture scaled by each block's change of level, so a shadow's dimming is not an outline
            scale = cv2.resize(blocks / np.maximum(g * self._bg_b, 1.0), fine.shape[::-1], interpolation=cv2.INTER_LINEAR)
            energy = cv2.resize((fine - scale * self._bg_h) ** 2, blocks.shape[::-1], interpolation=cv2.INTER_AREA)
            edge = np.sqrt(energy)
            step = cv2.dilate(np.where(ok, dev, 0.0).astype(np.float32), np.ones((3, 3), np.uint8))
            n = max(_block_side(small.shape) ** 2 / 4.0, 1.0)
            noise = _upper_median(edge[ok]) * (1.0 + K_EDGE / np.sqrt(2.0 * n))
            floor = np.maximum(REL_EDGE * np.maximum(blocks, EDGE_LEVEL), noise)
            hit = changed & (edge > floor) & (edge > SHARP * step)
        else:  # no block changed (a calm view, most checks): no outline to look for
            hit = changed
        # a bright object saturates: blocks clipped now whose background was well inside the usable
        # range (a rise of over 2 x REL, no hidden person's) are blocks something covered; the
        # rules above never see them, as clipped blocks are not 'ok'
        covered = broad & clipped & (g * self._bg_b * (1 + 2 * REL) < CLIP_HI)
        # the texture relative to the level (which light does not change), where it is needed:
        # to verify a shift, to judge an outline, and a few times a second to learn it (the
        # checks in between, every frame after anything suspect, do without: it is most of the
        # check's cost on a wall with moving shadows)
        learn_due = t - self._t_tex >= 1.0 / MATCH_RATE - 1e-3
        history_due = t - self._t_match >= 1.0 / MATCH_RATE - 1e-3
        outlined = anything and not moved and int(hit.sum()) >= MIN_MOVER_BLOCKS
        rel = _relative_texture(small, fine) if moved or outlined or learn_due or history_due else None
        if moved or history_due:
            still = _pixels(ok & ~broad, rel.shape)
            # two bands: the finest texture tells small shifts apart best but is what a codec keeps
            # least; the registration band (where the shift was found) is kept, but smooth
            bands = ((rel, self._ref_fine, self._match_fine), (_in_band(hp, small, fine, rel), self._ref_rel, self._match))
            matches = [_texture_match(x, ref, still) for x, ref, _ in bands]
            if moved:
                verdict = _motion_verdict(bands, matches, still, dx, dy)
                if verdict is None:
                    flags.add("motion not verifiable")
                    # the shift measured, unverified: max_shift_px 0 read as 'did not move'
                    self.max_shift = max(self.max_shift, shift)
                elif verdict:
                    flags.add("camera motion")
                    self.max_shift = max(self.max_shift, shift)
                else:
                    moved = False
                    self._shifts[-1] = (np.inf, np.inf)
            elif history_due:
                self._t_match = t
                for (_, _, history), match in zip(bands, matches):
                    if match is not None:
                        history.append(match)
        # the outline says only that the change is sharp; whether it is light or a thing is read
        # inside it, on the wall's texture relative to its level (which light does not change)
        chroma = _chroma(planes, self.roi, blocks, full) if self._bg_c is not None and (outlined or learn_due) else None
        judged = hit
        if anything and not moved and int(hit.sum()) >= MIN_MOVER_BLOCKS:  # outlined, or a shift taken back
            ratio = blocks / np.maximum(g * self._bg_b, 1e-3)
            judged, light = _objects(t, hit, changed, ok, rel, ratio, chroma, self._tex, self._bg_b, self._bg_c,
                                     self.trace)
            if light:
                self._mark_note("sharp light", t)
        judged = judged | covered
        if not moved and int(judged.sum()) >= MIN_MOVER_BLOCKS:
            flags.add("moving object")
            self._bad |= judged
            if self._object_hits is not None:
                self._object_hits.append((t, judged.copy()))
                if len(self._object_hits) > MAX_OBJECT_HITS:  # memory stays flat: no taking back from now on
                    self._object_hits = None
        # every frame for a while after anything suspect; a sharp change of light is not
        if suspect or moved or judged.any() or (anything and not outlined):
            self._dense_until = t + DENSE
        # in place, in float32 (a is a Python float): a full-size temporary less each
        bg_h = self._bg_h * (1 - a)
        bg_h += a * fine
        self._bg_h = bg_h
        self._bg_b = (1 - a) * self._bg_b + a * blocks / max(g, 1e-3)
        # the wall's texture: learnt where nothing changed, slower than the background (a shadow
        # that stays is learnt through, an object that stops is learnt like the background)
        if not learn_due:
            return flags
        calm = _pixels(~broad & ok, rel.shape)
        b = max(1.0 - math.exp(-max(float(t - self._t_tex), 1e-3) / TEX_TAU), 1.0 / self._bg_n)
        self._t_tex = t
        tex = self._tex
        learn = calm & np.isfinite(rel)  # an unknown pixel (an edge) keeps what was learnt
        blend = tex * (1 - b)  # float32: b is a Python float
        blend += b * rel
        self._tex = np.where(learn, np.where(np.isfinite(tex), blend, rel), tex)
        if chroma is not None:
            keep = ~broad & ok
            self._bg_c = np.where(keep, (1 - b) * self._bg_c + b * chroma, self._bg_c)
        return flags


    def _mark_note(self, kind: str, t: float) -> None:
        self._mark(kind, t, self.note_spans)

    def _mark(self, kind: str, t: float, where: dict | None = None) -> None:
        spans = (self.spans if where is None else where)[kind]
        if spans and (t - spans[-1][1] < 0.5 or len(spans) >= MAX_SPANS):
            spans[-1][1] = t
        else:
            spans.append([t, t])

    # ------------------------------------------------------------------ verdicts
    def view(self, start: float | None = None, end: float | None = None) -> dict:
        """``{"usable", "issues", "reason", "notes"}`` over [start, end] seconds (the whole clip: no
        bounds). Notes say what was seen that is no view fault (sharp light on the wall)."""
        lo = -np.inf if start is None else start
        hi = np.inf if end is None else end
        found = {k: [s for s in spans if s[1] >= lo and s[0] <= hi] for k, spans in self.spans.items()}
        # a gap is the time strictly between the frames either side: a window cut on one side of
        # it (no window spans one: signal.window) starts on the frame after it, or ends its nominal
        # one grid step (1/30 s) after the frame before it, and has lost nothing
        found["frame gap"] = [s for s in found["frame gap"] if s[1] > lo + GAP_EDGE and s[0] < hi - GAP_EDGE]
        issues = [k for k, s in found.items() if s]
        refused = [k for k in issues if k not in NOT_REFUSED]
        if self.frames == 0:
            return {"usable": False, "issues": ["too little usable area"], "reason": "no frame was checked", "notes": []}
        reason = None
        if refused:
            unchecked = ("too thin to check", "too small to check")  # what the check could not do
            parts = [f"{k} at {_spans_text(found[k])}" for k in refused if k != "frame gap" and k not in unchecked]
            reason = "; ".join((["not a static view of the wall: " + "; ".join(parts)] if parts else [])
                               + [KINDS[k] for k in refused if k in unchecked]
                               + ([f"frames missing at {_spans_text(found['frame gap'])}"]
                                  if "frame gap" in refused else []))
        notes = [f"{NOTES[k]} (at {_spans_text(s)})" for k, spans in self.note_spans.items()
                 if (s := [x for x in spans if x[1] >= lo and x[0] <= hi])]
        notes += [f"{KINDS[k]} (at {_spans_text(found[k])})" for k in issues if k in NOT_REFUSED]
        return {"usable": not refused, "issues": issues, "reason": reason, "notes": notes}

    def record(self) -> dict:
        """What :meth:`view` and :meth:`summary` answer from, as JSON (a .npz plot's metadata
        keeps it, so answers read from the plot carry the verdict of the video's check)."""
        return {"spans": {k: [list(s) for s in v] for k, v in self.spans.items()}, "frames": self.frames,
                "max_shift": self.max_shift, "min_usable": self.min_usable, "masked": [[list(b), f, s] for (b, f), s in zip(self.masked, self.masked_from)],
                "noise": float(np.median(self._sig_b)) if self._sig_b else None}

    @classmethod
    def restore(cls, record: dict) -> "ViewCheck":
        """A check that answers as the one whose :meth:`record` this is (nothing more is fed to it)."""
        check = cls()
        spans = record.get("spans") or {}
        for kind in check.spans:  # kinds of a newer wallcli are not this one's to judge
            check.spans[kind] = [[float(a), float(b)] for a, b in spans.get(kind, [])]
        check.frames = int(record.get("frames") or 0)
        check.max_shift = float(record.get("max_shift") or 0.0)
        check.min_usable = float(record.get("min_usable", 1.0))
        check._object_hits = None  # the spans recorded are final
        for box, first, *start in record.get("masked") or []:
            check.mask(box, first, *start[:1])
        if record.get("noise") is not None:
            check._sig_b.append(float(record["noise"]))
        return check

    def summary(self) -> dict:
        """The clip's view and what it was judged on (extra fields of the JSON's ``view``)."""
        noise = float(np.median(self._sig_b)) if self._sig_b else None
        return {**self.view(), "gaps": [list(s) for s in self.spans["frame gap"]],
                "frames": self.frames, "max_shift_px": round(self.max_shift, 2),
                "min_usable_area": round(self.min_usable, 3),
                "noise": None if noise is None else round(noise, 4), "masked": merged([(b, f, s) for (b, f), s in zip(self.masked, self.masked_from)])}


def _spans_text(spans: list) -> str:
    shown = ", ".join(span_text(a, b) for a, b in spans[:3])
    return shown + (f" and {len(spans) - 3} more" if len(spans) > 3 else "")