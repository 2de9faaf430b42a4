"""Where count, activity, track and stplot spend their CPU, per stage (issue 60 point 1).

    .venv/bin/python bench/profile_stages.py CLIP [--commands count,activity,track,stplot] [--pairs 3]

For each command: ``--pairs`` pairs of fresh processes, PyAV decode-only (bench/measure.py) and the
plain command, each measured as CPU seconds (user + sys of the process and all its threads:
``resource.getrusage(RUSAGE_CHILDREN)`` around the subprocess), so a loaded machine, which
stretches wall time, distorts the figure least. The analysis is (command - decode-only) CPU, read as a
share of decode-only; the median over pairs is reported, with the wall ratio (decode-only wall /
command wall). Then one more run of the command with its stages' entry points wrapped in the
thread's CPU clock gives the split per stage, in CPU ms per frame (the wrapping itself costs a little).
"""
from __future__ import annotations

import contextlib
import io
import json
import os
import resource
import statistics
import subprocess
import sys
import tempfile
import time
from collections import defaultdict
from pathlib import Path

HERE = Path(__file__).resolve().parent
SPENT: dict[str, float] = defaultdict(float)


def _wrap(owner, name: str, label: str) -> None:
    fn = getattr(owner, name, None)
    if fn is None:
        return

    def timed(*a, **k):
        t0 = time.thread_time()
        try:
            return fn(*a, **k)
        finally:
            SPENT[label] += time.thread_time() - t0

    setattr(owner, name, timed)


def _instrument() -> None:
    from wallcli.camera import interlace, overlay, repeats, tnr
    from wallcli.infer import classify
    from wallcli.io import video
    from wallcli.signal import blocks
    from wallcli.snr import column
    from wallcli.view import check

    _wrap(repeats.RepeatFilter, "_difference", "camera: repeats")
    for n in ("_observe", "_judge", "_static", "_fill"):
        _wrap(overlay.OverlayFilter, n, "camera: overlay")
    _wrap(interlace.InterlaceFilter, "_observe", "camera: interlace")
    _wrap(tnr.TemporalNoise, "__call__", "camera: TNR tap")
    _wrap(check.ViewCheck, "__call__", "view check")
    _wrap(column.ColumnSnr, "push", "column SNR")
    _wrap(column.ColumnSnr, "_flush", "column SNR")
    _wrap(blocks.RgbProjector, "_project", "projection (+ shift registration)")
    _wrap(classify.WindowClassifier, "push", "windows + nets")
    _wrap(video.VideoReader, "_planes", "reader: planes")
    try:
        from wallcli.signal import track

        _wrap(track, "darkness", "tracker")
    except ImportError:
        pass
    try:
        from wallcli.signal import stplot

        _wrap(stplot, "_finish", "stplot: mean removal")
    except ImportError:
        pass


def _child(args: list[str]) -> None:
    """One instrumented run in this process; prints the split as JSON."""
    import threading

    _instrument()
    threads: dict[str, float] = defaultdict(float)
    run0 = threading.Thread.run

    def run(self):
        try:
            run0(self)
        finally:
            threads[self.name] += time.thread_time()

    threading.Thread.run = run
    from wallcli.cli.app import main

    startup = c0 = time.process_time()  # since the process began: the interpreter and every import
    with contextlib.redirect_stdout(io.StringIO()):
        try:
            main(args)
        except SystemExit as exc:
            if exc.code:
                raise
    print(json.dumps({"cpu": time.process_time(), "imports": startup, "main_thread": time.thread_time(),
                      "stages": dict(SPENT), "python_threads": dict(threads)}))


def _cpu_of(cmd: list[str]) -> tuple[float, float, str]:
    """(CPU s of the child and its threads, wall s, stdout)."""
    before = resource.getrusage(resource.RUSAGE_CHILDREN)
    t0 = time.perf_counter()
    out = subprocess.run(cmd, check=True, capture_output=True, text=True)
    wall = time.perf_counter() - t0
    after = resource.getrusage(resource.RUSAGE_CHILDREN)
    return (after.ru_utime - before.ru_utime) + (after.ru_stime - before.ru_stime), wall, out.stdout


def _args(command: str, clip: str, out: Path) -> list[str]:
    return [command, clip] + (["-o", str(out / "p.npz"), "--force"] if command == "stplot" else ["--json"])


def main() -> None:
    import argparse

    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("clip")
    ap.add_argument("--commands", default="count,activity,track,stplot")
    ap.add_argument("--pairs", type=int, default=3)
    ap.add_argument("--no-stages", action="store_true")
    a = ap.parse_args()
    py = sys.executable
    with tempfile.TemporaryDirectory() as d:
        out = Path(d)
        n = json.loads(_cpu_of([py, str(HERE / "measure.py"), "decode", a.clip])[2])["frames"]  # warm the cache
        print(f"{a.clip}: {n} frames; load average {os.getloadavg()[0]:.1f} at start", file=sys.stderr)
        for command in a.commands.split(","):
            job = [py, "-m", "wallcli", *_args(command, a.clip, out)]
            shares, walls, dec_cpu, job_cpu = [], [], [], []
            for i in range(a.pairs):
                runs = [("dec", [py, str(HERE / "measure.py"), "decode", a.clip]), ("job", job)]
                got = {k: _cpu_of(c)[:2] for k, c in (runs if i % 2 == 0 else runs[::-1])}
                dec_cpu.append(got["dec"][0])
                job_cpu.append(got["job"][0])
                shares.append((got["job"][0] - got["dec"][0]) / got["dec"][0])
                walls.append(got["dec"][1] / got["job"][1])
            line = (f"{command}: analysis {statistics.median(shares):.2f} x decode-only CPU "
                    f"(pairs {', '.join(f'{s:.2f}' for s in shares)}; decode-only {statistics.median(dec_cpu):.2f} CPU s, "
                    f"{command} {statistics.median(job_cpu):.2f} CPU s); wall {statistics.median(walls):.2f} x decode-only "
                    f"(pairs {', '.join(f'{w:.2f}' for w in walls)}); load {os.getloadavg()[0]:.1f}")
            print(line)
            if a.no_stages:
                continue
            prof = json.loads(_cpu_of([py, __file__, "--child", *_args(command, a.clip, out)])[2].strip().splitlines()[-1])
            parts = sorted(prof["stages"].items(), key=lambda kv: -kv[1])
            print("  per stage, CPU ms/frame: " + "; ".join(f"{k} {1e3 * v / n:.2f}" for k, v in parts if v > 0))
            print(f"  imports {1e3 * prof['imports']:.0f} ms; python threads: "
                  + ", ".join(f"{k} {v:.2f} s" for k, v in prof["python_threads"].items())
                  + f"; main thread {prof['main_thread']:.2f} s; instrumented process {prof['cpu']:.2f} CPU s")
            sys.stdout.flush()


if __name__ == "__main__":
    if sys.argv[1:2] == ["--child"]:
        _child(sys.argv[2:])
    else:
        main()
