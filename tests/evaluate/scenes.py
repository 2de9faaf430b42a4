"""The simulated scenes of the evaluate tests, and an in-process CLI call for fixtures."""
from __future__ import annotations

SMALL = ["--duration", "10.5", "--size", "64x48", "--grid", "16x16"]
# (stem, people, activity, seed): every count class, a standing person (counted 0), two people
SCENES = [("empty", 0, "none", 1), ("walk", 1, "walking", 3), ("jump", 1, "jumping", 3),
          ("crouch", 1, "crouching", 5), ("stand", 1, "none", 2), ("two", 2, "walking,crouching", 3)]


def cli(*args) -> tuple[int, str]:
    """In-process `wallcli ARGS` for module fixtures (run_cli is per test): (exit code, stdout)."""
    import contextlib
    import io

    from wallcli.cli.app import main

    buf = io.StringIO()
    try:
        with contextlib.redirect_stdout(buf):
            main([str(a) for a in args])
    except SystemExit as exc:
        return (exc.code if isinstance(exc.code, int) else 1), buf.getvalue()
    return 0, buf.getvalue()
