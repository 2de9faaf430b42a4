"""The console script (``wallcli``) and ``python -m wallcli``: the signal handlers first, then the
imports of typer, click and rich (a tenth of a second or more), so that a Ctrl-C or ``kill`` that
lands while they load also exits 1 with one line, not with a traceback and status 130."""
from __future__ import annotations

import sys


def main() -> None:
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
