"""CPU seconds of whole shell commands, in rounds, paired by position (issue 60's "A" measure).

    python bench/cpu_rounds.py N 'CMD1' 'CMD2' ...

Each round runs every command once (the order reversed every other round, so drift in the machine's
load falls on both sides), measuring user + sys of the child and all its threads
(``getrusage(RUSAGE_CHILDREN)`` around it) and its wall time; prints the median and every value per
command. To compare two builds, run each from a ``git archive`` of its commit with ``PYTHONPATH`` set
and the working directory outside the checkout, so that ``python -m wallcli`` loads that tree:

    git archive 0ce717f wallcli | tar -x -C /tmp/before
    cd /tmp && python /path/bench/cpu_rounds.py 5 "python /path/bench/measure.py decode CLIP" \\
        "PYTHONPATH=/tmp/before python -m wallcli count CLIP --json" "python -m wallcli count CLIP --json"
"""
from __future__ import annotations

import resource
import statistics
import subprocess
import sys
import time


def main() -> None:
    if len(sys.argv) < 3 or not sys.argv[1].isdigit():
        sys.exit(__doc__)
    n, cmds = int(sys.argv[1]), sys.argv[2:]
    res: dict[str, list[tuple[float, float]]] = {c: [] for c in cmds}
    for i in range(n):
        for c in cmds if i % 2 == 0 else cmds[::-1]:
            b, t = resource.getrusage(resource.RUSAGE_CHILDREN), time.perf_counter()
            subprocess.run(c, shell=True, check=True, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
            a = resource.getrusage(resource.RUSAGE_CHILDREN)
            res[c].append((a.ru_utime - b.ru_utime + a.ru_stime - b.ru_stime, time.perf_counter() - t))
    for c, v in res.items():
        print(f"cpu {statistics.median(x for x, _ in v):.2f} ({', '.join(f'{x:.2f}' for x, _ in v)}) "
              f"wall {statistics.median(w for _, w in v):.2f}  {c}")


if __name__ == "__main__":
    main()
