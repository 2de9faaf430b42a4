"""Speed of `wallcli snr` against PyAV decode-only on a 1080p30 H.264 clip (issue 3: >= 0.7x).

    .venv/bin/python bench/bench_snr.py [--clip bench/out/wall1080.mp4] [--frames 600] [--repeat 1]

Makes the clip once if it is missing (a textured wall with camera-like noise and a faint moving
shadow, libx264 crf 18, yuv420p; noise keeps the bitrate and decode cost realistic), then times:
  decode   PyAV decode of every frame through wallcli's reader (planes only, nothing computed);
  snr      the full `wallcli snr CLIP --json` command, in-process (decode + estimator + JSON).
Prints both rates and the ratio snr/decode. Both use the same reader and decoder threads, so the
ratio measures what the estimator adds on top of decoding.
"""
from __future__ import annotations

import argparse
import contextlib
import io
import json
import sys
import time
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT))


def make_clip(path: Path, frames: int = 600, width: int = 1920, height: int = 1080, fps: int = 30) -> Path:
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
            img = wall * shadow[..., None] + noise[i % len(noise)]
            frame = av.VideoFrame.from_ndarray(np.clip(img + 0.5, 0, 255).astype(np.uint8), format="rgb24")
            for p in s.encode(frame):
                c.mux(p)
        for p in s.encode():
            c.mux(p)
    tmp.replace(path)
    return path


def decode_only(clip: Path, threads: int = 0) -> tuple[int, float]:
    from wallcli.io.video import open_video

    t0 = time.perf_counter()
    n = 0
    with open_video(clip, threads=threads) as r:
        for _ in r.frames():
            n += 1
    return n, time.perf_counter() - t0


def snr_run(clip: Path, extra: list[str]) -> tuple[int, float, dict]:
    from wallcli.cli.app import main

    buf = io.StringIO()
    t0 = time.perf_counter()
    with contextlib.redirect_stdout(buf):
        try:
            main(["snr", str(clip), "--json", *extra])
        except SystemExit as exc:
            if exc.code:
                raise RuntimeError(f"wallcli snr failed with exit code {exc.code}") from None
    dt = time.perf_counter() - t0
    out = json.loads(buf.getvalue())
    return int(out["frames"]), dt, out


def main() -> None:
    ap = argparse.ArgumentParser()
    ap.add_argument("--clip", type=Path, default=ROOT / "bench" / "out" / "wall1080.mp4")
    ap.add_argument("--frames", type=int, default=600)
    ap.add_argument("--repeat", type=int, default=1, help="time each side this many times, keep the best")
    ap.add_argument("--threads", type=int, default=0)
    ap.add_argument("--roi", default=None, help="pass --roi to snr (default: whole frame)")
    a = ap.parse_args()
    if not a.clip.exists():
        print(f"making {a.clip} ({a.frames} frames, 1920x1080, 30 fps) ...", file=sys.stderr)
        make_clip(a.clip, a.frames)
    extra = ["--threads", str(a.threads)] + (["--roi", a.roi] if a.roi else [])
    # Import and warm up everything once so neither side pays for module loading.
    decode_only(a.clip, a.threads) if a.repeat > 1 else None
    best_dec = best_snr = float("inf")
    for _ in range(a.repeat):
        n_dec, t_dec = decode_only(a.clip, a.threads)
        n_snr, t_snr, out = snr_run(a.clip, extra)
        best_dec, best_snr = min(best_dec, t_dec), min(best_snr, t_snr)
    fps_dec, fps_snr = n_dec / best_dec, n_snr / best_snr
    print(f"snr bench: {a.clip.name} {n_dec} frames")
    print(f"  decode-only  {fps_dec:7.1f} frames/s")
    print(f"  wallcli snr  {fps_snr:7.1f} frames/s   (snr_db r,g,b = {', '.join(f'{x:.1f}' for x in out['snr_db'])})")
    print(f"  ratio        {fps_snr / fps_dec:7.2f}   (target >= 0.70)")


if __name__ == "__main__":
    main()
