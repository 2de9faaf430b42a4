"""Small `wallcli scan` results (docs/contract.md: one JSON object per video and line), written by hand:
answers decided and undetermined, results from before the confident flag, a failed video, a
hostile file name and a last line cut short by a killed scan. The headline column SNR sits in the
first line's snr object, in the second's count and activity objects only, and not in the third
(results from before it existed)."""
from __future__ import annotations

import json
from pathlib import Path

from report_clips import HOSTILE

ACTIVITY = ["none", "walking", "crouching", "waving", "jumping"]


def _snr(signal, noise):
    import math

    db = [10 * math.log10(s / n) if s > 0 else -99.0 for s, n in zip(signal, noise)]
    return {"input": "x", "roi": [0, 0, 64, 48], "frames": 300, "channels": ["r", "g", "b"], "signal_power": signal,
            "noise_power": noise, "snr_db": db, "scales": []}


def _answer(task, label, probs, **extra):
    classes = [0, 1, 2] if task == "count" else ACTIVITY
    return {"input": "x", "task": task, "model": {"name": f"wallcli-{task}", "version": "0.4.1", "sha256": "0" * 64},
            "fps": 30.0, "classes": classes, "label": label, "probabilities": probs, **extra}


RECORDS = [
    {"input": "cam1/0001.mp4", "size": 1_234_567, "sha256": "a" * 64, "duration": 12.0, "frames": 360,
     "count": _answer("count", 1, [0.02, 0.93, 0.05], confident=True, reason=None, signal_db=12.46),
     "activity": _answer("activity", "walking", [0.05, 0.9, 0.03, 0.01, 0.01], confident=True, reason=None,
                         signal_db=-0.04),
     "snr": dict(_snr([0.5, 0.4, 0.6], [0.2, 0.2, 0.3]), column_snr_db=19.12), "error": None},
    {"input": f"cam1/{HOSTILE}.mp4", "size": 2_000_000, "sha256": "b" * 64, "duration": 30.5, "frames": 915,
     "count": _answer("count", 2, [0.1, 0.3, 0.6], confident=False, reason="signal 3 dB under the model's validated range",
                      signal_db=-30.0, column_snr_db=-4.75),
     "activity": _answer("activity", "none", [0.9, 0.04, 0.03, 0.02, 0.01], confident=True, reason=None,
                         signal_db=-28.5, column_snr_db=-4.75),
     "snr": _snr([0.01, 0.01, 0.01], [1.0, 1.0, 1.0]), "error": None},
    {"input": "cam2/old.mp4", "size": 500_000, "sha256": "c" * 64, "duration": 9.0, "frames": 270,
     "count": _answer("count", 0, [0.8, 0.15, 0.05]),  # written before the confident flag existed
     "activity": _answer("activity", "none", [0.7, 0.1, 0.1, 0.05, 0.05]),
     "snr": _snr([-0.1, -0.1, -0.1], [0.3, 0.3, 0.3]), "error": None},
    {"input": "cam2/broken.mp4", "size": 10, "sha256": "d" * 64, "duration": None, "frames": None,
     "error": "cam2/broken.mp4 is not a readable video (FFmpeg: Invalid data found when processing input)"},
]
CUT = '{"input": "cam3/0009.mp4", "size": 12'


def write_results(path: Path, records=RECORDS, tail: str | None = CUT) -> Path:
    lines = [json.dumps(r) for r in records] + ([tail] if tail else [])
    path.write_text("\n".join(lines) + "\n", encoding="utf-8")
    return path
