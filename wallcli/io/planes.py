"""A decoded frame as its planes (Y, U, V at their native bit depth, gray, or RGB), never rounded
to 8-bit RGB, with the colour matrix that turns them into RGB; and the planes of a PyAV frame,
turned as a display matrix asks. :mod:`wallcli.io.video` reads frames into these.
"""

from __future__ import annotations

import re
from dataclasses import dataclass

import numpy as np

# Luma coefficients (Kr, Kb) of the YUV matrices we honour.
_MATRICES = {"bt601": (0.299, 0.114), "bt709": (0.2126, 0.0722), "bt2020": (0.2627, 0.0593)}
# FFmpeg's AVColorSpace values -> our names (2 = unspecified, guessed from the frame height).
_AVCOL_SPC = {1: "bt709", 4: "bt601", 5: "bt601", 6: "bt601", 7: "bt601", 9: "bt2020", 10: "bt2020"}
_YUV_RE = re.compile(r"^yuv(j?)(420|422|444|440|411|410)p(\d+)?(le|be)?$")
_GRAY_RE = re.compile(r"^gray(\d+)?(le|be)?$")
_SUB = {"420": (1, 1), "422": (1, 0), "444": (0, 0), "440": (0, 1), "411": (2, 0), "410": (2, 1)}


@dataclass
class Planes:
    """A decoded frame's planes in their native code values, and how to turn them into RGB.

    ``kind`` is 'yuv' (y, u, v), 'gray' (y only) or 'rgb' (y, u, v hold R, G, B at full size).
    """

    y: np.ndarray
    u: np.ndarray | None
    v: np.ndarray | None
    kind: str = "yuv"
    sub_x: int = 0
    sub_y: int = 0
    depth: int = 8
    matrix: str = "bt601"
    full_range: bool = False

    @property
    def width(self) -> int:
        return self.y.shape[1]

    @property
    def height(self) -> int:
        return self.y.shape[0]

    def to_rgb(self, y, u=None, v=None) -> np.ndarray:
        """Affine map of plane values (any equal shapes, float) to RGB on the 0-255 scale, unclipped.

        Clipping would bias averages of values near black or white, so out-of-gamut stays as is.
        """
        return self._rgb64(y, u, v).astype(np.float32)

    def rgb_affine(self, chroma: bool = True) -> tuple[np.ndarray, np.ndarray]:
        """(M (3, 3), b (3,)), float64, with RGB = [y, u, v] @ M + b: :meth:`to_rgb` as one affine
        map, for callers that convert many small arrays (a frame's profiles) and would otherwise
        pay its dozen numpy steps each time. ``chroma=False``: from y alone (rows 1-2 of M zero)."""
        points = np.array([[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]])
        if chroma and self.u is not None:
            out = self._rgb64(points[:, 0], points[:, 1], points[:, 2])
        else:
            out = np.concatenate([self._rgb64(points[:2, 0]), np.zeros((2, 3))])
            out[2:] = out[0]
        return out[1:] - out[0], out[0]

    def _rgb64(self, y, u=None, v=None) -> np.ndarray:
        scale = float(1 << (self.depth - 8))
        y = np.asarray(y, dtype=np.float64) / scale
        if self.kind == "rgb":
            return np.stack([y, np.asarray(u, np.float64) / scale, np.asarray(v, np.float64) / scale], axis=-1)
        if self.kind == "gray" or u is None:
            yy = y if self.full_range else (y - 16.0) * (255.0 / 219.0)
            return np.repeat(yy[..., None], 3, axis=-1)
        u = np.asarray(u, dtype=np.float64) / scale - 128.0
        v = np.asarray(v, dtype=np.float64) / scale - 128.0
        if self.full_range:
            yy, cb, cr = y, u, v
        else:
            yy, cb, cr = (y - 16.0) * (255.0 / 219.0), u * (255.0 / 224.0), v * (255.0 / 224.0)
        kr, kb = _MATRICES[self.matrix]
        kg = 1.0 - kr - kb
        r = yy + 2.0 * (1.0 - kr) * cr
        b = yy + 2.0 * (1.0 - kb) * cb
        g = (yy - kr * r - kb * b) / kg
        return np.stack([r, g, b], axis=-1)

    def rgb(self) -> np.ndarray:
        """The whole frame as float32 RGB (H, W, 3), chroma upsampled bilinearly, no rounding."""
        import cv2

        if self.kind != "yuv":
            return self.to_rgb(self.y, self.u, self.v)
        h, w = self.y.shape
        u = self.u.astype(np.float32)
        v = self.v.astype(np.float32)
        if u.shape != (h, w):
            u = cv2.resize(u, (w, h), interpolation=cv2.INTER_LINEAR)
            v = cv2.resize(v, (w, h), interpolation=cv2.INTER_LINEAR)
        return self.to_rgb(self.y, u, v)


