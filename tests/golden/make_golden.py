"""Regenerate the golden outputs of the shipped models (run after retraining them).

    .venv/bin/python tests/golden/make_golden.py

For each task: a seeded simulator clip (the same one tests/test_models.py renders), the model's
window probabilities through `wallcli count|activity --json`, and the model's sha256, so a model
that changes without new goldens fails loudly.
"""
from __future__ import annotations

import json
import subprocess
import sys
import tempfile
from pathlib import Path

HERE = Path(__file__).resolve().parent
GOLDEN_CLIP = ["--people", "1", "--activity", "walking", "--seed", "7", "--size", "128x96", "--duration", "11",
               "--fps", "25", "--iso-gain", "0.1", "--read-noise", "1.5", "--sensor-pixels", "200000",
               "--distance", "1,2", "--crf", "12"]


def main() -> None:
    with tempfile.TemporaryDirectory() as d:
        clip = Path(d) / "golden.mp4"
        subprocess.run([sys.executable, "-m", "wallcli", "simulate", "-o", str(clip), *GOLDEN_CLIP], check=True)
        for task in ("count", "activity"):
            out = subprocess.run([sys.executable, "-m", "wallcli", task, str(clip), "--json"], check=True,
                                 capture_output=True, text=True).stdout
            r = json.loads(out)
            golden = {"clip": GOLDEN_CLIP, "sha256": r["model"]["sha256"], "label": r["label"],
                      "probabilities": r["probabilities"],
                      "windows": [{k: w[k] for k in ("start", "end", "label", "probabilities")} for w in r["windows"]]}
            (HERE / f"{task}.json").write_text(json.dumps(golden, indent=1) + "\n")
            print(f"{task}: label {r['label']}, {len(r['windows'])} windows, sha256 {r['model']['sha256'][:12]}")


if __name__ == "__main__":
    main()
