"""Speed and memory of the video commands against PyAV decode-only, measured in one run.

    .venv/bin/python bench/bench_speed.py [--frames 600] [--repeat 2]

On a 1080p30 H.264 clip of N frames (and one 4x as long, for memory), each job runs in a fresh
process (bench/measure.py) and reports wall time, CPU time and peak RSS:
  decode     PyAV decode-only, threaded: the baseline
  stplot     `wallcli stplot CLIP -o plots.npz`       (target >= 0.7 x decode, RSS < 400 MB, flat)
  snr        `wallcli snr CLIP --json`                 (target >= 0.7 x decode)
  count      `wallcli count CLIP --json`               (target >= 0.6 x decode; needs the shipped model)
Ratios are frames/s of the command over frames/s of decode-only from the same run. Whole
commands are timed, start-up (imports, model load) included. CPU-time ratios are printed too:
they move least when other work loads the machine.
"""
from __future__ import annotations

import argparse
import json
import os
import subprocess
import sys
from pathlib import Path

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE))

from clips import OUT, clip_1080p  # noqa: E402


def measure(*args: str) -> dict:
    out = subprocess.run([sys.executable, str(HERE / "measure.py"), *args], capture_output=True, text=True)
    if out.returncode:
        raise SystemExit(f"{' '.join(args)} failed:\n{out.stderr}")
    return json.loads(out.stdout.strip().splitlines()[-1])


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--frames", type=int, default=600)
    ap.add_argument("--repeat", type=int, default=2, help="runs per measurement; the fastest counts")
    args = ap.parse_args()
    clip = clip_1080p(args.frames)
    long_clip = clip_1080p(4 * args.frames)
    npz = OUT / "bench_stplot.npz"

    def best(*job):
        return min((measure(*job) for _ in range(args.repeat)), key=lambda r: r["seconds"])

    jobs = {
        "stplot": ("wallcli", "stplot", "{clip}", "-o", str(npz), "--force"),
        "snr": ("wallcli", "snr", "{clip}", "--json"),
        "count": ("wallcli", "count", "{clip}", "--json"),
    }
    have_model = (HERE.parent / "models" / "count.onnx").exists()
    dec = best("decode", str(clip))
    dec4 = best("decode", str(long_clip))
    dec_fps = args.frames / dec["seconds"]
    dec4_fps = 4 * args.frames / dec4["seconds"]
    tiny = clip_1080p(3)  # a command on 3 frames costs its start-up: imports, model load
    load = os.getloadavg()[0]
    print(f"1080p30 H.264, {args.frames} frames (and {4 * args.frames} for memory), best of {args.repeat}; "
          f"load average {load:.1f} on {os.cpu_count()} cores")
    print(f"  {'job':<8} {'frames/s':>9} {'x decode':>9} {'x decode (CPU)':>15} {'peak RSS':>9} "
          f"{'4x clip: frames/s':>18} {'x decode':>9} {'peak RSS':>9} {'start-up':>9} {'steady x decode':>16}")
    print(f"  {'decode':<8} {dec_fps:9.1f} {1.0:9.2f} {1.0:15.2f} {dec['peak_rss_mb']:7.0f}MB "
          f"{dec4_fps:18.1f} {1.0:9.2f} {dec4['peak_rss_mb']:7.0f}MB")
    for name, job in jobs.items():
        if name == "count" and not have_model:
            print("  count    (skipped: models/count.onnx is not there)")
            continue
        r = best(*(a.format(clip=clip) for a in job))
        r4 = best(*(a.format(clip=long_clip) for a in job))
        r0 = best(*(a.format(clip=tiny) for a in job)) if name != "count" else None
        fps = args.frames / r["seconds"]
        fps4 = 4 * args.frames / r4["seconds"]
        # Steady state: the long run without the command's fixed start-up cost.
        steady = f"{(4 * args.frames - 3) / (r4['seconds'] - r0['seconds']) / dec4_fps:16.2f}" if r0 else f"{'(< 256 frames)':>16}"
        start = f"{r0['seconds']:8.2f}s" if r0 else f"{'-':>9}"
        print(f"  {name:<8} {fps:9.1f} {fps / dec_fps:9.2f} {dec['cpu_seconds'] / r['cpu_seconds']:15.2f} "
              f"{r['peak_rss_mb']:7.0f}MB {fps4:18.1f} {fps4 / dec4_fps:9.2f} {r4['peak_rss_mb']:7.0f}MB {start} {steady}")


if __name__ == "__main__":
    main()
