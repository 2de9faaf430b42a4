"""`wallcli count` on 1080p wall footage against PyAV decode-only, in alternating pairs (issue 36, part 3).

    .venv/bin/python bench/bench_wall_count.py [--seconds 30] [--pairs 5] [--command count|activity|snr|stplot|track]

The clip looks like a wall: `wallcli simulate --people 1 --activity walking --seed 11 --size
1920x1080 --fps 30 --crf 18 --grid 32x32` (made once per length, cached in bench/out/; 30 s takes
about 6 minutes here). bench/clips.py's clip is not used: its 8 repeating noise fields keep the
view check suspicious, so it measures a worst case rather than footage.

Each pair runs, in fresh processes, a PyAV decode-only loop (bench/measure.py: threaded decode,
nothing done with the frames) and the whole command with every check and correction on (start-up
and model load included), in an order that alternates between pairs. The figure is the median over
pairs of (command frames/s) / (decode-only frames/s); pairs keep a loaded machine's slow moments
from landing on one side only. CPU-time ratios are printed too.
"""
from __future__ import annotations

import argparse
import os
import statistics
import subprocess
import sys
from pathlib import Path

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE))

from bench_speed import measure  # noqa: E402  (one job in a fresh process: bench/measure.py)

OUT = HERE / "out"


def wall_clip(seconds: int, fps: int = 30) -> Path:
    """bench/out/hd_walker_<frames>.mp4, simulated if missing."""
    path = OUT / f"hd_walker_{seconds * fps}.mp4"
    if not path.exists():
        OUT.mkdir(parents=True, exist_ok=True)
        print(f"simulating {path.name} (1080p, {seconds} s; minutes) ...", file=sys.stderr)
        subprocess.run([sys.executable, "-m", "wallcli", "simulate", "-o", str(path), "--people", "1",
                        "--activity", "walking", "--seed", "11", "--size", "1920x1080", "--duration",
                        str(seconds), "--fps", str(fps), "--crf", "18", "--grid", "32x32", "--force"],
                       check=True, stdout=subprocess.DEVNULL)
    return path


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--seconds", type=int, default=30)
    ap.add_argument("--pairs", type=int, default=5)
    ap.add_argument("--command", default="count", choices=["count", "activity", "snr", "stplot", "track"])
    ap.add_argument("--clip", default="export", choices=["export", "sim"],
                    help="export: a recording upscaled to 1080p at a real export's bitrate (bench/export_clip.py); "
                         "sim: the simulator's 1080p CRF 18 walker (slow to decode)")
    a = ap.parse_args()
    if a.clip == "export":
        from export_clip import export_clip

        clip = str(export_clip(a.seconds * 30))
    else:
        clip = str(wall_clip(a.seconds))
    cmd = ["wallcli", a.command, clip]
    cmd += ["-o", str(OUT / "bench_wall.npz"), "--force"] if a.command == "stplot" else ["--json"]
    measure("decode", clip)  # page cache and bytecode cache
    measure(*cmd)
    ratios, cpu = [], []
    for i in range(a.pairs):
        if i % 2 == 0:
            dec = measure("decode", clip)
            job = measure(*cmd)
        else:
            job = measure(*cmd)
            dec = measure("decode", clip)
        ratios.append(dec["seconds"] / job["seconds"])
        cpu.append(dec["cpu_seconds"] / job["cpu_seconds"])
        print(f"  pair {i + 1}: decode-only {dec['seconds']:.2f} s ({dec['cpu_seconds']:.1f} CPU s), {a.command} "
              f"{job['seconds']:.2f} s ({job['cpu_seconds']:.1f} CPU s, peak RSS {job['peak_rss_mb']:.0f} MB): "
              f"{ratios[-1]:.2f} x", file=sys.stderr)
    load = os.getloadavg()[0]
    what = ("a recording's walker upscaled to 1080p30, CRF 18 veryfast" if a.clip == "export"
            else "a 1080p30 simulated wall with a walker, CRF 18")
    print(f"{a.command} on {what} ({a.seconds * 30} frames): "
          f"{statistics.median(ratios):.2f} x decode-only throughput, {statistics.median(cpu):.2f} x in CPU time "
          f"(medians of {a.pairs} pairs; wall: {', '.join(f'{r:.2f}' for r in ratios)}); "
          f"load average {load:.1f} on {os.cpu_count()} cores")


if __name__ == "__main__":
    main()
