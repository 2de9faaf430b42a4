"""Whole-frame light nuisances injected into an existing clip, with the truth known.

For testing the corrections (``wallcli.camera.corrections``): the same clip with and without a
nuisance, frame for frame and with the same camera noise, so that what changes in an analysis
is the nuisance and its removal alone (``wallcli simulate --flicker/--ae-steps/--drift`` makes a
new noise realisation with each option). Gains multiply the RGB code values.
"""
from __future__ import annotations

from pathlib import Path

import numpy as np

KINDS = ("flicker", "rolling", "exposure", "drift")


def gain_track(kind: str, frames: int, fps: float, height: int, *, strength: float,
               rng: np.random.Generator, mains: float = 50.0, bands: float = 2.5) -> np.ndarray:
    """(frames, height) relative gain of every frame's rows.

    flicker: 1 + strength sin(2 pi alias t + phi), alias = 2 mains folded by fps; rolling: the same
    with the phase advancing ``bands`` cycles down the frame; exposure: two steps of +-strength
    (each a 0.05-0.3 s ramp, at random times in the middle 80 %); drift: strength times the mean of
    two sines of 0.02-0.1 Hz plus a ramp of up to +-strength over the clip.
    """
    t = np.arange(frames) / fps
    rows = (np.arange(height) + 0.5) / height
    if kind in ("flicker", "rolling"):
        f = 2 * mains
        alias = f - fps * np.round(f / fps)
        phase = 2 * np.pi * alias * t[:, None] + rng.uniform(0, 2 * np.pi)
        if kind == "rolling":
            phase = phase + 2 * np.pi * bands * rows[None, :]
        return 1 + strength * np.sin(phase) * np.ones((1, height))
    g = np.ones(frames)
    if kind == "exposure":
        dur = max(t[-1], 1e-3)
        for _ in range(2):
            at = rng.uniform(0.1, 0.9) * dur
            ramp = np.clip((t - at) / rng.uniform(0.05, 0.3), 0, 1)
            g = g * (1 + rng.choice([-1, 1]) * strength * ramp)
    elif kind == "drift":
        slow = sum(np.sin(2 * np.pi * rng.uniform(0.02, 0.1) * t + rng.uniform(0, 2 * np.pi)) for _ in range(2)) / 2
        g = 1 + strength * (slow + rng.uniform(-1, 1) * t / max(t[-1], 1e-3))
    elif kind != "none":
        raise ValueError(f"unknown nuisance {kind!r} (one of {', '.join(KINDS)})")
    return g[:, None] * np.ones((1, height))


def inject(src: str | Path, dst: str | Path, kind: str, *, strength: float, seed: int = 0, **kw) -> np.ndarray:
    """Write ``src`` with the nuisance to ``dst`` (a .mkv: FFV1, 4:4:4 at 16 bits, lossless); returns
    the gains. ``kind`` "none" re-encodes the clip alone (the clean reference).

    The gain multiplies (Y - 16, U - 128, V - 128) of the limited-range planes, so exactly the RGB
    code values whichever YUV matrix a reader applies (RGB is linear in them), and the result is
    kept to 1/256 of a code value: rounding a small gain back to 8 bits would move every pixel of a
    level at once (the source is already rounded, nothing dithers it) and draw steps that a real
    camera, whose light changes before its noise and rounding, does not.
    """
    import av

    with av.open(str(src)) as c:
        stream = c.streams.video[0]
        fps = float(stream.average_rate or 30)
        frames = [f.reformat(format="yuv444p").to_ndarray() for f in c.decode(stream)]
    h, w = frames[0].shape[1:]
    rng = np.random.default_rng(seed)
    gains = np.ones((len(frames), h)) if kind == "none" else gain_track(kind, len(frames), fps, h, strength=strength,
                                                                        rng=rng, **kw)
    zero = np.array([16.0, 128.0, 128.0])[:, None, None]
    with av.open(str(dst), "w", format="matroska") as c:
        s = c.add_stream("ffv1", rate=int(round(fps)) if abs(fps - round(fps)) < 1e-6 else fps)
        s.width, s.height, s.pix_fmt = w, h, "yuv444p16le"
        for planes, g in zip(frames, gains):
            x = np.clip(np.rint(((planes - zero) * g[None, :, None] + zero) * 256.0), 0, 65535).astype(np.uint16)
            frame = av.VideoFrame.from_ndarray(np.ascontiguousarray(x.transpose(1, 2, 0)), format="yuv444p16le")
            frame.color_range = 1  # limited (MPEG) range, as the planes are
            for p in s.encode(frame):
                c.mux(p)
        for p in s.encode():
            c.mux(p)
    return gains
