"""The shared decode path against PyAV decode-only: 5 alternating pairs in one run, their median.

    .venv/bin/python bench/bench_decode_path.py [--frames 600] [--pairs 5] [--vertical/--no-vertical]

Every video command reads frames the same way: ``open_video`` -> ``Planes`` (views of the decoded
buffers) -> ``RowReducer`` (the exact per-frame column and row sums behind stplot, count,
activity, scan and report). Each job runs in a fresh process on the 1080p30 clip of
bench/clips.py, imports done before the clock starts, so the ratio is the per-frame cost alone:

  decode   PyAV decode-only, threaded (thread_type AUTO): the baseline
  path     the same decode through wallcli.io.video plus RowReducer on every frame

The two run one after the other, ``--pairs`` times; each pair gives path frames/s over decode
frames/s, and the median of those ratios is the figure (target >= 0.85). Pairs keep a loaded
machine's slow moments from landing on one side only.
"""
from __future__ import annotations

import argparse
import json
import os
import statistics
import subprocess
import sys
import time
from pathlib import Path

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE))


def _job(kind: str, clip: str, vertical: bool) -> dict:
    import resource

    import av

    if kind == "path":
        from wallcli.io.video import open_video
        from wallcli.signal.blocks import check_roi
        from wallcli.signal.stplot import RowReducer
    t0 = time.perf_counter()
    c0 = resource.getrusage(resource.RUSAGE_SELF)
    n = 0
    if kind == "decode":
        with av.open(clip) as c:
            s = c.streams.video[0]
            s.thread_type = "AUTO"
            for _ in c.decode(s):
                n += 1
    else:
        reduce = None
        with open_video(clip) as reader:
            for frame in reader.frames():
                if reduce is None:
                    roi = check_roi(None, frame.planes.width, frame.planes.height)
                    reduce = RowReducer(roi, 64, vertical)
                reduce(frame.planes)
                n += 1
    seconds = time.perf_counter() - t0
    c1 = resource.getrusage(resource.RUSAGE_SELF)
    cpu = (c1.ru_utime - c0.ru_utime) + (c1.ru_stime - c0.ru_stime)
    return {"kind": kind, "frames": n, "seconds": seconds, "cpu_seconds": cpu}


def _run(kind: str, clip: Path, vertical: bool) -> dict:
    args = [sys.executable, __file__, "--job", kind, "--clip", str(clip)] + ([] if vertical else ["--no-vertical"])
    out = subprocess.run(args, capture_output=True, text=True)
    if out.returncode:
        raise SystemExit(f"{kind} failed:\n{out.stderr}")
    return json.loads(out.stdout.strip().splitlines()[-1])


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--frames", type=int, default=600)
    ap.add_argument("--pairs", type=int, default=5)
    ap.add_argument("--vertical", action=argparse.BooleanOptionalAction, default=True,
                    help="also the vertical profile (stplot, activity); --no-vertical: count's horizontal only")
    ap.add_argument("--fresh-noise", action="store_true",
                    help="a clip with new noise in every frame (camera-like decode cost) instead of the 8 reused fields")
    ap.add_argument("--job", choices=["decode", "path"], help=argparse.SUPPRESS)
    ap.add_argument("--clip", help=argparse.SUPPRESS)
    a = ap.parse_args()
    if a.job:
        print(json.dumps(_job(a.job, a.clip, a.vertical)))
        return
    from clips import clip_1080p

    clip = clip_1080p(a.frames, fresh=a.fresh_noise)
    ratios, cpu_ratios = [], []
    print(f"1080p30 H.264{' (fresh noise every frame)' if a.fresh_noise else ''}, {a.frames} frames, {a.pairs} pairs, vertical={a.vertical}; "
          f"load average {os.getloadavg()[0]:.1f} on {os.cpu_count()} cores")
    for i in range(a.pairs):
        d, p = _run("decode", clip, a.vertical), _run("path", clip, a.vertical)
        assert d["frames"] == p["frames"] == a.frames, (d, p)
        ratio = d["seconds"] / p["seconds"]
        ratios.append(ratio)
        cpu_ratios.append(d["cpu_seconds"] / p["cpu_seconds"])
        print(f"  pair {i + 1}: decode {a.frames / d['seconds']:6.1f} frames/s ({d['cpu_seconds']:.2f} CPU s), "
              f"path {a.frames / p['seconds']:6.1f} frames/s ({p['cpu_seconds']:.2f} CPU s): {ratio:.2f} x decode")
    print(f"median {statistics.median(ratios):.2f} x decode (wall), {statistics.median(cpu_ratios):.2f} (CPU); "
          f"pairs {', '.join(f'{r:.2f}' for r in ratios)}; load average now {os.getloadavg()[0]:.1f}")


if __name__ == "__main__":
    main()
