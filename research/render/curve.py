"""The learning curve (issue 59 point 2): a count or activity net fine-tuned on the first N rendered
training rooms, for several N, each read on rooms it never saw, paired against the shipped model.

    python research/render/curve.py --task count --sizes 30,60,123 --train runs/render/train \\
        --eval ../shared/transfer --eval runs/render/val --out runs/exp/curve

For each N: the first N rows of ``--train``'s labels.csv (seed order, so a larger N holds every
smaller one) are hard-linked into ``OUT/nN`` (evaluate and train refuse clips that leave their
folder, symbolic links included); ``wallcli train TASK --clips OUT/nN --init models/TASK.onnx`` with
the settings below; the shipped card's rules copied in (``two_stage_card.py``); ``wallcli evaluate``
on each ``--eval`` folder; a line per folder with the detectable clips right, the exact interval
and the McNemar test against the shipped model (``paired.py``), whose evaluations are made once.
Re-running skips what is already there.
"""
from __future__ import annotations

import argparse
import csv
import os
import subprocess
import sys
from pathlib import Path

HERE = Path(__file__).resolve().parent
TRAIN_ARGS = ["--lr", "2e-4", "--epochs", "8", "--anneal", "4", "--threads", "2", "--seed", "0"]


def _subset(train: Path, n: int, out: Path) -> Path:
    rows = list(csv.DictReader(open(train / "labels.csv")))
    rows = [r for r in rows if (train / r["file"]).exists()][:n]
    if len(rows) < n:
        sys.exit(f"{train} has {len(rows)} rooms, fewer than {n}")
    out.mkdir(parents=True, exist_ok=True)
    for r in rows:
        for suffix in ("", ".json"):
            src = train / (r["file"] if not suffix else Path(r["file"]).with_suffix(".json").name)
            dst = out / src.name
            if src.exists() and not dst.exists():
                os.link(src, dst)
    with open(out / "labels.csv", "w", newline="") as fh:
        w = csv.DictWriter(fh, fieldnames=list(rows[0]))
        w.writeheader()
        w.writerows(rows)
    return out


def _run(cmd: list[str], stdout: Path | None = None) -> None:
    print("$ " + " ".join(cmd), file=sys.stderr)
    with open(stdout, "w") if stdout else open(os.devnull, "w") as fh:
        subprocess.run(cmd, check=True, stdout=fh if stdout else None)


def _evaluate(folder: Path, task: str, model: Path | None, out: Path) -> Path:
    if not out.exists():
        cmd = [sys.executable, "-m", "wallcli", "evaluate", str(folder), "--task", task, "--json"]
        _run(cmd + (["--model", str(model)] if model else []), stdout=out)
    return out


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--task", choices=("count", "activity"), default="count")
    ap.add_argument("--sizes", default="30,60,123")
    ap.add_argument("--train", type=Path, required=True)
    ap.add_argument("--eval", type=Path, action="append", required=True)
    ap.add_argument("--out", type=Path, required=True)
    a = ap.parse_args()
    shipped = HERE.parents[1] / "models" / f"{a.task}.onnx"
    a.out.mkdir(parents=True, exist_ok=True)
    base = {f: _evaluate(f, a.task, None, a.out / f"base_{a.task}_{f.name}.json") for f in a.eval}
    for n in map(int, a.sizes.split(",")):
        folder = _subset(a.train, n, a.out / f"n{n}")
        model = a.out / f"{a.task}_n{n}.onnx"
        if not model.exists():
            extra = ["--superpose", "0.25"] if a.task == "count" else []  # (count only: labels add)
            _run([sys.executable, "-m", "wallcli", "train", a.task, "--clips", str(folder), "--init", str(shipped),
                  *TRAIN_ARGS, *extra, "--model-version", f"curve-n{n}", "-o", str(model)])
            _run([sys.executable, str(HERE / "two_stage_card.py"), str(model)])
        for f in a.eval:
            got = _evaluate(f, a.task, model, a.out / f"{a.task}_n{n}_{f.name}.json")
            print(f"== {a.task}, {n} training rooms, read on {f}", flush=True)
            subprocess.run([sys.executable, str(HERE / "paired.py"), str(base[f]), str(got)], check=True)


if __name__ == "__main__":
    main()
