"""The console script (``wallcli``) and ``python -m wallcli``: the signal handlers first, then the
imports of typer, click and rich (a tenth of a second or more), so that a Ctrl-C or ``kill`` that
lands while they load also exits 1 with one line, not with a traceback and status 130.

OpenBLAS is held to one thread before numpy loads: every matrix numpy hands it here is small (a
window's 64x64 Gram matrix, the corrections' least squares), too small for a helper thread to pay,
and its helpers spin while they wait. With them, activity spent 1.2 CPU s of a 900-frame 1080p
clip, and count 0.6, on spinning (bench/RESULTS.md, issue 60); the answers are the same. A user's
own OPENBLAS_NUM_THREADS (or OMP_NUM_THREADS) is kept."""
from __future__ import annotations

import os
import sys


def _one_blas_thread() -> None:
    if "OPENBLAS_NUM_THREADS" not in os.environ and "OMP_NUM_THREADS" not in os.environ:
        os.environ["OPENBLAS_NUM_THREADS"] = "1"


def main() -> None:
    _one_blas_thread()
    from wallcli.cli import _signals

    _signals.install()
    try:
        from wallcli.cli.app import main as run
    except KeyboardInterrupt:
        _signals.settle()
        if sys.stderr is not None:
            sys.stderr.write("Error: interrupted\n")
        sys.exit(1)
    run()
