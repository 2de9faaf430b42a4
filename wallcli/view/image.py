"""The view check's images: a frame's luma downscaled or sampled (native integer codes to float32
on the 0-255 scale), the block grid it is judged on, the noise of a difference, and the filters
that split a frame into bands (fine structure, registration band, broad light)."""
from __future__ import annotations

import math

import numpy as np

from wallcli.view.limits import BLOCKS, MIN_CROP


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


def _box_blocks(geometry, shape: tuple[int, int], boxes) -> np.ndarray:
    """(rows, cols) bool: the blocks of the grid (ViewCheck._note_bad's ``geometry``) that overlap
    any of ``boxes`` (x, y, w, h, source pixels)."""
    out = np.zeros(shape, bool)
    x0, y0, side, dh, dw, scale = geometry
    for bx, by, bw, bh in boxes:
        c0 = int(np.floor(((bx - x0) / scale - dw) / side))
        c1 = int(np.ceil(((bx + bw - x0) / scale - dw) / side))
        r0 = int(np.floor(((by - y0) / scale - dh) / side))
        r1 = int(np.ceil(((by + bh - y0) / scale - dh) / side))
        out[max(r0, 0):max(r1, 0), max(c0, 0):max(c1, 0)] = True
    return out


def _block_rects(geometry, where) -> list:
    """(x0, x1, y0, y1) source rectangles of the blocks at ``where`` (rows, cols) of the grid."""
    x0, y0, side, dh, dw, scale = geometry
    return [(x0 + (dw + j * side) * scale, x0 + (dw + (j + 1) * side) * scale,
             y0 + (dh + i * side) * scale, y0 + (dh + (i + 1) * side) * scale) for i, j in zip(*where)]


def _cells(rects, roi, rows: int, cols: int) -> np.ndarray:
    """(rows, cols) bool: the cells of a grid over ``roi`` (x, y, w, h) that ``rects`` (x0, x1,
    y0, y1, source pixels) overlap (open intervals: a rectangle that only touches a cell's edge
    leaves the cell alone)."""
    out = np.zeros((rows, cols), bool)
    gx, gy, gw, gh = roi
    cw, ch = gw / cols, gh / rows
    for bx0, bx1, by0, by1 in rects:
        c0, c1 = int(np.floor((bx0 - gx) / cw)), int(np.ceil((bx1 - gx) / cw))
        r0, r1 = int(np.floor((by0 - gy) / ch)), int(np.ceil((by1 - gy) / ch))
        out[max(r0, 0):max(min(r1, rows), 0), max(c0, 0):max(min(c1, cols), 0)] = True
    return out


def _crop(a: np.ndarray, roi) -> np.ndarray:
    if roi is None:
        return a
    x, y, w, h = roi
    c = a[y:y + h, x:x + w]
    # a bad ROI is the reader's error to give; one too small to look at is ViewCheck's ('too small')
    return c if min(c.shape) >= MIN_CROP else a


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
    if scale != 1:  # a division by 1 is the identity, to the bit
        y /= scale
    if not planes.full_range:  # in place: y is this function's own copy
        y -= np.float32(16.0)
        y *= np.float32(255.0 / 219.0)
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
    y = _shrink(Y, size)  # a new array: what follows is done in place
    if scale != 1:  # a division by 1 is the identity, to the bit
        y /= np.float32(scale)
    if not planes.full_range:
        y -= np.float32(16.0)
        y *= np.float32(255.0 / 219.0)
    return y, w


def _sigma_stride(size: int) -> int:
    """The stride at which :func:`_robust_sigma` reads a difference of ``size`` values (1: all),
    one rule for it and for :func:`_inner_difference`, which subtracts only those values."""
    return size // 2048 if size > 4096 else 1


