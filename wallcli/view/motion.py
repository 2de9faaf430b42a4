"""Did the camera move? The view check's registration of a frame on the reference frame: whether
the shift the phase correlation found fits (against its mirror image), and whether the wall's
texture, relative to its level, agrees that the camera moved by it. Plain functions on the
check's downscaled images."""
from __future__ import annotations

import numpy as np

from wallcli.view.limits import K_SHIFT, REGISTRABLE, SHIFT_Z


def _in_band(hp: np.ndarray, small: np.ndarray, fine: np.ndarray, rel: np.ndarray) -> np.ndarray:
    """The registration band ``hp`` relative to the local level, unknown where ``rel`` (the
    relative texture) is: what camera motion is verified on, the band the shift was found in
    (a wall's finest texture is what a codec keeps least)."""
    return np.where(np.isfinite(rel), hp / np.maximum(small - fine, 1.0), np.float32(np.nan)).astype(np.float32)



def _warp_texture(tex: np.ndarray, dx: float, dy: float) -> np.ndarray:
    """``tex`` moved by (dx, dy) pixels; NaN (unknown) where any unknown or outside pixel enters."""
    import cv2

    known = np.isfinite(tex)
    m = np.float32([[1, 0, dx], [0, 1, dy]])
    size = tex.shape[::-1]
    moved = cv2.warpAffine(np.where(known, tex, 0.0).astype(np.float32), m, size, flags=cv2.INTER_LINEAR)
    ok = cv2.warpAffine(known.astype(np.float32), m, size, flags=cv2.INTER_LINEAR, borderValue=0.0) > 0.999
    return np.where(ok, moved, np.float32(np.nan))



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

def _shift_fits(ref_h: np.ndarray, hp: np.ndarray, dx: float, dy: float, var_h: float):
    """Whether the reference band ``ref_h`` moved by (dx, dy) explains ``hp`` far better than
    moved the other way (``var_h``: the band's frame-to-frame noise variance)."""
    import cv2

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
        warped = cv2.warpAffine(ref_h, m, hp.shape[::-1], borderMode=cv2.BORDER_REFLECT)
        e.append(float(np.mean((hp - warped)[c, c] ** 2)))
    n = hp[c, c].size / 4
    return (e[1] - e[0]) > K_SHIFT * max(e[0], var_h) * np.sqrt(8.0 / n)


def _motion_verdict(bands, matches, still: np.ndarray, dx: float, dy: float) -> bool | None:
    """Whether the camera moved by (dx, dy), by the texture: ``bands`` are (this frame's texture,
    the reference's, the band's history of matches) and ``matches`` their matches in place. None:
    no band was registrable, the motion is not verifiable. Each band's history gets this check's
    best match."""
    # the camera moved by the shift if the reference's texture fits better moved by it
    # than where it was: a moving edge of light that the correlation locked on leaves it
    # where it was, and so does a re-coded (intra) frame, which only lowers both
    verdict = None
    for (x, ref, history), match in zip(bands, matches):
        shifted = _texture_match(x, _warp_texture(ref, dx, dy), still)
        found = [v for v in (match, shifted) if v is not None]
        if found:
            history.append(max(found))
        # registrable if the texture matched the reference (in place or moved by the
        # shift found) well enough at some check: a shaking camera seldom comes back;
        # every band that is must agree, each by SHIFT_Z
        if shifted is None or match is None:
            # nothing known to compare here (a high-contrast wall is all edges to the texture):
            # this band cannot say the camera stayed, and a 15 px pan of one passed as still
            continue
        if history and max(history) >= REGISTRABLE:
            agrees = shifted - match > SHIFT_Z
            verdict = agrees if verdict is None else verdict and agrees
    return verdict
