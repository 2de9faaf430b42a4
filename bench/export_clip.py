"""The real-bitrate bench clip: footage as a recorder exports it (issue 45, part 1).

    .venv/bin/python bench/export_clip.py [--frames 900] [--source t002_p1_walking.mp4]

A walker of the independent renderer's recordings (/work/shared/transfer or $WALLCLI_TRANSFER),
upscaled bicubic to 1920x1080, with fresh noise of +-2 code values in every frame (so that no two
frames repeat and the codec has a sensor's grain to spend bits on), played forward, back and
forward to ``--frames`` frames, written as H.264 CRF 18 ``veryfast`` (about 7 Mbit/s). Cached in
bench/out/; not committed. The simulator's 1080p clip (bench_wall_count.py --clip sim) decodes
slowly (fresh sensor noise in every sample at CRF 18 is a heavy stream), which hides what the
analysis costs; this one decodes at the speed of real exports.
"""
from __future__ import annotations

import argparse
import os
import sys
from pathlib import Path

import numpy as np

OUT = Path(__file__).resolve().parent / "out"
TRANSFER = Path(os.environ.get("WALLCLI_TRANSFER", Path(__file__).resolve().parents[2] / "shared" / "transfer"))
SIZE = (1920, 1080)


def _source_frames(path: Path) -> list[np.ndarray]:
    import av

    with av.open(str(path)) as c:
        return [f.to_ndarray(format="rgb24") for f in c.decode(video=0)]


def export_clip(frames: int = 900, source: str = "t002_p1_walking.mp4", crf: int = 18) -> Path:
    """bench/out/export_<source stem>_<frames>.mp4, made if missing (a minute or two)."""
    import av
    import cv2

    path = OUT / f"export_{Path(source).stem}_{frames}_crf{crf}.mp4"
    if path.exists():
        return path
    src = TRANSFER / source
    if not src.exists():
        raise SystemExit(f"{src} not found: set WALLCLI_TRANSFER to the recordings' folder")
    clip = _source_frames(src)
    order = list(range(len(clip))) + list(range(len(clip) - 2, 0, -1))  # forward and back, no repeated ends
    seq = [order[i % len(order)] for i in range(frames)]
    rng = np.random.default_rng(45)
    OUT.mkdir(parents=True, exist_ok=True)
    tmp = path.with_suffix(".part.mp4")
    print(f"exporting {path.name} ({frames} frames, 1920x1080, CRF {crf} veryfast) ...", file=sys.stderr)
    with av.open(str(tmp), "w") as c:
        s = c.add_stream("libx264", rate=30)
        s.width, s.height, s.pix_fmt = SIZE[0], SIZE[1], "yuv420p"
        s.options = {"crf": str(crf), "preset": "veryfast"}
        big = {}
        for i in seq:
            if i not in big:  # one upscale per source frame, in float (no 8-bit rounding before the noise)
                big[i] = cv2.resize(clip[i].astype(np.float32), SIZE, interpolation=cv2.INTER_CUBIC)
            noisy = big[i] + rng.integers(-2, 3, size=big[i].shape).astype(np.float32)
            rgb = np.clip(np.rint(noisy), 0, 255).astype(np.uint8)
            for p in s.encode(av.VideoFrame.from_ndarray(rgb, format="rgb24")):
                c.mux(p)
        for p in s.encode():
            c.mux(p)
    tmp.replace(path)
    return path


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--frames", type=int, default=900)
    ap.add_argument("--source", default="t002_p1_walking.mp4")
    ap.add_argument("--crf", type=int, default=18)
    a = ap.parse_args()
    path = export_clip(a.frames, a.source, a.crf)
    size = path.stat().st_size
    print(f"{path}: {size / 1e6:.1f} MB, {size * 8 / (a.frames / 30) / 1e6:.1f} Mbit/s")


if __name__ == "__main__":
    main()