def _robust_sigma(d: np.ndarray) -> float:
    """Sigma of one image from a difference of two: the RMS of the smallest 90 % of |d| (of the
    differences the codec coded, see _coded), scaled to a Gaussian's. Not the median: H.264
    repeats static blocks exactly, so most differences of a compressed wall are 0 and the median
    says 'no noise'; the trimmed tail keeps a mover out."""
    d = np.ravel(d)
    if d.size == 0:
        return 0.0
    step = _sigma_stride(d.size)
    if step > 1:  # a fixed stride of the image: as good an estimate for a tenth of the sorting
        d = d[::step]
    d = _coded(d)
    a = np.abs(d - _upper_median(d))
    k = int(0.9 * (a.size - 1))
    keep = np.partition(a, k)[:k + 1]  # partitions, not numpy's median and quantile: a tenth of the time
    # np.mean's own sum and division, without its Python wrapper (called on every sample)
    return math.sqrt(float(np.add.reduce(keep * keep, dtype=np.float64)) / keep.size / 0.623 / 2.0)


def _block_side(shape) -> int:
    """Pixels per (square) block: BLOCKS blocks along the long side, at least 4 along the short."""
    return max(1, min(max(shape) // BLOCKS, min(shape) // 4))


def _whole_blocks(img: np.ndarray) -> np.ndarray:
    """The centre of ``img`` that whole blocks tile (a few rows or columns at most are left out):
    block means then take OpenCV's integer-factor area path, ten times faster than its general one."""
    rows, cols = _whole_block_bounds(img.shape)
    return img[rows, cols]


def _whole_block_bounds(shape) -> tuple[slice, slice]:
    """The rows and columns of :func:`_whole_blocks`' centre of an image of ``shape``."""
    side = _block_side(shape)
    h, w = shape
    dh, dw = h % side, w % side
    return slice(dh // 2, h - (dh - dh // 2)), slice(dw // 2, w - (dw - dw // 2))


def _coded(d: np.ndarray) -> np.ndarray:
    """The differences a codec actually coded: where most of a compressed wall is repeated exactly
    from the frame before (H.264 skip blocks: at CRF 28 nearly all of it), the noise is what the
    updated blocks show, not the zeros, which made every threshold built on it nothing and had
    still walls refused as moving (2-3 of 12 walls at CRF 28)."""
    nz = d[d != 0]
    return nz if d.size // 2 > nz.size >= 16 else d


def _median(x: np.ndarray) -> float:
    """np.median of a flat float32 array of finite values, to the bit (the mean of the two middle
    values in float32 for an even count), without its Python layers: a fifth of the time."""
    n = x.size
    k = n // 2
    if n % 2:
        return float(np.partition(x, k)[k])
    p = np.partition(x, (k - 1, k))
    return float((p[k - 1] + p[k]) / 2)


def _upper_median(x: np.ndarray) -> float:
    k = x.size // 2
    return float(np.partition(x, k)[k])


def _highpass(img: np.ndarray, sigma: float = 4.0) -> np.ndarray:
    import cv2

    return img - cv2.GaussianBlur(img, (0, 0), sigma)



def _rms_known(a: np.ndarray) -> float:
    """RMS of the finite values of ``a``; infinite (no bound) when there are none."""
    a = a[np.isfinite(a)]
    return float(np.sqrt(np.mean(a * a))) if a.size else np.inf



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


def _pixels(mask: np.ndarray, shape) -> np.ndarray:
    """A block mask at pixel resolution (the block grid tiles ``shape``: see _whole_blocks)."""
    import cv2

    return cv2.resize(mask.astype(np.uint8), shape[::-1], interpolation=cv2.INTER_NEAREST).astype(bool)


_INNER: dict = {}


def _inner_difference(a: np.ndarray, b: np.ndarray, margin: int) -> np.ndarray:
    """``(a - b)[margin:-margin, margin:-margin]`` as far as :func:`_robust_sigma` reads it: over
    4096 values it reads a fixed stride of them (_sigma_stride), which are then all that is subtracted (the
    gather's indices kept per shape: the whole difference and its copy were most of the cost)."""
    h, w = a.shape[0] - 2 * margin, a.shape[1] - 2 * margin
    step = _sigma_stride(h * w)
    if step == 1:
        return (a - b)[margin:-margin, margin:-margin]
    key = (a.shape, margin)
    if key not in _INNER:
        flat = np.arange(0, h * w, step)
        _INNER[key] = (flat // w + margin, flat % w + margin)
    rows, cols = _INNER[key]
    return a[rows, cols] - b[rows, cols]
