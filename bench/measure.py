"""Run one job in this fresh process and print {"seconds", "frames", "peak_rss_mb"} as JSON.

    python bench/measure.py decode CLIP          # PyAV decode-only (threaded), the baseline
    python bench/measure.py wallcli ARGS...      # any wallcli command, in-process

A fresh process per job keeps peak RSS (ru_maxrss) honest: it is the job's own high-water mark.
"""
from __future__ import annotations

import contextlib
import io
import json
import resource
import sys
import time


def _decode(clip: str) -> int:
    import av

    n = 0
    with av.open(clip) as c:
        s = c.streams.video[0]
        s.thread_type = "AUTO"
        for _ in c.decode(s):
            n += 1
    return n


def _wallcli(args: list[str]) -> None:
    from wallcli.cli.app import main

    with contextlib.redirect_stdout(io.StringIO()):
        try:
            main(args)
        except SystemExit as exc:
            if exc.code:
                raise RuntimeError(f"wallcli {' '.join(args)} exited with {exc.code}") from None


def _peak_rss_mb() -> float:
    # VmHWM belongs to this process image; ru_maxrss would inherit the parent's peak across fork.
    with open("/proc/self/status") as fh:
        for line in fh:
            if line.startswith("VmHWM:"):
                return int(line.split()[1]) / 1024
    return resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024


def main() -> None:
    kind, rest = sys.argv[1], sys.argv[2:]
    t0 = time.perf_counter()
    frames = _decode(rest[0]) if kind == "decode" else (_wallcli(rest) or None)
    seconds = time.perf_counter() - t0
    rss = _peak_rss_mb()
    ru = resource.getrusage(resource.RUSAGE_SELF)
    # CPU time (all threads) is what a loaded machine distorts least; wall time is what users see.
    print(json.dumps({"seconds": seconds, "cpu_seconds": ru.ru_utime + ru.ru_stime, "frames": frames,
                      "peak_rss_mb": rss}))


if __name__ == "__main__":
    main()
