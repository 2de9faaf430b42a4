"""Simulator throughput: labelled windows per second, the number training cares about.

    .venv/bin/python bench/bench_sim.py [--scenes 8] [--jobs 2] [--task count] [--profile]

Runs dataset mode end to end (render -> camera -> encode -> decode -> stplot -> windows) into a
temporary folder and prints windows/s for one process and for --jobs processes.
"""

from __future__ import annotations

import argparse
import cProfile
import pstats
import tempfile
import time


def main() -> None:
    ap = argparse.ArgumentParser()
    ap.add_argument("--scenes", type=int, default=8)
    ap.add_argument("--jobs", type=int, default=2)
    ap.add_argument("--task", default="count")
    ap.add_argument("--world", default="room")
    ap.add_argument("--windows-per-scene", type=int, default=4)
    ap.add_argument("--profile", action="store_true", help="cProfile the single-process run")
    args = ap.parse_args()

    from wallcli.datagen.clips import render_windows
    from wallcli.datagen.dataset import build_dataset

    wps = args.windows_per_scene
    t0 = time.perf_counter()
    prof = cProfile.Profile() if args.profile else None
    if prof:
        prof.enable()
    n = 0
    for i in range(args.scenes):
        n += len(render_windows(1234, i, args.task, world=args.world, windows=wps)["label"])
    if prof:
        prof.disable()
        pstats.Stats(prof).sort_stats("tottime").print_stats(15)
    dt = time.perf_counter() - t0
    print(f"1 process : {n} windows from {args.scenes} scenes in {dt:.1f} s = {n / dt:.2f} windows/s "
          f"({dt / args.scenes:.2f} s/scene)")
    if args.jobs > 1:
        with tempfile.TemporaryDirectory() as d:
            total = args.scenes * wps
            t0 = time.perf_counter()
            build_dataset(d, total, args.task, seed=99, jobs=args.jobs, world=args.world, windows_per_scene=wps,
                          shard_scenes=max(1, args.scenes // 2))
            dt = time.perf_counter() - t0
        print(f"{args.jobs} processes: {total} windows in {dt:.1f} s = {total / dt:.2f} windows/s")


if __name__ == "__main__":
    main()
