"""The benchmark clip: a 1080p30 H.264 wall with camera-like noise and a faint moving shadow.

Made once per length and cached in bench/out/ (ignored by git). Noise keeps the bitrate, and so
the decode cost, realistic: a noiseless synthetic wall would decode unrealistically fast.
"""
from __future__ import annotations

from pathlib import Path

import numpy as np

OUT = Path(__file__).resolve().parent / "out"


def clip_1080p(frames: int, fresh: bool = False) -> Path:
    """bench/out/wall1080_<frames>.mp4 (wall1080_fresh_<frames>.mp4 with ``fresh``), made if missing."""
    path = OUT / (f"wall1080_fresh_{frames}.mp4" if fresh else f"wall1080_{frames}.mp4")
    if not path.exists():
        make_clip(path, frames, fresh=fresh)
    return path


def make_clip(path: Path, frames: int = 600, width: int = 1920, height: int = 1080, fps: int = 30,
              fresh: bool = False) -> Path:
    """``fresh``: new noise in every frame, as a camera's sensor gives, instead of 8 fields
    reused in turn. At CRF 18 the encoder quantises this noise away either way: the fresh clip
    is as large (1.7 against 1.5 MB for 600 frames) and decodes at the same CPU cost
    (bench/RESULTS.md, session 17), so the reused fields do not make the benchmark easier or
    harder."""
    import av

    path.parent.mkdir(parents=True, exist_ok=True)
    rng = np.random.default_rng(0)
    yy, xx = np.mgrid[0:height, 0:width].astype(np.float32)
    wall = 150.0 + 40.0 * np.exp(-((xx - 0.6 * width) ** 2 + (yy - 0.3 * height) ** 2) / (0.5 * width) ** 2)
    wall = np.repeat(wall[..., None], 3, axis=2) * np.array([1.0, 0.95, 0.85], np.float32)
    # 8 noise fields reused in turn: generating 600 fresh 1080p fields costs more than encoding.
    noise = [rng.normal(0, 1.5, (height, width, 3)).astype(np.float32) for _ in range(8)]
    tmp = path.with_suffix(".tmp.mp4")
    with av.open(str(tmp), "w") as c:
        s = c.add_stream("libx264", rate=fps)
        s.width, s.height, s.pix_fmt = width, height, "yuv420p"
        s.options = {"crf": "18", "preset": "veryfast"}
        for i in range(frames):
            # A faint shadow sweeping across the wall (about 1 % of the level), like a person walking.
            cx = (i / frames) * width
            shadow = 1.0 - 0.01 * np.exp(-((xx[:1] - cx) ** 2) / (0.1 * width) ** 2)
            field = rng.normal(0, 1.5, (height, width, 3)).astype(np.float32) if fresh else noise[i % len(noise)]
            img = wall * shadow[..., None] + field
            frame = av.VideoFrame.from_ndarray(np.clip(img + 0.5, 0, 255).astype(np.uint8), format="rgb24")
            for p in s.encode(frame):
                c.mux(p)
        for p in s.encode():
            c.mux(p)
    tmp.replace(path)
    return path
