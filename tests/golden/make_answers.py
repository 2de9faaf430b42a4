"""The answers of count, activity, track and stplot on the bundled examples, as a golden file (issue 60).

    .venv/bin/python tests/golden/make_answers.py      # writes tests/golden/answers.json
    .venv/bin/python tests/golden/make_answers.py --clips ../shared/transfer --out tests/golden/recordings.json.gz

Generated from the code before issue 60's speed work, so that tests/test_answers_golden.py can
hold the faster code to the same answers: every label, probability, signal_db, view verdict and
track, and the stplot plots' figures. Regenerate only after a change that is meant to change answers
(a retrained model, a new rule), and say so in the commit.
"""
from __future__ import annotations

import contextlib
import gzip
import io
import json
import sys
import tempfile
from pathlib import Path

import numpy as np

HERE = Path(__file__).resolve().parent
EXAMPLES = HERE.parents[1] / "examples"
TASKS = ("count", "activity", "track", "stplot")


def _view(v: dict | None) -> dict | None:
    return None if v is None else {"usable": v["usable"], "issues": v["issues"], "reason": v["reason"]}


def summarise(task: str, r: dict, npz: Path | None = None) -> dict:
    """What must not change in one command's --json (and, for stplot, its .npz)."""
    if task in ("count", "activity"):
        return {"label": r["label"], "probabilities": r["probabilities"], "confident": r["confident"],
                "signal_db": r["signal_db"], "view": _view(r["view"]),
                "windows": [{"label": w["label"], "probabilities": w["probabilities"], "signal_db": w["signal_db"],
                             "view": _view(w.get("view"))} for w in r["windows"]]}
    if task == "track":
        return {"view": _view(r["view"]), "simultaneous": r["simultaneous"], "reason": r["reason"],
                "tracks": [{"start": t["start"], "end": t["end"], "moving": t["moving"], "strength": t["strength"],
                            "samples": [[s["t"], s["x"], s["sigma"], s["sigma_shade"]] for s in t["samples"]]}
                           for t in r["tracks"]]}
    with np.load(npz) as z:
        # the plots' time profile per bin and colour: small enough to keep, and it moves with any change
        # in the projection, the corrections or the mean removal
        rms = {k: np.sqrt(np.mean(np.square(z[k].astype(np.float64)), axis=1)).round(7).tolist()
               for k in ("horizontal", "vertical")}
        frames = int(z["horizontal"].shape[1])
    return {"view": _view(r["view"]), "signal_rms": r["signal_rms"], "column_snr_db": r.get("column_snr_db"),
            "frames": frames, "bin_rms": rms}


def run(main, task: str, clip: Path, out_dir: Path) -> tuple[int, dict, Path | None]:
    """One command in this process: (exit code, its JSON, the .npz for stplot)."""
    npz = out_dir / f"{clip.stem}.npz" if task == "stplot" else None
    args = [task, str(clip), "--json"] + (["-o", str(npz), "--force"] if npz else [])
    buf = io.StringIO()
    code = 0
    with contextlib.redirect_stdout(buf), contextlib.redirect_stderr(io.StringIO()):
        try:
            main(args)
        except SystemExit as exc:
            code = exc.code if isinstance(exc.code, int) else (0 if exc.code is None else 1)
    return code, json.loads(buf.getvalue()) if code == 0 else {}, npz


def main() -> None:
    import argparse

    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--clips", type=Path, default=EXAMPLES, help="folder of .mp4 clips (default: examples/)")
    ap.add_argument("--out", type=Path, default=HERE / "answers.json")
    a = ap.parse_args()
    from wallcli.cli.app import main as cli

    golden: dict = {}
    with tempfile.TemporaryDirectory() as d:
        for clip in sorted(a.clips.glob("*.mp4")):
            for task in TASKS:
                code, r, npz = run(cli, task, clip, Path(d))
                if code:
                    sys.exit(f"{task} {clip.name} exited {code}")
                golden[f"{task}/{clip.stem}"] = summarise(task, r, npz)
            print(clip.stem, file=sys.stderr)
    text = json.dumps(golden, indent=0) + "\n"
    if a.out.suffix == ".gz":  # the recordings' answers: 1.8 MB as text
        a.out.write_bytes(gzip.compress(text.encode(), 9, mtime=0))
    else:
        a.out.write_text(text)


if __name__ == "__main__":
    main()
