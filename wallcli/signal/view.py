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

from collections import deque

import numpy as np

MAX_SIDE = 320  # registration scale: finer texture than this is not needed to see a pan
BLOCKS = 40  # blocks along the long side for movers and cuts: a person in view covers several
K_MOVER = 8.0  # a block changed by this many noise sigmas (and REL) from its slow background
REL_EDGE = 0.10  # whose fine structure changed by an RMS over this fraction of the level
FINE = 2.0  # pixels (at the registration scale): the outline's scale
EDGE_LEVEL = 40.0  # code values: under it, the level floor (noise, not contrast, rules dark walls)
K_CUT = 8.0
REL = 0.05  # of the local level: above any hidden person's shadow
REL_CUT = 0.02  # one frame to the next: a shadow moves, it does not change a fifth of the wall at once
CUT_FRACTION = 0.2  # of the usable blocks (simulated walls: at most 1.5 %; cuts between two: 40 % and more)
CUT_CALM = 0.1  # the frames before and after a cut (a codec settling after one, a shadow: up to 9 %)
MIN_MOVER_BLOCKS = 2
MIN_SHIFT = 1.5  # source pixels from the reference frame
K_SHIFT = 3.0  # z-score of the shift's fit against its mirror image (see _changes), held over
HOLD, HOLD_WITHIN = 3, 8  # agreeing frames among the last few: the phase correlation picks the best
# of many shifts, so noise alone scores a few, but its peaks land anywhere; on a noisy wall the
# true peak wins only in some frames, so agreement is asked of 3 of 8, not of 3 in a row
DARK = 10.0  # 8-bit code values: 1 % of the level is then a tenth of a quantisation step
CLIP_HI = 250.0
MIN_USABLE = 0.5  # of the frame's area, neither clipped nor dark
SIGMA_FLOOR = 0.02  # code values: a frozen (repeated) frame has no measurable noise
HISTORY = 64  # frames whose noise estimates are pooled (a median: a cut or a mover does not move it)
MAX_SPANS = 64  # per kind; more are merged, so memory stays bounded

KINDS = {
    "camera motion": "the camera moved",
    "moving object": "something moved in view",
    "scene cut": "the shot changes",
    "clipped": "much of the frame is clipped",
    "too dark": "much of the frame is too dark",
    "too little usable area": "too little of the frame is usable",
}


