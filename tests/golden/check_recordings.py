"""Hold the code to the recordings' golden answers (issue 60 point 4): count, activity, track and stplot
on every recording of ../shared/transfer against tests/golden/recordings.json.gz, made by make_answers.py
from the code before the speed work (2e76421).

    .venv/bin/python tests/golden/check_recordings.py [--clips ../shared/transfer] [--every N]

Prints each clip whose answers moved and what moved; exits 1 if any did. tests/test_answers_golden.py
runs a sixteenth of them in the suite; this runs them all (about 5 min on 2 cores).
"""
from __future__ import annotations

import argparse
import gzip
import json
import sys
import tempfile
from pathlib import Path

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE))
sys.path.insert(0, str(HERE.parent))

import make_answers  # noqa: E402

RECORDINGS = HERE.parents[1].parent / "shared" / "transfer"


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--clips", type=Path, default=RECORDINGS)
    ap.add_argument("--golden", type=Path, default=HERE / "recordings.json.gz")
    ap.add_argument("--every", type=int, default=1, help="check every N-th recording only")
    a = ap.parse_args()
    from test_answers_golden import _same
    from wallcli.cli.app import main as cli

    golden = json.loads(gzip.decompress(a.golden.read_bytes()))
    clips = sorted(a.clips.glob("*.mp4"))[:: a.every]
    if not clips:
        sys.exit(f"no .mp4 in {a.clips}")
    moved = 0
    with tempfile.TemporaryDirectory() as d:
        for clip in clips:
            for task in make_answers.TASKS:
                key = f"{task}/{clip.stem}"
                code, r, npz = make_answers.run(cli, task, clip, Path(d))
                try:
                    assert code == 0, f"exit {code}"
                    _same(task, make_answers.summarise(task, r, npz), golden[key], key)
                except AssertionError as exc:
                    moved += 1
                    print(f"MOVED {key}: {exc}", flush=True)
    print(f"{len(clips)} recordings x {len(make_answers.TASKS)} commands: {moved} moved")
    sys.exit(1 if moved else 0)


if __name__ == "__main__":
    main()