def _plane_array(plane, width: int, height: int, dtype) -> np.ndarray:
    itemsize = np.dtype(dtype).itemsize
    arr = np.frombuffer(plane, dtype=dtype)
    return arr.reshape(-1, plane.line_size // itemsize)[:height, :width]


def frame_planes(frame) -> Planes:
    """The planes of a decoded ``av.VideoFrame``; exotic pixel formats are converted by swscale."""
    name = frame.format.name
    w, h = frame.width, frame.height
    m = _YUV_RE.match(name)
    g = _GRAY_RE.match(name)
    if m is None and g is None and name not in ("rgb24", "bgr24", "gbrp"):
        # Packed, semi-planar (nv12), paletted or hardware formats: convert once, at full depth.
        deep = any(c.bits > 8 for c in frame.format.components)
        frame = frame.reformat(format="yuv444p16le" if deep else "yuv444p")
        return frame_planes(frame)
    if name in ("rgb24", "bgr24"):
        arr = _plane_array(frame.planes[0], w * 3, h, np.uint8).reshape(h, w, 3)
        r, gg, b = (arr[..., 0], arr[..., 1], arr[..., 2]) if name == "rgb24" else (arr[..., 2], arr[..., 1], arr[..., 0])
        return Planes(np.ascontiguousarray(r), np.ascontiguousarray(gg), np.ascontiguousarray(b), kind="rgb")
    if name == "gbrp":
        gp, bp, rp = (_plane_array(p, w, h, np.uint8) for p in frame.planes[:3])
        return Planes(rp, gp, bp, kind="rgb")
    bits = int((m or g).group(3 if m else 1) or 8)
    if (m or g).group(4 if m else 2) == "be":
        frame = frame.reformat(format=name[:-2] + "le")
    dtype = np.uint8 if bits <= 8 else np.uint16
    planes = frame.planes  # (PyAV builds the list anew at each access: 9 us)
    y = _plane_array(planes[0], w, h, dtype)
    spc = _AVCOL_SPC.get(int(frame.colorspace or 2)) or ("bt709" if h >= 720 else "bt601")
    full = int(frame.color_range or 0) == 2 or (m is not None and m.group(1) == "j")
    if g is not None:
        # Gray formats are full range in FFmpeg unless the stream says otherwise.
        return Planes(y, None, None, kind="gray", depth=bits, matrix=spc, full_range=int(frame.color_range or 0) != 1)
    sx, sy = _SUB[m.group(2)]
    cw, ch = (w + (1 << sx) - 1) >> sx, (h + (1 << sy) - 1) >> sy  # ceil: odd sizes keep their last column
    u = _plane_array(planes[1], cw, ch, dtype)
    v = _plane_array(planes[2], cw, ch, dtype)
    return Planes(y, u, v, kind="yuv", sub_x=sx, sub_y=sy, depth=bits, matrix=spc, full_range=full)


def rotate_planes(planes: Planes, k: int) -> Planes:
    """``planes`` turned by k quarter turns counterclockwise (np.rot90's sense), each plane copied
    to contiguous memory; a quarter turn swaps the chroma's horizontal and vertical subsampling."""
    k %= 4
    if not k:
        return planes

    def turn(a):
        return None if a is None else np.ascontiguousarray(np.rot90(a, k))

    sx, sy = (planes.sub_y, planes.sub_x) if k % 2 else (planes.sub_x, planes.sub_y)
    return Planes(turn(planes.y), turn(planes.u), turn(planes.v), kind=planes.kind, sub_x=sx, sub_y=sy,
                  depth=planes.depth, matrix=planes.matrix, full_range=planes.full_range)


def quarter_turns(rotation) -> int | None:
    """np.rot90's k that shows a frame as its display matrix asks (FFmpeg's ``rotation``: degrees
    the matrix turns the frame counterclockwise); None for an angle that is not a quarter turn."""
    angle = float(rotation or 0.0)
    k = round(angle / 90.0)
    return k % 4 if abs(angle - 90.0 * k) < 1.0 else None
