"""Foundation benchmark (issue 2): decode vs `wallcli stplot` on 1080p30 H.264, and memory.

    .venv/bin/python bench/bench_video.py [--frames 600]

Makes a 1080p30 H.264 clip of N frames and one 4x as long (cached in bench/out/), then runs
each job in its own process (bench/measure.py) and reports, from this one run:
  PyAV decode-only frames/s (threaded), `wallcli stplot` frames/s, their ratio (target >= 0.7),
  stplot peak RSS on the clip and on the 4x clip (target < 400 MB and flat in length).
"""
from __future__ import annotations

import argparse
import json
import subprocess
import sys
from pathlib import Path

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE))

from bench_snr import make_clip  # noqa: E402  (one clip recipe for every benchmark)


def measure(*args: str) -> dict:
    out = subprocess.run([sys.executable, str(HERE / "measure.py"), *args], capture_output=True, text=True, check=True)
    return json.loads(out.stdout.strip().splitlines()[-1])


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--frames", type=int, default=600)
    ap.add_argument("--repeat", type=int, default=2, help="runs per measurement; the fastest counts")
    args = ap.parse_args()
    out = HERE / "out"
    clip = out / f"wall1080_{args.frames}.mp4"
    long_clip = out / f"wall1080_{4 * args.frames}.mp4"
    for path, n in ((clip, args.frames), (long_clip, 4 * args.frames)):
        if not path.exists():
            print(f"making {path.name} ({n} frames) ...", file=sys.stderr)
            make_clip(path, frames=n)
    npz = out / "bench_stplot.npz"

    def best(*job):
        runs = [measure(*job) for _ in range(args.repeat)]
        return min(runs, key=lambda r: r["seconds"])

    dec = best("decode", str(clip))
    stp = best("wallcli", "stplot", str(clip), "-o", str(npz), "--force")
    stp_long = measure("wallcli", "stplot", str(long_clip), "-o", str(npz), "--force")
    dec_fps = dec["frames"] / dec["seconds"]
    stp_fps = args.frames / stp["seconds"]
    rows = [
        ("PyAV decode-only (threaded)", f"{dec_fps:.1f} frames/s", f"{dec['peak_rss_mb']:.0f} MB"),
        ("wallcli stplot", f"{stp_fps:.1f} frames/s", f"{stp['peak_rss_mb']:.0f} MB"),
        ("stplot / decode ratio", f"{stp_fps / dec_fps:.2f} (target >= 0.7)", ""),
        (f"wallcli stplot, 4x clip ({4 * args.frames} frames)", f"{4 * args.frames / stp_long['seconds']:.1f} frames/s",
         f"{stp_long['peak_rss_mb']:.0f} MB"),
        ("peak RSS growth 4x / 1x", f"{stp_long['peak_rss_mb'] / stp['peak_rss_mb']:.2f} (flat = 1.0)", ""),
    ]
    width = max(len(r[0]) for r in rows)
    print(f"1080p30 H.264, {args.frames} frames, best of {args.repeat}")
    for name, a, b in rows:
        print(f"  {name:<{width}}  {a:<28} {b}")


if __name__ == "__main__":
    main()
