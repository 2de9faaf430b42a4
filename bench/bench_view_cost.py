"""What the view check costs: `wallcli count` on the 1080p bench clip with and without it, in one run.

    .venv/bin/python bench/bench_view_cost.py [--frames 600] [--pairs 5] [--command count]

Issue 27 asks that count's throughput on the 1080p bench clip stays >= 0.9 x what it was before
the view check. Both sides run the same code in fresh processes, alternating, whole commands
(start-up and model load included): ``with`` is the command as shipped; ``without`` replaces
``ViewCheck.update`` by a no-op before the command starts, which is the command as it was before
the check (the check is a tap on the one decode; nothing else changed around it). The figure is
the median over the pairs of (with frames/s) / (without frames/s); pairs keep a loaded machine's
slow moments from landing on one side only. The CPU-time ratio (whole command, all threads) is
printed too: it moves least when other work loads the machine.
"""
from __future__ import annotations

import argparse
import os
import resource
import statistics
import subprocess
import sys
import time
from pathlib import Path

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE))

from clips import clip_1080p  # noqa: E402

_RUN = """
import sys
if sys.argv[1] == "without":
    from wallcli.view import check as view
    view.ViewCheck.update = lambda self, t, planes: None
sys.argv = ["wallcli", *sys.argv[2:]]
from wallcli.cli.entry import main
main()
"""


def _once(side: str, args: list[str], tree: str | None = None) -> tuple[float, float]:
    """(wall seconds, CPU seconds) of one whole command; ``tree``: run that source tree instead."""
    env = dict(os.environ, PYTHONPATH=tree) if tree else None
    c0 = resource.getrusage(resource.RUSAGE_CHILDREN)
    t0 = time.perf_counter()
    out = subprocess.run([sys.executable, "-c", _RUN, side, *args], capture_output=True, text=True, env=env)
    seconds = time.perf_counter() - t0
    c1 = resource.getrusage(resource.RUSAGE_CHILDREN)
    if out.returncode:
        raise SystemExit(f"{side}: wallcli {' '.join(args)} failed:\n{out.stderr}")
    return seconds, (c1.ru_utime + c1.ru_stime) - (c0.ru_utime + c0.ru_stime)


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--frames", type=int, default=600)
    ap.add_argument("--pairs", type=int, default=5)
    ap.add_argument("--command", default="count", choices=["count", "activity", "snr"])
    ap.add_argument("--baseline", metavar="COMMIT",
                    help="the 'without' side is this commit of the repository as it was (exported to a temporary "
                         "folder), run whole, instead of this tree with the check removed: e.g. the commit before "
                         "issue 27 (dc8e913^1), for everything the issue added (view check and corrections)")
    a = ap.parse_args()
    clip = str(clip_1080p(a.frames))
    args = [a.command, clip, "--json"]
    tree = None
    if a.baseline:
        import tarfile
        import tempfile

        tree = tempfile.mkdtemp(prefix="wallcli-baseline-")
        archive = subprocess.run(["git", "-C", str(HERE.parent), "archive", a.baseline], capture_output=True, check=True)
        import io
        with tarfile.open(fileobj=io.BytesIO(archive.stdout)) as t:
            t.extractall(tree, filter="data")
    side = "with" if tree else "without"
    _once("with", args)  # warm the page cache and Python's bytecode cache
    if tree:
        _once(side, args, tree)
    ratios, cpu = [], []
    for i in range(a.pairs):
        without, without_cpu = _once(side, args, tree)
        with_, with_cpu = _once("with", args)
        ratios.append(without / with_)
        cpu.append(without_cpu / with_cpu)
        print(f"  pair {i + 1}: without {without:.2f} s ({without_cpu:.2f} CPU s), with {with_:.2f} s "
              f"({with_cpu:.2f} CPU s): {ratios[-1]:.2f} x", file=sys.stderr)
    load = os.getloadavg()[0]
    what = f"the throughput of {a.baseline}" if a.baseline else "the throughput without it"
    print(f"{a.command} on 1080p30, {a.frames} frames: with the view check {statistics.median(ratios):.2f} x "
          f"{what}, {statistics.median(cpu):.2f} x in CPU time (medians of {a.pairs} pairs; "
          f"wall: {', '.join(f'{r:.2f}' for r in ratios)}); load average {load:.1f} on {os.cpu_count()} cores")


if __name__ == "__main__":
    main()
