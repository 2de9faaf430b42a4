"""Per-stage CPU time of `wallcli count` on one clip (issue 45, part 1): each camera-pipeline
check's own work, timed with the thread's CPU clock around its entry points.

    .venv/bin/python research/speed/stages.py bench/out/export_t002_p1_walking_900_crf18.mp4
"""
from __future__ import annotations

import contextlib
import io
import sys
import time
from collections import defaultdict

SPENT: dict[str, float] = defaultdict(float)


def wrap(owner, name: str, label: str) -> None:
    fn = getattr(owner, name)

    def timed(*a, **k):
        t0 = time.thread_time()
        try:
            return fn(*a, **k)
        finally:
            SPENT[label] += time.thread_time() - t0

    setattr(owner, name, timed)


def main() -> None:
    from wallcli.camera import interlace, overlay, repeats, tnr
    from wallcli.view import check as view
    from wallcli.infer import classify
    from wallcli.io import video

    wrap(overlay.OverlayFilter, "_observe", "overlay.observe")
    wrap(overlay.OverlayFilter, "_judge", "overlay.judge")
    wrap(overlay.OverlayFilter, "_static", "overlay.static")
    wrap(overlay.OverlayFilter, "_fill", "overlay.fill")
    wrap(repeats.RepeatFilter, "_difference", "repeats")
    wrap(interlace.InterlaceFilter if hasattr(interlace, "InterlaceFilter") else interlace.Interlace, "_observe",
         "interlace.observe")
    wrap(tnr.TemporalNoise, "__call__", "tnr")
    wrap(view.ViewCheck, "__call__", "view")
    wrap(classify.WindowClassifier, "push", "windows+nets")
    from wallcli.signal import blocks as _b
    from wallcli.infer import stream as _s
    wrap(_b.RgbProjector, "_project", "projection")
    first = {}
    orig = video.VideoReader.frames

    def frames(self):
        for i, f in enumerate(orig(self)):
            if i == 0:
                first["main"] = time.thread_time()
            yield f

    video.VideoReader.frames = frames
    from wallcli.cli.app import main as cli
    import threading

    ends: dict[str, float] = defaultdict(float)
    run0 = threading.Thread.run

    def run(self):
        try:
            run0(self)
        finally:
            ends[self.name] += time.thread_time()

    threading.Thread.run = run

    t0, c0 = time.perf_counter(), time.process_time()
    with contextlib.redirect_stdout(io.StringIO()):
        try:
            cli(["count", sys.argv[1], "--json"])
        except SystemExit:
            pass
    wall, cpu = time.perf_counter() - t0, time.process_time() - c0
    main_cpu = time.thread_time()
    print(f"wall {wall:.2f} s, process CPU {cpu:.2f} s; main thread {main_cpu:.2f} s "
          f"({first.get('main', 0):.2f} s before the first frame)")
    import os
    tick = os.sysconf("SC_CLK_TCK")
    by = defaultdict(float)
    for tid in os.listdir("/proc/self/task"):
        try:
            stat = open(f"/proc/self/task/{tid}/stat").read()
            comm = open(f"/proc/self/task/{tid}/comm").read().strip()
        except OSError:
            continue
        f = stat.rsplit(")", 1)[1].split()
        by[comm] += (int(f[11]) + int(f[12])) / tick
    print("  python threads that ended:", ", ".join(f"{k} {v:.2f} s" for k, v in ends.items()))
    print("  threads still alive:", ", ".join(f"{k} {v:.2f} s" for k, v in sorted(by.items(), key=lambda kv: -kv[1])))
    for k, v in sorted(SPENT.items(), key=lambda kv: -kv[1]):
        print(f"  {k:20s} {v:6.2f} s")


if __name__ == "__main__":
    main()
