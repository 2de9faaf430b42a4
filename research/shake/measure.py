"""Camera shake against stabilisation: are the answers of a still clip kept when the camera shakes?

    .venv/bin/python research/shake/measure.py [--n 24] [--rms 0.5] [--features 0.3] [--json out.json]

For each seed, one simulated scene (base domain, 0-2 people, every activity, 10 s, 320x240 at
30 fps, H.264 crf 18, no lighting nuisances) is rendered twice with the same room, people and
camera: still, and shaking by ``--rms`` pixels per axis (exact sub-pixel warps of each frame
before the sensor noise, time scale 0.05-1 s), on a wall with a door frame, a switch plate and a
skirting board of ``--features`` relative contrast (the structure a shake moves; on a plain wall
a column sum averages the texture away and a shake changes the profiles little). The shipped
count and activity models read each shaking clip without and with stabilisation
(``wallcli.signal.blocks.LineShift``). Printed: answers equal to the still clip's, and the
signal_db differences; the view check is not run (it refuses shifts of 1.5 px and more, which
larger shakes reach).
"""
from __future__ import annotations

import argparse
import json
import sys
import tempfile
from pathlib import Path

import numpy as np


def _clip(seed: int, rms: float, features: float, path: Path, crf: int = 18) -> dict:
    from wallcli.sim.scene import SceneConfig, sample_scene

    rng = np.random.default_rng(seed)
    from wallcli.sim.views import encode

    people = int(rng.integers(0, 3))
    acts = ["walking", "crouching", "waving", "jumping"]
    activities = [str(x) for x in rng.choice(acts, size=people)] if people else None
    cfg = SceneConfig(people=people, activities=activities, duration=10.0, fps=30.0, width=320, height=240,
                      domain="base", codec="libx264", crf=18, nuisance_p=0.0,
                      camera_overrides={"shake": rms, "shake_exact": True, "features": features,
                                        "drift": 0.0, "flicker": 0.0, "ae_steps": 0})
    scene = sample_scene(seed, cfg)
    encode(scene.frames(), path, fps=30.0, crf=crf)
    return {"people": people, "activities": activities}


def _answers(model, path: Path, stabilize: bool) -> dict:
    from wallcli.infer.classify import WindowClassifier
    from wallcli.infer.stream import RowStream
    from wallcli.io.video import open_video

    c = WindowClassifier(model, 64)
    with open_video(str(path)) as reader:
        rows = RowStream(reader, bins=model.bins, fps=model.fps, vertical="vertical" in model.input_names,
                         stabilize=stabilize)
        for t, row in rows:
            c.push(t, row, rows.ref)
    r = c.result(str(path))
    shifts = rows.shifts.summary() if rows.shifts is not None else None
    return {"label": r["label"], "signal_db": r.get("signal_db"), "shake": shifts}


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--n", type=int, default=24)
    ap.add_argument("--rms", type=float, default=0.5)
    ap.add_argument("--features", type=float, default=0.3)
    ap.add_argument("--seed", type=int, default=7000)
    ap.add_argument("--crf", type=int, default=18, help="x264 CRF of both clips (0: lossless, so the codec's "
                    "repeating of a still wall's blocks does not hide the still clip's noise)")
    ap.add_argument("--json", type=Path)
    a = ap.parse_args()
    from wallcli.infer.model import load_model

    models = {task: load_model(task) for task in ("count", "activity")}
    rows = []
    with tempfile.TemporaryDirectory() as tmp:
        for i in range(a.n):
            seed = a.seed + i
            still, shaky = Path(tmp) / f"{seed}_still.mp4", Path(tmp) / f"{seed}_shake.mp4"
            truth = _clip(seed, 0.0, a.features, still, a.crf)
            _clip(seed, a.rms, a.features, shaky, a.crf)
            rec = {"seed": seed, **truth}
            for task, model in models.items():
                rec[task] = {"still": _answers(model, still, False),
                             "shake_off": _answers(model, shaky, False),
                             "shake_on": _answers(model, shaky, True)}
            rows.append(rec)
            print(json.dumps(rec), file=sys.stderr, flush=True)
    if a.json:
        a.json.write_text(json.dumps(rows, indent=1))
    print(f"{a.n} scenes, shake {a.rms} px rms per axis, features {a.features}, crf {a.crf}:")
    for task in models:
        for side in ("shake_off", "shake_on"):
            kept = sum(r[task][side]["label"] == r[task]["still"]["label"] for r in rows)
            d = [r[task][side]["signal_db"] - r[task]["still"]["signal_db"] for r in rows
                 if r[task][side]["signal_db"] is not None and r[task]["still"]["signal_db"] is not None]
            print(f"  {task:8s} {side:9s}: answers kept {kept}/{a.n}; signal_db change median "
                  f"{np.median(d):+.2f} dB, largest {max(d, key=abs):+.2f} dB")


if __name__ == "__main__":
    main()
