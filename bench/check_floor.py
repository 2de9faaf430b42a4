"""What a command costs with its camera and view checks switched off: the floor the checks sit on
(issue 60's analysis; a measurement harness, never a way to run wallcli).

    python bench/check_floor.py ROUNDS CLIP [count,stplot,track]

Runs, in alternating rounds (bench/cpu_rounds.py), decode-only (bench/measure.py) and each command
twice: as shipped, and with the repeats, overlay, interlace, TNR and view checks replaced by
pass-throughs in the process (``--off``). Prints the median CPU seconds (user + sys of the child and
its threads) and each one's share over decode-only: (command − decode-only) / decode-only. The gap
between the two lines of a command is what its checks cost; the "off" line is what is left for the
reader, the projection, the nets and start-up. ``OPENBLAS_NUM_THREADS=1`` is set before anything
imports numpy, as the CLI's entry sets it.
"""
from __future__ import annotations

import os
import subprocess
import sys
from pathlib import Path

HERE = Path(__file__).resolve().parent


def _off(args: list[str]) -> None:
    """Run ``wallcli ARGS`` in this process with the checks replaced by pass-throughs (the same
    switches as research/speed/ablate.py's)."""
    os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")
    sys.path.insert(0, str(HERE.parent / "research" / "speed"))
    from ablate import _switch_off

    _switch_off({"overlay", "repeats", "interlace", "tnr", "view"})
    from wallcli.cli.entry import main

    sys.argv = ["wallcli", *args]
    main()


def _args(command: str, clip: str) -> str:
    return f"{command} {clip} " + ("-o /tmp/wallcli_floor.npz --force" if command == "stplot" else "--json")


def main() -> None:
    if sys.argv[1:2] == ["--off"]:
        _off(sys.argv[2:])
        return
    if len(sys.argv) < 3 or not sys.argv[1].isdigit():
        sys.exit(__doc__)
    rounds, clip = sys.argv[1], str(Path(sys.argv[2]).resolve())
    commands = (sys.argv[3] if len(sys.argv) > 3 else "count,stplot,track").split(",")
    py = sys.executable
    cmds = [f"{py} {HERE / 'measure.py'} decode {clip}"]
    for c in commands:
        cmds += [f"{py} -m wallcli {_args(c, clip)}",
                 f"OPENBLAS_NUM_THREADS=1 {py} {Path(__file__).resolve()} --off {_args(c, clip)}"]
    out = subprocess.run([py, str(HERE / "cpu_rounds.py"), rounds, *cmds], check=True, capture_output=True,
                         text=True, cwd="/tmp").stdout
    medians = [float(line.split()[1]) for line in out.splitlines() if line.startswith("cpu ")]
    print(out, end="")
    dec = medians[0]
    for i, c in enumerate(commands):
        on, off = medians[1 + 2 * i], medians[2 + 2 * i]
        print(f"{c}: as shipped {(on - dec) / dec:.2f} x decode-only CPU; checks off {(off - dec) / dec:.2f}; "
              f"the checks {on - off:.2f} CPU s")


if __name__ == "__main__":
    main()