def _shrink(a: np.ndarray, size: tuple[int, int]) -> np.ndarray:
    """A plane (native integer codes) as float32 at ``size`` (w, h), by area averaging. A large
    plane is first halved, in its own integer type, while it stays at least twice the size
    (OpenCV's 2x2 area path takes 0.07 ms for 1080p; rounding there adds 0.3 codes of noise to
    averages whose noise the thresholds measure anyway): converting every full-size pixel to float
    made the check slower than the decode itself."""
    import cv2

    while a.dtype in (np.uint8, np.uint16) and a.shape[1] >= 4 * size[0] and a.shape[0] >= 4 * size[1]:
        h, w = a.shape
        a = cv2.resize(a[:h - h % 2, :w - w % 2], (w // 2, h // 2), interpolation=cv2.INTER_AREA)
    a = a.astype(np.float32)
    return a if a.shape[::-1] == tuple(size) else cv2.resize(a, size, interpolation=cv2.INTER_AREA)


def _grey(planes, roi, max_side: int) -> tuple[np.ndarray, int]:
    """Luma of the frame (or its ROI) as float32 on the 0-255 scale, at most ``max_side`` pixels
    on its long side (what the wall's level is judged on), and the source width it stands for."""
    def crop(a):
        if roi is None:
            return a
        x, y, w, h = roi
        c = a[y:y + h, x:x + w]
        return c if min(c.shape) >= 8 else a  # a bad ROI is the reader's error to give

    Y = crop(planes.y)
    h, w = Y.shape
    s = min(1.0, max_side / max(h, w))
    size = (max(1, round(w * s)), max(1, round(h * s)))
    scale = float(1 << (planes.depth - 8))
    if planes.kind == "rgb":
        y = (0.299 * _shrink(Y, size) + 0.587 * _shrink(crop(planes.u), size) + 0.114 * _shrink(crop(planes.v), size)) / scale
        return y.astype(np.float32), w
    y = _shrink(Y, size) / np.float32(scale)
    if not planes.full_range:
        y = (y - np.float32(16.0)) * np.float32(255.0 / 219.0)
    return y, w


def _robust_sigma(d: np.ndarray) -> float:
    """Sigma of one image from a difference of two: the RMS of the smallest 90 % of |d|, scaled to
    a Gaussian's. Not the median: H.264 repeats static blocks exactly, so most differences of a
    compressed wall are 0 and the median says 'no noise'; the trimmed tail keeps a mover out."""
    if d.size == 0:
        return 0.0
    d = np.ravel(d)
    if d.size > 8192:  # a fixed stride of the image: as good an estimate for a tenth of the sorting
        d = d[:: d.size // 4096]
    a = np.abs(d - np.median(d))
    keep = a[a <= np.quantile(a, 0.9)]
    return float(np.sqrt(np.mean(keep.astype(np.float64) ** 2) / 0.623 / 2.0)) if keep.size else 0.0


def _highpass(img: np.ndarray, sigma: float = 4.0) -> np.ndarray:
    import cv2

    return img - cv2.GaussianBlur(img, (0, 0), sigma)


class ViewCheck:
    """Per-frame tests of the view, remembered as time spans per kind of issue.

    Call it with decoded frames (a :class:`wallcli.io.video.FrameTee` tap) or :meth:`update` with
    (time, planes). Nothing of the frame is kept but a few small downscaled images.
    """

    def __init__(self, roi=None) -> None:
        self.roi = roi  # (x, y, w, h): only what the analysis reads needs to be a still wall
        self.frames = 0
        self.spans: dict[str, list[list[float]]] = {k: [] for k in KINDS}
        self.max_shift = 0.0
        self.min_usable = 1.0
        self._sig_b: deque = deque(maxlen=HISTORY)
        self._sig_h: deque = deque(maxlen=HISTORY)
        self._prev_b = self._prev_h = self._ref_h = self._bg_h = self._bg_b = None
        self._t_prev = None
        self._scale = 1.0
        self._window = None
        self._fracs = (1.0, 1.0)  # changed shares of the last two frames (none calm before the first)
        self._shifts: deque = deque(maxlen=HOLD_WITHIN)  # recent significant shifts (inf: none)

    def __call__(self, frame) -> None:
        self.update(frame.time, frame.planes)

    # ------------------------------------------------------------------ per frame
    def update(self, t: float, planes) -> None:
        import cv2

        small, w = _grey(planes, self.roi, MAX_SIDE)
        h = small.shape[0] * w / small.shape[1]
        self._scale = 1.0 / (small.shape[1] / w)
        bw = BLOCKS if w >= h else max(4, round(BLOCKS * w / h))
        bh = max(4, round(bw * h / w))
        blocks = cv2.resize(small, (bw, bh), interpolation=cv2.INTER_AREA)
        clipped = cv2.resize((small >= CLIP_HI).astype(np.float32), (bw, bh), interpolation=cv2.INTER_AREA) > 0.01
        dark = (blocks < DARK) & ~clipped
        ok = ~(clipped | dark)
        usable = float(ok.mean())
        self.min_usable = min(self.min_usable, usable)
        flags = set()
        if usable < MIN_USABLE:
            flags.add("too little usable area")
            if clipped.mean() >= (1 - MIN_USABLE) / 2:
                flags.add("clipped")
            if dark.mean() >= (1 - MIN_USABLE) / 2:
                flags.add("too dark")
        # registration reads a band: finer is mostly noise and codec residue, coarser is light
        hp = cv2.GaussianBlur(small, (0, 0), 1.5) - cv2.GaussianBlur(small, (0, 0), 8.0)
        if self._prev_b is None:
            self._reset(hp, small, blocks)
        else:
            flags |= self._changes(t, blocks, hp, ok, small)
        self._prev_b, self._prev_h, self._t_prev = blocks, hp, t
        self.frames += 1
        for kind in flags:
            self._mark(kind, t)

    def _reset(self, hp, small, blocks) -> None:
        self._ref_h, self._bg_h, self._bg_b = hp, _highpass(small, FINE), blocks.copy()

    def _changes(self, t, blocks, hp, ok, small) -> set:
        import cv2

        flags = set()
        if not ok.any():
            return flags
        prev = self._prev_b
        d = blocks - prev
        self._sig_b.append(_robust_sigma(d[ok]))
        self._sig_h.append(_robust_sigma((hp - self._prev_h)[4:-4, 4:-4]) ** 2 if min(hp.shape) > 8 else 0.0)
        sigma = max(float(np.median(self._sig_b)), SIGMA_FLOOR)
        var_h = max(float(np.median(self._sig_h)), SIGMA_FLOOR ** 2)
        level = np.maximum(blocks, DARK)
        # a cut: much of the frame changes from one frame to the next, beyond a whole-frame gain
        # (exposure, flicker), with calm frames on either side (a hard shadow sweeping the wall
        # changes as much, but over several frames); judged one frame late, on the previous one
        gain = float(np.median(blocks[ok] / np.maximum(prev[ok], 1e-3)))
        jump = np.abs(blocks - gain * prev) > np.maximum(K_CUT * sigma * np.sqrt(2.0), REL_CUT * level)
        frac = float(jump[ok].mean())
        before = self._fracs
        self._fracs = (before[1], frac)
        if before[1] > CUT_FRACTION and before[0] < CUT_CALM and frac < CUT_CALM:
            self._mark("scene cut", self._t_prev)
            self._reset(hp, small, blocks)
            return flags
        # camera motion: a shift of the frame's fine structure against the reference frame that
        # explains more of the change than the noise could
        if self._window is None or self._window.shape != hp.shape:
            self._window = cv2.createHanningWindow(hp.shape[::-1], cv2.CV_32F)
        # copies: OpenCV applies the window to its inputs in place
        (dx, dy), _ = cv2.phaseCorrelate(self._ref_h.copy(), hp.copy(), self._window)
        shift = float(np.hypot(dx, dy)) * self._scale
        moved = False
        if shift >= MIN_SHIFT and min(hp.shape) > 32:  # smaller: no structure to register on
            # the reference moved by +s must fit far better than moved by -s: both warps smooth
            # its noise alike, so only a real shift of shared structure separates them; the
            # spread of the difference of two means of N squared residuals is e*sqrt(8/N), N
            # counted as a quarter of the pixels (interpolation and compression correlate them).
            # e is the residual itself, not the frame-to-frame noise: a codec that repeats static
            # blocks makes consecutive frames alike but not the reference's texture
            c = slice(8, -8)
            e = []
            for sg in (1, -1):
                m = np.float32([[1, 0, sg * dx], [0, 1, sg * dy]])
                warped = cv2.warpAffine(self._ref_h, m, hp.shape[::-1], borderMode=cv2.BORDER_REFLECT)
                e.append(float(np.mean((hp - warped)[c, c] ** 2)))
            n = hp[c, c].size / 4
            fits = (e[1] - e[0]) > K_SHIFT * max(e[0], var_h) * np.sqrt(8.0 / n)
            # and it must hold from one frame to the next: a camera moves smoothly, while the
            # correlation peaks of noise land anywhere
            if fits:
                near = [1 for x, y in self._shifts if np.hypot(dx - x, dy - y) * self._scale < 1.0]
                moved = len(near) + 1 >= HOLD
            self._shifts.append((dx, dy) if fits else (np.inf, np.inf))
        else:
            self._shifts.append((np.inf, np.inf))
        if moved:
            flags.add("camera motion")
            self.max_shift = max(self.max_shift, shift)
        # something in view: a block far brighter or darker than its slow background (beyond
        # the noise and beyond any hidden person's few per cent) whose fine structure changed
        # too (an object's outline); a hidden person's shadow, even a hard one from a window, has
        # edges blurred by its penumbra and changes the fine scale far less
        a = 1.0 - np.exp(-max(t - self._t_prev, 1e-3) / 2.0)  # 2 s: a mover that stops fades out
        g = float(np.median(blocks[ok] / np.maximum(self._bg_b[ok], 1e-3)))
        broad = np.abs(blocks - g * self._bg_b) > np.maximum(K_MOVER * sigma, REL * level)
        fine = _highpass(small, FINE)
        # light falling on the wall scales its texture with it: compare with the background's
        # texture scaled by each block's change of level, so a shadow's dimming is not an outline
        scale = cv2.resize(blocks / np.maximum(g * self._bg_b, 1.0), fine.shape[::-1], interpolation=cv2.INTER_LINEAR)
        energy = cv2.resize((fine - scale * self._bg_h) ** 2, blocks.shape[::-1], interpolation=cv2.INTER_AREA)
        hit = broad & (np.sqrt(energy) > REL_EDGE * np.maximum(blocks, EDGE_LEVEL)) & ok
        if not moved and int(hit.sum()) >= MIN_MOVER_BLOCKS:
            flags.add("moving object")
        self._bg_h = ((1 - a) * self._bg_h + a * fine).astype(np.float32)
        self._bg_b = ((1 - a) * self._bg_b + a * blocks / max(g, 1e-3)).astype(np.float32)
        return flags

    def _mark(self, kind: str, t: float) -> None:
        spans = self.spans[kind]
        if spans and (t - spans[-1][1] < 0.5 or len(spans) >= MAX_SPANS):
            spans[-1][1] = t
        else:
            spans.append([t, t])

    # ------------------------------------------------------------------ verdicts
    def view(self, start: float | None = None, end: float | None = None) -> dict:
        """``{"usable", "issues", "reason"}`` over [start, end] seconds (the whole clip: no bounds)."""
        lo = -np.inf if start is None else start
        hi = np.inf if end is None else end
        found = {k: [s for s in spans if s[1] >= lo and s[0] <= hi] for k, spans in self.spans.items()}
        issues = [k for k, s in found.items() if s]
        if self.frames == 0:
            return {"usable": False, "issues": ["too little usable area"], "reason": "no frame was checked"}
        reason = None
        if issues:
            parts = [f"{k} at {_spans_text(found[k])}" for k in issues]
            reason = "not a static view of the wall: " + "; ".join(parts)
        return {"usable": not issues, "issues": issues, "reason": reason}

    def summary(self) -> dict:
        """The clip's view and what it was judged on (extra fields of the JSON's ``view``)."""
        noise = float(np.median(self._sig_b)) if self._sig_b else None
        return {**self.view(), "frames": self.frames, "max_shift_px": round(self.max_shift, 2),
                "min_usable_area": round(self.min_usable, 3),
                "noise": None if noise is None else round(noise, 4)}


def _spans_text(spans: list) -> str:
    shown = ", ".join(f"{a:.1f}-{b:.1f} s" if b > a else f"{a:.1f} s" for a, b in spans[:3])
    return shown + (f" and {len(spans) - 3} more" if len(spans) > 3 else "")
