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

import statistics
from collections import deque

import numpy as np

from wallcli.wording import span_text

MAX_SIDE = 320  # registration scale: finer texture than this is not needed to see a pan
BLOCKS = 40  # blocks along the long side for movers and cuts: a person in view covers several
K_MOVER = 8.0  # a block changed by this many noise sigmas (and REL) from its slow background
REL_EDGE = 0.05  # whose fine structure changed by an RMS over this fraction of the level (REL: no
# hidden person changes the wall by that much, outline or not)
K_EDGE = 4.0  # and this many spreads above the frame's median block residual (its noise, texture
# and codec residue in the fine band): the RMS of n pixels spreads by about median/sqrt(2 n), n
# counted as a quarter of the block's pixels (see K_SHIFT); a block of a 96-pixel-wide frame is 2x2
# pixels, of a 320-pixel one 8x8 (three refused some transfer-set walls as movers; six
# missed a 40-60 % sprite on a dark noisy wall that four catches)
SHARP = 0.15  # and over this fraction of the step it bounds (the largest change among the block and
# its 8 neighbours): an in-focus outline (blurred by a pixel or less) puts 0.09-0.11 of its step into
# the fine band on its own and the wall texture it hides adds to that (simulated objects: 0.2 and
# more), a penumbra of 4 px or more puts under 0.05; deep simulated shadows (half the level) reached
# 0.13 with the codec's re-coding residue on top. Session 17 (research/view/README.md):
# with a floor of 10 % of the level alone, faint objects (15-40 % contrast) were caught a quarter of
# the time, while hard shadows of people 1-2 m from the wall (half the level, the codec re-coding
# them) were refused as movers; these three together catch more of the one and none of the other
FINE = 2.0  # pixels (at the registration scale): the outline's scale
EDGE_LEVEL = 40.0  # code values: under it, the level floor (noise, not contrast, rules dark walls)
K_CUT = 8.0
REL = 0.05  # of the local level: above any hidden person's shadow
REL_CUT = 0.02  # one frame to the next: a shadow moves, it does not change a fifth of the wall at once
CUT_FRACTION = 0.2  # of the usable blocks (simulated walls: at most 1.5 %; cuts between two: 40 % and more)
CUT_SIDE = 160  # samples along the long side for the cut watch (4x4 per block at 16:9)
CUT_RATE = 15.0  # frames a second the cut watch compares (every other frame at 30 fps): a cut is
# one jump between any two of them, while a sweeping shadow changes a sample pair 2 frames apart
# by a third of what 6 frames (a full check's spacing) did on the walls measured
CUT_CALM = 0.1  # the frames before and after a cut (a codec settling after one, a shadow: up to 9 %)
# A cut between two views of alike walls can change under a fifth of the blocks by 2 %: most of the
# change is then the frame's gain, which is divided out, and a little of its spatial pattern. What is
# left is coarse (the other room's shading) and comes in one step, while the codec's re-coding is
# fine-grained and a person's light changes over many frames. So the gain-free step is also read on
# CUT_CELLS cells along the long side, as an RMS relative to the level: a cut is a step CUT_SPIKE
# times the clip's median step and each of the CUT_REACH steps on either side, and over REL_CUT / 2
# (no hidden person changes that much of the wall's pattern between two samples). Session 18
# (research/view/README.md): steps over the floor reached at most 2.7 times on 220 walls; the 15
# cuts the changed share missed, 2.0-48 times (13 over 4)
CUT_CELLS = 8
CUT_SPIKE = 4.0
CUT_REACH = 2
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
CHECK_RATE = 3.0  # frames checked per second of a calm view: checking every frame cost more than
# the analysis itself (3-5 ms a 1080p frame against about 3 for decoding and the plots;
# bench/RESULTS.md). After a check that finds anything suspect (a shift that fits, a block far off
# its background; or a frame of the cut watch with a large changed share) every frame is checked
# for DENSE seconds, so the rules that ask for agreement between neighbouring frames (a shake's
# shifts) and a mover's outline get every frame's chance, as before
DENSE = 0.5
MATCH_RATE = 1.0  # checks a second that learn the texture and colour and measure how registrable the
# wall is (see REGISTRABLE): each is a few tenths of a ms, and light and texture change slowly

