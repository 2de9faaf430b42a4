"""Not-a-wall clips made from simulated wall clips, to test the view check with known truth.

Each function takes and yields uint8 RGB frames (H, W, 3), so it composes with
``Scene.frames()``: a sprite crossing the view, a pan, a shake, a cut to a second clip. Motions
are exact warps (not the camera model's first-order shift), so any amplitude is faithful.
"""
from __future__ import annotations

from typing import Iterable, Iterator

import numpy as np

KINDS = ("sprite", "pan", "shake", "cut")


def _warp(img: np.ndarray, dx: float, dy: float) -> np.ndarray:
    import cv2

    m = np.float32([[1, 0, dx], [0, 1, dy]])
    return cv2.warpAffine(img, m, (img.shape[1], img.shape[0]), flags=cv2.INTER_LINEAR, borderMode=cv2.BORDER_REFLECT)


def sprite(frames: Iterable[np.ndarray], rng, *, n: int, fps: float, contrast=(0.15, 0.6),
           size=(0.12, 0.4)) -> Iterator[np.ndarray]:
    """A soft-edged upright ellipse (a person or object) crossing the view once, at a random
    time, speed and height; its colour differs from the wall by ``contrast`` (relative)."""
    import cv2

    frames = iter(frames)
    first = next(frames)
    H, W = first.shape[:2]
    h = rng.uniform(*size) * H * 2
    w = h * rng.uniform(0.3, 0.6)
    level = float(first.mean())
    sign = rng.choice([-1.0, 1.0]) if level < 200 else -1.0
    colour = np.clip(level * (1 + sign * rng.uniform(*contrast) * rng.uniform(0.8, 1.2, 3)), 0, 255)
    dur = rng.uniform(0.8, 2.5)  # seconds in view
    t0 = rng.uniform(0, max(n / fps - dur, 0.01))
    y = rng.uniform(0.3, 0.7) * H
    left = rng.random() < 0.5
    i = 0
    for f in _chain(first, frames):
        u = (i / fps - t0) / dur
        if 0 <= u <= 1:
            x = (-w + u * (W + 2 * w)) if left else (W + w - u * (W + 2 * w))
            mask = np.zeros((H, W), np.float32)
            cv2.ellipse(mask, (int(x), int(y)), (int(w / 2), int(h / 2)), 0, 0, 360, 1.0, -1)
            mask = cv2.GaussianBlur(mask, (0, 0), 0.7)[..., None]  # an in-focus outline: a pixel or two
            f = np.clip(f * (1 - mask) + colour * mask + 0.5, 0, 255).astype(np.uint8)
        yield f
        i += 1


def pan(frames: Iterable[np.ndarray], rng, *, n: int, fps: float, amplitude: float) -> Iterator[np.ndarray]:
    """A pan of ``amplitude`` pixels in total, in a random direction, over a random 1-3 s."""
    ang = rng.uniform(0, 2 * np.pi)
    dur = rng.uniform(1.0, 3.0)
    t0 = rng.uniform(0, max(n / fps - dur, 0.01))
    for i, f in enumerate(frames):
        u = np.clip((i / fps - t0) / dur, 0, 1)
        yield _warp(f, amplitude * u * np.cos(ang), amplitude * u * np.sin(ang)) if u > 0 else f


def shake(frames: Iterable[np.ndarray], rng, *, n: int, fps: float, rms: float) -> Iterator[np.ndarray]:
    """Hand-held shake: a smooth random displacement of ``rms`` pixels per axis (time scale 0.1-0.5 s)."""
    tau = rng.uniform(0.1, 0.5) * fps
    a = np.exp(-1 / tau)
    s = rng.standard_normal(2) * rms
    for f in frames:
        s = a * s + rng.standard_normal(2) * rms * np.sqrt(1 - a * a)
        yield _warp(f, s[0], s[1])


def cut(frames: Iterable[np.ndarray], other: Iterable[np.ndarray], rng, *, n: int) -> Iterator[np.ndarray]:
    """The first clip up to a random frame, then the second."""
    at = int(rng.integers(n // 4, 3 * n // 4))
    for i, (a, b) in enumerate(zip(frames, other)):
        yield a if i < at else b


def encode(frames: Iterable[np.ndarray], path, *, fps: float, crf: int = 18):
    """Write uint8 RGB frames (the size of the first) as H.264 at ``crf``, as `wallcli simulate`
    does; returns ``path``."""
    from wallcli.io.writer import VideoWriter

    frames = iter(frames)
    first = next(frames)
    with VideoWriter(path, fps, first.shape[1], first.shape[0], codec="libx264", crf=crf) as vw:
        vw.write(first)
        for f in frames:
            vw.write(f)
    return path


def _chain(first, rest):
    yield first
    yield from rest
