"""Light or a thing? The view check's judging of a changed region with a sharp outline: a change
of light keeps the wall's texture relative to its level, its fine noise and its colour ratios; an
object in view hides them. Plain functions on the check's downscaled images and block grids."""
from __future__ import annotations

import numpy as np

from wallcli.view.image import _block_side, _crop, _pixels, _rms_known, _shrink, _whole_blocks
from wallcli.view.limits import (
    COLOUR, COLOUR_BLOCKS, COLOUR_LEVEL, DARK, EDGE_GRAD, FLAT, FLAT_SHARE, K_OUTLIER, K_TEX, KEPT, MIN_KNOWN,
    MIN_MOVER_BLOCKS,
)


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



def _chroma(planes, roi, blocks, full) -> np.ndarray | None:
    """(2, rows, cols): the block means of the two colour planes over the luma level (U-128 and
    V-128 for YUV, G and B for RGB), on the luma's block grid; what a change of light keeps."""
    import cv2

    if planes.u is None or planes.v is None:
        return None
    if roi is not None and planes.kind != "rgb":
        sx, sy = planes.sub_x, planes.sub_y
        roi = (roi[0] >> sx, roi[1] >> sy, max(1, roi[2] >> sx), max(1, roi[3] >> sy))
    scale = np.float32(1 << (planes.depth - 8))
    out = []
    for a in (planes.u, planes.v):
        c = _shrink(_crop(a, roi), full[::-1])  # a new array: what follows is done in place
        if scale != 1:  # a division by 1 is the identity, to the bit
            c /= scale
        c = _whole_blocks(c)
        if planes.kind != "rgb":
            c -= np.float32(128.0)
        out.append(cv2.resize(c, blocks.shape[::-1], interpolation=cv2.INTER_AREA))
    return np.stack(out) / np.maximum(blocks, DARK)


def _objects(t, hit, changed, ok, rel, ratio, chroma, tex, bg_b, bg_c, trace) -> tuple[np.ndarray, bool]:
    """The blocks of ``hit`` (sharp outlines) that bound an object rather than a change of
    light: per connected region of changed blocks, the wall's texture (relative to the level,
    which a change of light leaves as it is) is gone from it, or the region is flat (holds
    neither that texture nor the noise its level brings), or its colour ratios changed. The
    other regions are sharp light on the wall: noted (see NOTES), not refused; the second value
    says whether to note it (some region was light, and too few blocks were objects to refuse).
    ``tex``: the learnt relative texture; ``bg_b``, ``bg_c``: the background's block levels and
    colour ratios; ``trace``: a list that gets what each region was judged on, or None."""
    import cv2

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
    pc = _pixels(calm, rel.shape)
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
        lit = region & (bg_b >= COLOUR_LEVEL)  # darker, a ratio is its quantisation and noise
        colour = chroma is not None and int(lit.sum()) >= COLOUR_BLOCKS and float(np.median(
            np.hypot(*(chroma[:, lit] - bg_c[:, lit])))) > COLOUR
        if trace is not None:
            trace.append({"t": round(t, 3), "blocks": int(region.sum()), "hits": int((hit & region).sum()),
                          "beta": b, "se": se, "beta_calm": b0, "se_calm": se0,
                          "flat": float(np.min(energy[region])) / e0 if e0 > 0 else None,
                          "colour": None if chroma is None else float(np.median(
                              np.hypot(*(chroma[:, region] - bg_c[:, region])))),
                          "ratio": float(np.median(ratio[region])), "object": bool(lost or flat or colour),
                          "e_q": [float(x) for x in np.percentile(energy[region], [10, 25, 50])] if e0 > 0 else None,
                          "e0": e0, "known": float(known[region].sum()) / (side * side),
                          "colour_calm": None if chroma is None or not calm.any() else float(np.median(
                              np.hypot(*(chroma[:, calm] - bg_c[:, calm])))),
                          "level": float(np.median(bg_b[region]))})
        if lost or flat or colour:
            out |= hit & region
        else:
            sharp.append(region)
    return out, bool(sharp) and int(out.sum()) < MIN_MOVER_BLOCKS