TEX_TAU = 4.0  # seconds: the wall's texture is learnt where nothing changed, over this time
EDGE_GRAD = 0.02  # of the level a pixel, at the outline's scale FINE: a step of 10 % (a wall's texture
# of a few per cent a pixel, blurred by FINE, stayed under 0.9 % on the bundled examples)
K_OUTLIER = 3.0  # RMS of the calm blocks: beyond it a pixel of either texture is an edge, not texture
# A region is an object when (any of):
# - the wall's texture is gone: its regression on the learnt texture is under KEPT of the calm
#   blocks' by K_TEX standard errors (with MIN_KNOWN blocks' worth of pixels that are no edge).
#   Not a half: a compressed wall's calm blocks are copied from frame to frame, frozen noise and
#   all, while the codec re-codes a moving shadow and keeps a tenth to a half of the texture there
#   (sharp-shadow walls at CRF 18: 0.1-0.4; the same walls lossless: all of it);
# - it is flat: FLAT_SHARE % of its blocks hold under FLAT of the calm blocks' relative fine
#   energy (at their level): neither the wall's texture nor the noise that light brings;
# - its colour ratios moved by over COLOUR (on COLOUR_BLOCKS blocks or more, of a background level
#   of COLOUR_LEVEL or more: a small deep shadow under two lights of other colours moved them by up
#   to 0.25, a shadow taking half the light of a room lit in two colours by 0.10, and on a wall of
#   level 30 a ratio's quantisation alone is 0.03). On the simulator's objects it adds next to
#   nothing to the two rules above; it is there for real objects on walls with no texture.
# Chosen on session 19's first 16 rounds (research/view/README.md); COLOUR_LEVEL and COLOUR 0.15
# after false alarms of the whole sample were seen (walls of level 30; the half-light shadow).
MIN_KNOWN = 4
KEPT = 0.1
K_TEX = 4.0
FLAT, FLAT_SHARE = 0.02, 10
COLOUR, COLOUR_BLOCKS, COLOUR_LEVEL = 0.15, 4, 60.0
NOTES = {"sharp light": "sharp shadow or light in view: a person near the wall or a small light"}

REGISTRABLE = 8.0  # standard errors: the best texture match with the reference frame (see
# _texture_match; in place, or moved by the shift found) over the last checks, of a wall whose
# camera motion can be verified: under it the texture is under the
# noise, and a shift the correlation finds is no proof
SHIFT_Z = 3.0  # standard errors by which the reference moved by the shift must fit better than in place
# (session 19: four still walls had the finest band's two within 0.3-1.5 and the other band's reversed)
NOT_REFUSED = ("motion not verifiable",)  # issues that say what could not be checked; answers stand

KINDS = {
    "camera motion": "the camera moved",
    "motion not verifiable": "the wall has no texture to register on: whether the camera moved is not known",
    "moving object": "something moved in view",
    "scene cut": "the shot changes",
    "clipped": "much of the frame is clipped",
    "too dark": "much of the frame is too dark",
    "too little usable area": "too little of the frame is usable",
    "too thin to check": "the frame is too thin to check for camera motion",
    # not the view's fault but the file's: frames lost (their timestamps jump, io.video.GAP_FACTOR);
    # nothing spanning it is continuous video
    "frame gap": "frames are missing",
}


