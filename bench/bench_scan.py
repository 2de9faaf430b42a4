"""`wallcli scan` against what it replaces, measured in one run.

    .venv/bin/python bench/bench_scan.py [--clips 40] [--workers 2] [--frames 600] [--copies 4]

1. Many short clips: `wallcli scan DIR -o r.jsonl --workers 2` against a shell loop of
   `wallcli count`, `wallcli activity` and `wallcli snr` (--json) on every clip (target: scan
   >= 3x faster). The clips are simulated walls, 12 s at 320x240 and 30 fps, H.264 crf 18, made
   once and cached in bench/out/scan_clips/. Both sides are whole commands, start-up included,
   and must agree on every label.
2. The 1080p clip of bench/clips.py: videos/s of scan (--copies hard links of the clip, so each
   is a video of its own) against PyAV decode-only of the same clip (threaded, in a fresh
   process: bench/measure.py), and the same per worker from the seconds each line reports.
"""
from __future__ import annotations

import argparse
import json
import os
import shutil
import subprocess
import sys
import time
from concurrent.futures import ProcessPoolExecutor
from pathlib import Path

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE))

from clips import OUT, clip_1080p  # noqa: E402

WALLCLI = str(Path(sys.executable).with_name("wallcli"))
SIM = ["--duration", "12", "--size", "320x240", "--fps", "30", "--grid", "16x16", "--crf", "18"]
KINDS = [["--people", "0"], ["--people", "1", "--activity", "walking"], ["--people", "1", "--activity", "jumping"],
         ["--people", "2", "--activity", "walking,waving"]]


def _simulate(args: tuple[str, list[str]]) -> None:
    path, spec = args
    subprocess.run([WALLCLI, "simulate", "-o", path, *spec, *SIM], check=True, capture_output=True)


def short_clips(n: int) -> Path:
    folder = OUT / "scan_clips"
    folder.mkdir(parents=True, exist_ok=True)
    todo = [(str(folder / f"clip{i:03d}.mp4"), [*KINDS[i % len(KINDS)], "--seed", str(i)])
            for i in range(n) if not (folder / f"clip{i:03d}.mp4").exists()]
    if todo:
        print(f"simulating {len(todo)} clips into {folder} (once) ...", flush=True)
        with ProcessPoolExecutor(2) as pool:
            list(pool.map(_simulate, todo))
    return folder


def timed(cmd: list[str], **kw) -> tuple[float, subprocess.CompletedProcess]:
    t0 = time.perf_counter()
    out = subprocess.run(cmd, capture_output=True, text=True, **kw)
    if out.returncode:
        raise SystemExit(f"{' '.join(cmd[:4])} ... failed:\n{out.stderr}")
    return time.perf_counter() - t0, out


def bench_many(n: int, workers: int) -> None:
    folder = short_clips(n)
    clips = sorted(folder.glob("clip*.mp4"))[:n]
    work = OUT / "scan_work"
    shutil.rmtree(work, ignore_errors=True)
    (work / "in").mkdir(parents=True)
    for c in clips:
        os.link(c, work / "in" / c.name)
    loop = "\n".join(f'{WALLCLI} count "$f" --json; {WALLCLI} activity "$f" --json; {WALLCLI} snr "$f" --json'
                     .replace('"$f"', f'"{c}"') for c in clips)
    load0 = os.getloadavg()[0]
    t_loop, loop_out = timed(["bash", "-e", "-c", loop])
    t_scan, scan_out = timed([WALLCLI, "scan", str(work / "in"), "-o", str(work / "r.jsonl"), "--workers",
                              str(workers), "--json"])
    load1 = os.getloadavg()[0]
    answers = [json.loads(s) for s in loop_out.stdout.splitlines()]
    single = {}
    for a in answers:
        if "task" in a:
            single[Path(a["input"]).name, a["task"]] = a["label"]
    lines = [json.loads(s) for s in (work / "r.jsonl").read_text().splitlines()]
    agree = sum(line[t]["label"] == single[Path(line["input"]).name, t] for line in lines for t in ("count", "activity"))
    summary = json.loads(scan_out.stdout)
    print(f"{n} clips of 12 s at 320x240 (H.264 crf 18); load average {load0:.1f} before, {load1:.1f} after, "
          f"{os.cpu_count()} cores")
    print(f"  shell loop count+activity+snr: {t_loop:7.1f} s  ({n / t_loop:.2f} videos/s)")
    print(f"  scan --workers {workers}:            {t_scan:7.1f} s  ({n / t_scan:.2f} videos/s; "
          f"{summary['ok']} ok, {summary['failed']} failed)")
    print(f"  scan is {t_loop / t_scan:.2f}x faster; labels agree on {agree} of {2 * len(lines)}")


def bench_1080p(frames: int, copies: int, workers: int) -> None:
    clip = clip_1080p(frames)
    work = OUT / "scan_1080"
    shutil.rmtree(work, ignore_errors=True)
    (work / "in").mkdir(parents=True)
    for i in range(copies):
        os.link(clip, work / "in" / f"copy{i}.mp4")
    decode = min((json.loads(timed([sys.executable, str(HERE / "measure.py"), "decode", str(clip)])[1]
                             .stdout.splitlines()[-1])["seconds"] for _ in range(2)))
    t_scan, out = timed([WALLCLI, "scan", str(work / "in"), "-o", str(work / "r.jsonl"), "--workers", str(workers),
                         "--json"])
    lines = [json.loads(s) for s in (work / "r.jsonl").read_text().splitlines()]
    per_video = sum(line["seconds"] for line in lines) / len(lines)
    print(f"1080p30 H.264, {frames} frames; {copies} copies; load average {os.getloadavg()[0]:.1f}")
    print(f"  decode-only (PyAV, threaded):  {1 / decode:.3f} videos/s ({frames / decode:.0f} frames/s)")
    print(f"  scan --workers {workers}, whole command: {copies / t_scan:.3f} videos/s = {copies / t_scan * decode:.2f} x decode "
          f"(cluster start-up included)")
    print(f"  scan, per worker from the lines: {1 / per_video:.3f} videos/s each ({frames / per_video:.0f} frames/s), "
          f"{workers} workers: {workers / per_video * decode:.2f} x decode")


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--clips", type=int, default=40)
    ap.add_argument("--workers", type=int, default=2)
    ap.add_argument("--frames", type=int, default=600)
    ap.add_argument("--copies", type=int, default=4)
    args = ap.parse_args()
    bench_many(args.clips, args.workers)
    bench_1080p(args.frames, args.copies, args.workers)


if __name__ == "__main__":
    main()
