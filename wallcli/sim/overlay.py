"""Burned-in overlays and interlaced weaving, as camera pipelines add them (``simulate --overlay``,
``simulate --interlace``; research/pipelines applies the same to other renderers' clips).

An overlay is drawn after the camera's noise, in the recorder: its pixels are one flat code value,
frozen between the moments its text changes (a clock: once a second). Interlaced video holds two
fields in a frame, the even rows (the top field) and the odd rows, captured at two instants.
"""

from __future__ import annotations

import numpy as np

FONT_HEIGHT = 1 / 12  # of the frame's height: a CCTV clock's line of text (9 px on a 96x72 frame)
EPOCH = 1_795_708_800  # the clock's reading at t = 0 (2026-11-26 16:00:00 UTC)


def clock_text(t: float, width: int, start: int = EPOCH) -> str:
    """The clock's reading at ``t`` seconds: date and time where the frame is wide enough for it."""
    import time

    stamp = time.gmtime(start + int(np.floor(t)))
    return time.strftime("%Y-%m-%d %H:%M:%S" if width >= 240 else "%H:%M:%S", stamp)


def text_mask(height: int, width: int, t: float, *, name: str | None = None, start: int = EPOCH) -> np.ndarray:
    """(height, width) bool: the pixels a clock at the top left (reading ``t``) and an optional
    camera ``name`` at the bottom right cover, drawn without anti-aliasing (a recorder's flat text)."""
    import cv2

    font = cv2.FONT_HERSHEY_PLAIN
    scale = max(FONT_HEIGHT * height / 15.0, 0.5)  # the plain font is 15 px tall at scale 1
    canvas = np.zeros((height, width), np.uint8)
    margin = max(2, height // 36)
    thick = max(1, int(scale / 2))  # strokes as a recorder draws them, bolder on large frames
    (_, th), _ = cv2.getTextSize("0", font, scale, thick)
    cv2.putText(canvas, clock_text(t, width, start), (margin, margin + th), font, scale, 255, thick, cv2.LINE_8)
    if name:
        (nw, _), base = cv2.getTextSize(name, font, scale, thick)
        cv2.putText(canvas, name, (width - margin - nw, height - margin - base), font, scale, 255, thick, cv2.LINE_8)
    return canvas > 0


def stamp_rgb(rgb: np.ndarray, t: float, *, name: str | None = None, start: int = EPOCH) -> np.ndarray:
    """An RGB uint8 frame with the overlay drawn white on it (a new array)."""
    out = np.array(rgb)
    out[text_mask(out.shape[0], out.shape[1], t, name=name, start=start)] = 255
    return out


def weave(first: np.ndarray, second: np.ndarray, order: str = "tff") -> np.ndarray:
    """One interlaced frame from two instants: with ``order`` 'tff' the even rows (the top field)
    are ``first``'s, the odd rows ``second``'s; 'bff' the other way round (the bottom field first)."""
    out = np.array(second if order == "tff" else first)
    out[0::2] = (first if order == "tff" else second)[0::2]
    return out


def interlaced(frames, order: str = "tff"):
    """Frames rendered at twice the rate, woven two by two into interlaced frames (field rate = the
    rendered rate, frame rate half of it)."""
    it = iter(frames)
    for a in it:
        b = next(it, None)
        if b is None:
            return
        yield weave(np.array(a), b, order)