def _shrink(a: np.ndarray, size: tuple[int, int]) -> np.ndarray:
    """A plane (native integer codes) as float32 at ``size`` (w, h). A large plane is halved by
    2x2 area averages in its own integer type while it stays at least twice the size (OpenCV's
    2x2 path takes 0.07 ms for 1080p; rounding there adds 0.3 codes of noise to averages whose
    noise the thresholds measure anyway), then brought to ``size`` bilinearly: the last factor is
    under 2, and OpenCV's area resize for such factors took three times the rest together."""
    import cv2

    while a.dtype in (np.uint8, np.uint16) and a.shape[1] >= 2 * size[0] and a.shape[0] >= 2 * size[1]:
        h, w = a.shape
        a = cv2.resize(a[:h - h % 2, :w - w % 2], (w // 2, h // 2), interpolation=cv2.INTER_AREA)
    a = a.astype(np.float32)
    if a.shape[::-1] == tuple(size):
        return a
    fast = a.shape[1] < 2 * size[0] and a.shape[0] < 2 * size[1]
    return cv2.resize(a, size, interpolation=cv2.INTER_LINEAR if fast else cv2.INTER_AREA)


def _crop(a: np.ndarray, roi) -> np.ndarray:
    if roi is None:
        return a
    x, y, w, h = roi
    c = a[y:y + h, x:x + w]
    return c if min(c.shape) >= 8 else a  # a bad ROI is the reader's error to give


def _sampled_luma(planes, roi, max_side: int) -> np.ndarray:
    """Luma of the frame (or its ROI) on the 0-255 scale, float32, one pixel in every ``step`` on
    each axis so that the long side has at most ``max_side`` samples (OpenCV's nearest-neighbour
    gather: a tenth of the cost of a strided copy, and no area resize of the whole plane)."""
    import cv2

    y = _crop(planes.y, roi)
    h, w = y.shape
    step = max(1, -(-max(h, w) // max_side))
    size = (max(1, w // step), max(1, h // step))

    def sample(a):
        a = a if step == 1 else cv2.resize(a[: size[1] * step, : size[0] * step], size, interpolation=cv2.INTER_NEAREST)
        return a.astype(np.float32)

    scale = np.float32(1 << (planes.depth - 8))
    y = sample(y)
    if planes.kind == "rgb":
        g, b = sample(_crop(planes.u, roi)), sample(_crop(planes.v, roi))
        return (np.float32(0.299) * y + np.float32(0.587) * g + np.float32(0.114) * b) / scale
    y /= scale
    if not planes.full_range:
        y = (y - np.float32(16.0)) * np.float32(255.0 / 219.0)
    return y


def _grey(planes, roi, max_side: int) -> tuple[np.ndarray, int]:
    """Luma of the frame (or its ROI) as float32 on the 0-255 scale, at most ``max_side`` pixels
    on its long side (what the wall's level is judged on), and the source width it stands for."""
    def crop(a):
        return _crop(a, roi)

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
    """Sigma of one image from a difference of two: the RMS of the smallest 90 % of |d| (of the
    differences the codec coded, see _coded), scaled to a Gaussian's. Not the median: H.264
    repeats static blocks exactly, so most differences of a compressed wall are 0 and the median
    says 'no noise'; the trimmed tail keeps a mover out."""
    d = np.ravel(d)
    if d.size == 0:
        return 0.0
    if d.size > 4096:  # a fixed stride of the image: as good an estimate for a tenth of the sorting
        d = d[:: d.size // 2048]
    d = _coded(d)
    a = np.abs(d - _upper_median(d))
    k = int(0.9 * (a.size - 1))
    keep = np.partition(a, k)[:k + 1]  # partitions, not numpy's median and quantile: a tenth of the time
    return float(np.sqrt(np.mean(keep * keep, dtype=np.float64) / 0.623 / 2.0))


def _block_side(shape) -> int:
    """Pixels per (square) block: BLOCKS blocks along the long side, at least 4 along the short."""
    return max(1, min(max(shape) // BLOCKS, min(shape) // 4))


def _whole_blocks(img: np.ndarray) -> np.ndarray:
    """The centre of ``img`` that whole blocks tile (a few rows or columns at most are left out):
    block means then take OpenCV's integer-factor area path, ten times faster than its general one."""
    side = _block_side(img.shape)
    h, w = img.shape
    dh, dw = h % side, w % side
    return img[dh // 2: h - (dh - dh // 2), dw // 2: w - (dw - dw // 2)]


def _coded(d: np.ndarray) -> np.ndarray:
    """The differences a codec actually coded: where most of a compressed wall is repeated exactly
    from the frame before (H.264 skip blocks: at CRF 28 nearly all of it), the noise is what the
    updated blocks show, not the zeros, which made every threshold built on it nothing and had
    still walls refused as moving (2-3 of 12 walls at CRF 28)."""
    nz = d[d != 0]
    return nz if d.size // 2 > nz.size >= 16 else d


def _upper_median(x: np.ndarray) -> float:
    k = x.size // 2
    return float(np.partition(x, k)[k])


def _highpass(img: np.ndarray, sigma: float = 4.0) -> np.ndarray:
    import cv2

    return img - cv2.GaussianBlur(img, (0, 0), sigma)


def _relative_texture(small: np.ndarray, fine: np.ndarray) -> np.ndarray:
    """The fine band relative to the local level: what a change of light leaves as it is (texture,
    fixed pattern). Where the level itself changes fast (an edge of light, over EDGE_GRAD of the
    level a pixel) it is NaN, unknown: the edge is no texture."""
    import cv2

    low = small - fine
    level = np.maximum(low, 1.0)
    gx = cv2.Sobel(low, cv2.CV_32F, 1, 0, ksize=3)
    gy = cv2.Sobel(low, cv2.CV_32F, 0, 1, ksize=3)
    edge = cv2.dilate(((gx * gx + gy * gy) > (8.0 * EDGE_GRAD * level) ** 2).astype(np.uint8), np.ones((3, 3), np.uint8))
    return np.where(edge.astype(bool), np.float32(np.nan), fine / level)


def _in_band(hp: np.ndarray, small: np.ndarray, fine: np.ndarray, rel: np.ndarray) -> np.ndarray:
    """The registration band ``hp`` relative to the local level, unknown where ``rel`` (the
    relative texture) is: what camera motion is verified on, the band the shift was found in
    (a wall's finest texture is what a codec keeps least)."""
    return np.where(np.isfinite(rel), hp / np.maximum(small - fine, 1.0), np.float32(np.nan)).astype(np.float32)


def _rms_known(a: np.ndarray) -> float:
    """RMS of the finite values of ``a``; infinite (no bound) when there are none."""
    a = a[np.isfinite(a)]
    return float(np.sqrt(np.mean(a * a))) if a.size else np.inf


def _warp_texture(tex: np.ndarray, dx: float, dy: float) -> np.ndarray:
    """``tex`` moved by (dx, dy) pixels; NaN (unknown) where any unknown or outside pixel enters."""
    import cv2

    known = np.isfinite(tex)
    m = np.float32([[1, 0, dx], [0, 1, dy]])
    size = tex.shape[::-1]
    moved = cv2.warpAffine(np.where(known, tex, 0.0).astype(np.float32), m, size, flags=cv2.INTER_LINEAR)
    ok = cv2.warpAffine(known.astype(np.float32), m, size, flags=cv2.INTER_LINEAR, borderValue=0.0) > 0.999
    return np.where(ok, moved, np.float32(np.nan))


def _broad_blur(img: np.ndarray, sigma: float) -> np.ndarray:
    """A Gaussian blur of large ``sigma`` computed at a quarter of the size (what it keeps has no
    detail finer than that) and brought back bilinearly: a tenth of the cost of the full kernel."""
    import cv2

    h, w = img.shape
    if sigma < 6.0 or min(h, w) < 32:
        return cv2.GaussianBlur(img, (0, 0), sigma)
    small = cv2.resize(img, (max(1, w // 4), max(1, h // 4)), interpolation=cv2.INTER_AREA)
    small = cv2.GaussianBlur(small, (0, 0), np.sqrt(max(sigma ** 2 - 4.0, 1.0)) / 4.0)
    return cv2.resize(small, (w, h), interpolation=cv2.INTER_LINEAR)


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
        self._prev_b = self._prev_h = self._ref_h = self._bg_h = self._bg_b = None
        self._bg_n = 0  # frames averaged into the background since the last reset
        self._t_prev = None
        self._t_checked = -np.inf
        self._dense_until = -np.inf
        self._gap = np.inf  # the shortest time between two checked frames: one frame interval
        self._scale = 1.0
        self._window = None
        self._fracs = (1.0, 1.0)  # changed shares of the last two frames (none calm before the first)
        self._cut_prev = self._cut_t = None
        self._cut_sig: deque = deque(maxlen=HISTORY)
        # the coarse gain-free steps (time of the later sample, RMS): the clip's, and the last few
        self._cut_steps: deque = deque(maxlen=HISTORY + CUT_REACH + 1)
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

    def __call__(self, frame) -> None:
        gap = getattr(frame, "gap", 0.0)
        if gap:
            self.gap(frame.time - gap, frame.time)
        self.update(frame.time, frame.planes)

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
        # these images are too small for OpenCV's pool's hand-offs to pay (blocks.one_opencv_thread)
        with one_opencv_thread():
            cut = self._watch_cut(t, planes) if self._cut_t is None or t - self._cut_t >= 1.0 / CUT_RATE - 1e-3 else None
            if cut is not None:
                self._mark("scene cut", cut)
                self._cut_reset = True
            if t - self._t_checked < 1.0 / CHECK_RATE - 1e-3 and t > self._dense_until and not self._cut_reset:
                return
            self._t_checked = t
            self._update(t, planes)

    def _watch_cut(self, t: float, planes) -> float | None:
        """The time of the previous sample if it was a cut: much of the frame changed from the
        sample before it, beyond a whole-frame gain (exposure, flicker), with calm samples on
        either side (a hard shadow sweeping the wall changes as much, but over several frames).
        Judged on CUT_RATE frames a second, one sample late, on block means of the luma sampled
        at most CUT_SIDE pixels wide (a cut changes whole blocks: a gather of pixels, not a resize,
        is enough to see it)."""
        import cv2

        y = _whole_blocks(_sampled_luma(planes, self.roi, CUT_SIDE))
        bh, bw = (n // _block_side(y.shape) for n in y.shape)
        blocks = cv2.resize(y, (bw, bh), interpolation=cv2.INTER_AREA)
        prev, t_prev = self._cut_prev, self._cut_t
        self._cut_prev, self._cut_t = blocks, t
        if prev is None or prev.shape != blocks.shape:
            return None
        # every step on a few hundred blocks: each numpy call's overhead, not its work, is the cost
        ok = (np.minimum(blocks, prev) >= DARK) & (np.maximum(blocks, prev) < CLIP_HI)
        b, p = blocks[ok], prev[ok]
        if b.size == 0:
            return None
        self._cut_sig.append(_robust_sigma(b - p))
        sigma = max(statistics.median(self._cut_sig), SIGMA_FLOOR)
        gain = _upper_median(b / p)  # p >= DARK > 0
        threshold = np.maximum(b * REL_CUT, K_CUT * sigma * np.sqrt(2.0))
        frac = np.count_nonzero(np.abs(b - gain * p) > threshold) / b.size
        before = self._fracs
        self._fracs = (before[1], frac)
        if frac >= CUT_CALM:
            self._dense_until = t + DENSE
        spike = self._coarse_spike(t, blocks, prev, ok, gain)
        if before[1] > CUT_FRACTION and before[0] < CUT_CALM and frac < CUT_CALM:
            return t_prev
        return spike

    def _coarse_spike(self, t, blocks, prev, ok, gain) -> float | None:
        """The time of the step CUT_REACH samples back if it was a cut by its coarse pattern (see
        CUT_CELLS): a step far above the clip's usual and its neighbours', and above REL_CUT / 2."""
        import cv2

        k = max(1, max(blocks.shape) // CUT_CELLS)
        hh, ww = blocks.shape[0] // k * k, blocks.shape[1] // k * k
        step = np.nan
        if hh and ww and ok.mean() >= MIN_USABLE:
            r = np.where(ok, (blocks - gain * prev) / np.maximum(prev, DARK), 0.0).astype(np.float32)
            size = (ww // k, hh // k)
            cells = cv2.resize(r[:hh, :ww], size, interpolation=cv2.INTER_AREA)
            share = cv2.resize(ok[:hh, :ww].astype(np.float32), size, interpolation=cv2.INTER_AREA)
            m = share > 0.5  # cells mostly usable: their mean is the usable blocks' mean
            if m.any():
                step = float(np.sqrt(np.mean((cells[m] / share[m]) ** 2)))
        steps = self._cut_steps
        steps.append((t, step))
        n = 2 * CUT_REACH + 1
        if len(steps) < n + 3:  # a median of at least 3 earlier steps
            return None
        recent = [s for _, s in list(steps)[-n:]]
        t_mid, mid = steps[-CUT_REACH - 1]
        if not mid > REL_CUT / 2:  # nan (too little usable) too
            return None
        others = [s for i, s in enumerate(recent) if i != CUT_REACH and s == s]
        earlier = [s for _, s in list(steps)[:-n + CUT_REACH] if s == s]
        if len(earlier) < 3 or (others and mid <= CUT_SPIKE * max(others)):
            return None
        return t_mid if mid > CUT_SPIKE * statistics.median(earlier) else None

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
        out = np.zeros((rows, cols), bool)
        if self._bad is None or not self._bad.any():
            return out
        x0, y0, side, dh, dw, scale = self._bad_geometry
        gx, gy, gw, gh = roi
        cw, ch = gw / cols, gh / rows
        for i, j in zip(*np.nonzero(self._bad)):
            # the block's source rectangle, then the cells it overlaps (open intervals: a block
            # that only touches a cell's edge leaves the cell alone)
            bx0, bx1 = x0 + (dw + j * side) * scale, x0 + (dw + (j + 1) * side) * scale
            by0, by1 = y0 + (dh + i * side) * scale, y0 + (dh + (i + 1) * side) * scale
            c0, c1 = int(np.floor((bx0 - gx) / cw)), int(np.ceil((bx1 - gx) / cw))
            r0, r1 = int(np.floor((by0 - gy) / ch)), int(np.ceil((by1 - gy) / ch))
            out[max(r0, 0):max(min(r1, rows), 0), max(c0, 0):max(min(c1, cols), 0)] = True
        return out

    def _reset(self, hp, small, blocks, planes, full) -> None:
        self._dense_until = max(self._dense_until, self._t_checked + DENSE)  # neighbours' noise first
        self._ref_h, self._bg_h, self._bg_b = hp, _highpass(small, FINE), blocks.copy()
        self._tex = _relative_texture(small, self._bg_h)
        self._ref_rel = _in_band(hp, small, self._bg_h, self._tex)
        self._ref_fine = self._tex
        self._bg_c = self._chroma(planes, blocks, full)
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
        prev = self._prev_b
        d = blocks - prev
        # the noise is measured between neighbouring frames only: between checks a fifth of a
        # second apart a shake or a shadow has moved the picture too, and the thresholds built
        # on such a 'noise' let exactly those through
        gap = t - self._t_prev
        self._gap = min(self._gap, gap)
        if gap <= 1.5 * self._gap or not self._sig_b:
            self._sig_b.append(_robust_sigma(d[ok]))
            self._sig_h.append(_robust_sigma((hp - self._prev_h)[4:-4, 4:-4]) ** 2 if min(hp.shape) > 8 else 0.0)
        sigma = max(float(np.median(self._sig_b)), SIGMA_FLOOR)
        var_h = max(float(np.median(self._sig_h)), SIGMA_FLOOR ** 2)
        level = np.maximum(blocks, DARK)
        # camera motion: a shift of the frame's fine structure against the reference frame that
        # explains more of the change than the noise could
        if min(hp.shape) < 2:
            # a frame one sample thin at the check's scale (4000x16, 1x1000) has no second dimension
            # to register on (OpenCV's window needs two): its motion cannot be judged, so say so
            flags.add("too thin to check")
            dx = dy = 0.0
        else:
            if self._window is None or self._window.shape != hp.shape:
                self._window = cv2.createHanningWindow(hp.shape[::-1], cv2.CV_32F)
            # copies: OpenCV applies the window to its inputs in place
            (dx, dy), _ = cv2.phaseCorrelate(self._ref_h.copy(), hp.copy(), self._window)
        shift = float(np.hypot(dx, dy)) * self._scale
        moved = False
        # a shift of half the floor that fits is not motion yet, but a shake on its way to it:
        # every frame is then checked (see CHECK_RATE), as the old every-frame check did
        if shift >= MIN_SHIFT / 2 and min(hp.shape) > 32:  # smaller: no structure to register on
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
            suspect |= fits
            fits &= shift >= MIN_SHIFT
            if fits:
                near = [1 for x, y in self._shifts if np.hypot(dx - x, dy - y) * self._scale < 1.0]
                moved = len(near) + 1 >= HOLD
            self._shifts.append((dx, dy) if fits else (np.inf, np.inf))
        else:
            self._shifts.append((np.inf, np.inf))
        # the wall's own texture, relative to its level, where nothing changed: still in its
        # place (the learnt texture at no shift) if the camera did not move, whatever light did
        a = 1.0 - np.exp(-max(t - self._t_prev, 1e-3) / 2.0)  # 2 s: a mover that stops fades out
        g = float(np.median(blocks[ok] / np.maximum(self._bg_b[ok], 1e-3)))
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
        # light falling on the wall scales its texture with it: compare with the background's
        # texture scaled by each block's change of level, so a shadow's dimming is not an outline
        scale = cv2.resize(blocks / np.maximum(g * self._bg_b, 1.0), fine.shape[::-1], interpolation=cv2.INTER_LINEAR)
        energy = cv2.resize((fine - scale * self._bg_h) ** 2, blocks.shape[::-1], interpolation=cv2.INTER_AREA)
        edge = np.sqrt(energy)
        step = cv2.dilate(np.where(ok, dev, 0.0).astype(np.float32), np.ones((3, 3), np.uint8))
        n = max(_block_side(small.shape) ** 2 / 4.0, 1.0)
        noise = _upper_median(edge[ok]) * (1.0 + K_EDGE / np.sqrt(2.0 * n))
        floor = np.maximum(REL_EDGE * np.maximum(blocks, EDGE_LEVEL), noise)
        hit = broad & (edge > floor) & (edge > SHARP * step) & ok
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
        outlined = not moved and int(hit.sum()) >= MIN_MOVER_BLOCKS
        rel = _relative_texture(small, fine) if moved or outlined or learn_due or history_due else None
        if moved or history_due:
            still = self._pixels(ok & ~broad, rel.shape)
            # two bands: the finest texture tells small shifts apart best but is what a codec keeps
            # least; the registration band (where the shift was found) is kept, but smooth
            bands = ((rel, self._ref_fine, self._match_fine), (_in_band(hp, small, fine, rel), self._ref_rel, self._match))
            matches = [self._texture_match(x, ref, still) for x, ref, _ in bands]
            if moved:
                # the camera moved by the shift if the reference's texture fits better moved by it
                # than where it was: a moving edge of light that the correlation locked on leaves it
                # where it was, and so does a re-coded (intra) frame, which only lowers both
                verdict = None
                for (x, ref, history), match in zip(bands, matches):
                    shifted = self._texture_match(x, _warp_texture(ref, dx, dy), still)
                    found = [v for v in (match, shifted) if v is not None]
                    if found:
                        history.append(max(found))
                    # registrable if the texture matched the reference (in place or moved by the
                    # shift found) well enough at some check: a shaking camera seldom comes back;
                    # every band that is must agree, each by SHIFT_Z
                    if history and max(history) >= REGISTRABLE:
                        agrees = shifted is not None and match is not None and shifted - match > SHIFT_Z
                        verdict = agrees if verdict is None else verdict and agrees
                if verdict is None:
                    flags.add("motion not verifiable")
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
        chroma = self._chroma(planes, blocks, full) if self._bg_c is not None and (outlined or learn_due) else None
        judged = hit
        if not moved and int(hit.sum()) >= MIN_MOVER_BLOCKS:
            ratio = blocks / np.maximum(g * self._bg_b, 1e-3)
            judged = self._objects(t, hit, broad & ok, ok, rel, ratio, chroma)
        judged = judged | covered
        if not moved and int(judged.sum()) >= MIN_MOVER_BLOCKS:
            flags.add("moving object")
            self._bad |= judged
        # every frame for a while after anything suspect; a sharp change of light is not
        if suspect or moved or judged.any() or ((broad & ok).any() and not outlined):
            self._dense_until = t + DENSE
        self._bg_h = ((1 - a) * self._bg_h + a * fine).astype(np.float32)
        self._bg_b = ((1 - a) * self._bg_b + a * blocks / max(g, 1e-3)).astype(np.float32)
        # the wall's texture: learnt where nothing changed, slower than the background (a shadow
        # that stays is learnt through, an object that stops is learnt like the background)
        if not learn_due:
            return flags
        calm = self._pixels(~broad & ok, rel.shape)
        b = max(1.0 - np.exp(-max(t - self._t_tex, 1e-3) / TEX_TAU), 1.0 / self._bg_n)
        self._t_tex = t
        tex = self._tex
        learn = calm & np.isfinite(rel)  # an unknown pixel (an edge) keeps what was learnt
        self._tex = np.where(learn, np.where(np.isfinite(tex), (1 - b) * tex + b * rel, rel), tex).astype(np.float32)
        if chroma is not None:
            keep = ~broad & ok
            self._bg_c = np.where(keep, (1 - b) * self._bg_c + b * chroma, self._bg_c).astype(np.float32)
        return flags

    @staticmethod
    def _texture_match(rel: np.ndarray, ref: np.ndarray, where: np.ndarray) -> float | None:
        """The regression of this frame's relative texture on the reference frame's, over
        ``where`` (pixels; edges left out), in standard errors: large on a still wall with
        texture (or, compressed, noise the codec froze) that registers, falling to 0 as the
        camera moves it away."""
        m = where & np.isfinite(rel) & np.isfinite(ref)
        if np.count_nonzero(m) < 64:
            return None
        x, y = rel[m], ref[m]
        yy = float(np.dot(y, y))
        if yy <= 0:
            return None
        b = float(np.dot(x, y)) / yy
        resid = max(float(np.dot(x, x)) - b * b * yy, 0.0) / x.size
        # in standard errors (pixels counted a quarter, as in _objects): a wall's texture can be
        # a small share of each pixel and still register over the whole frame
        return b / max(float(np.sqrt(4.0 * resid / yy)), 1e-12)

    @staticmethod
    def _pixels(mask: np.ndarray, shape) -> np.ndarray:
        """A block mask at pixel resolution (the block grid tiles ``shape``: see _whole_blocks)."""
        import cv2

        return cv2.resize(mask.astype(np.uint8), shape[::-1], interpolation=cv2.INTER_NEAREST).astype(bool)

    def _chroma(self, planes, blocks, full) -> np.ndarray | None:
        """(2, rows, cols): the block means of the two colour planes over the luma level (U-128 and
        V-128 for YUV, G and B for RGB), on the luma's block grid; what a change of light keeps."""
        import cv2

        if planes.u is None or planes.v is None:
            return None
        roi = self.roi
        if roi is not None and planes.kind != "rgb":
            sx, sy = planes.sub_x, planes.sub_y
            roi = (roi[0] >> sx, roi[1] >> sy, max(1, roi[2] >> sx), max(1, roi[3] >> sy))
        scale = np.float32(1 << (planes.depth - 8))
        out = []
        for a in (planes.u, planes.v):
            c = _whole_blocks(_shrink(_crop(a, roi), full[::-1]) / scale)
            if planes.kind != "rgb":
                c = c - np.float32(128.0)
            out.append(cv2.resize(c, blocks.shape[::-1], interpolation=cv2.INTER_AREA))
        return np.stack(out) / np.maximum(blocks, DARK)

    def _objects(self, t, hit, changed, ok, rel, ratio, chroma) -> np.ndarray:
        """The blocks of ``hit`` (sharp outlines) that bound an object rather than a change of
        light: per connected region of changed blocks, the wall's texture (relative to the level,
        which a change of light leaves as it is) is gone from it, or the region is flat (holds
        neither that texture nor the noise its level brings), or its colour ratios changed. The
        other regions are sharp light on the wall: noted (see NOTES), not refused."""
        import cv2

        tex = self._tex
        calm = ok & ~cv2.dilate(changed.astype(np.uint8), np.ones((3, 3), np.uint8)).astype(bool)
        if not calm.any():
            calm = ok & ~changed
        side = _block_side(rel.shape)
        # per block: the texture's projection and energy, the frame's own relative fine energy
        def block_sum(a):
            return cv2.resize(a, hit.shape[::-1], interpolation=cv2.INTER_AREA) * np.float32(side * side)

        # edges are no texture: a shadow's outline in this frame, or one the learnt texture kept
        # from where a shadow stood (it is learnt where blocks are calm, not pixels), would read
        # as texture lost; pixels far out in either are left out (the wall's texture is a few
        # per cent with a Gaussian's tails)
        pc = self._pixels(calm, rel.shape)
        sx, sm = (_rms_known(a[pc]) for a in (rel, tex))
        with np.errstate(invalid="ignore"):
            keep = (np.abs(rel) < K_OUTLIER * sx) & (np.abs(tex) < K_OUTLIER * sm)  # NaN: no
        r, m = np.where(keep, rel, 0.0).astype(np.float32), np.where(keep, tex, 0.0).astype(np.float32)
        xm, mm, xx = block_sum(r * m), block_sum(m * m), block_sum(r * r)
        known = block_sum(keep.astype(np.float32))

        def beta(m):
            """Regression of the frame's relative texture on the learnt one over blocks ``m`` and
            its standard error (pixels counted a quarter: interpolation and the codec correlate them)."""
            smm, sxm, sxx, n = (float(np.sum(a[m], dtype=np.float64)) for a in (mm, xm, xx, known))
            if smm <= 0.0 or n < MIN_KNOWN * side * side:
                return 0.0, np.inf
            b = sxm / smm
            resid = max(sxx - b * sxm, 0.0) / n
            return b, float(np.sqrt(4.0 * resid / smm))

        b0, se0 = beta(calm)
        registrable = b0 > K_TEX * se0 and b0 > 0.0
        # per block, the mean relative fine energy of its known pixels (most must be known)
        measured = known >= side * side / 2
        energy = np.where(measured, xx / np.maximum(known, 1.0), np.float32(1e30)) * np.maximum(ratio, 1.0)
        e0 = float(np.median(energy[calm & measured])) if (calm & measured).any() else 0.0
        n, labels = cv2.connectedComponents(changed.astype(np.uint8), connectivity=8)
        out = np.zeros_like(hit)
        sharp = []
        for k in range(1, n):
            region = labels == k
            if not (hit & region).any():
                continue
            b, se = beta(region)
            lost = registrable and b < KEPT * b0 and (KEPT * b0 - b) > K_TEX * se
            flat = e0 > 0.0 and float(np.percentile(energy[region], FLAT_SHARE)) < FLAT * e0
            lit = region & (self._bg_b >= COLOUR_LEVEL)  # darker, a ratio is its quantisation and noise
            colour = chroma is not None and int(lit.sum()) >= COLOUR_BLOCKS and float(np.median(
                np.hypot(*(chroma[:, lit] - self._bg_c[:, lit])))) > COLOUR
            if self.trace is not None:
                self.trace.append({"t": round(t, 3), "blocks": int(region.sum()), "hits": int((hit & region).sum()),
                                   "beta": b, "se": se, "beta_calm": b0, "se_calm": se0,
                                   "flat": float(np.min(energy[region])) / e0 if e0 > 0 else None,
                                   "colour": None if chroma is None else float(np.median(
                                       np.hypot(*(chroma[:, region] - self._bg_c[:, region])))),
                                   "ratio": float(np.median(ratio[region])), "object": bool(lost or flat or colour),
                                   "e_q": [float(x) for x in np.percentile(energy[region], [10, 25, 50])] if e0 > 0 else None,
                                   "e0": e0, "known": float(known[region].sum()) / (side * side),
                                   "colour_calm": None if chroma is None or not calm.any() else float(np.median(
                                       np.hypot(*(chroma[:, calm] - self._bg_c[:, calm])))),
                                   "level": float(np.median(self._bg_b[region]))})
            if lost or flat or colour:
                out |= hit & region
            else:
                sharp.append(region)
        if sharp and int(out.sum()) < MIN_MOVER_BLOCKS:
            self._mark_note("sharp light", t)
        return out

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
        issues = [k for k, s in found.items() if s]
        refused = [k for k in issues if k not in NOT_REFUSED]
        if self.frames == 0:
            return {"usable": False, "issues": ["too little usable area"], "reason": "no frame was checked", "notes": []}
        reason = None
        if refused:
            parts = [f"{k} at {_spans_text(found[k])}" for k in refused if k != "frame gap"]
            reason = "; ".join((["not a static view of the wall: " + "; ".join(parts)] if parts else [])
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
                "max_shift": self.max_shift, "min_usable": self.min_usable,
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
        if record.get("noise") is not None:
            check._sig_b.append(float(record["noise"]))
        return check

    def summary(self) -> dict:
        """The clip's view and what it was judged on (extra fields of the JSON's ``view``)."""
        noise = float(np.median(self._sig_b)) if self._sig_b else None
        return {**self.view(), "gaps": [list(s) for s in self.spans["frame gap"]],
                "frames": self.frames, "max_shift_px": round(self.max_shift, 2),
                "min_usable_area": round(self.min_usable, 3),
                "noise": None if noise is None else round(noise, 4)}


def _spans_text(spans: list) -> str:
    shown = ", ".join(span_text(a, b) for a, b in spans[:3])
    return shown + (f" and {len(spans) - 3} more" if len(spans) > 3 else "")
