"""False alarms and catches of the view check (measured from 2026-11-25) on generated clips.

Wall clips: the simulator in each domain (base, shifted, wide, steady; lighting nuisances and
sub-pixel shake as each domain draws them), H.264 as `wallcli simulate` writes. Not-a-wall clips:
the same wall clips with a sprite crossing the view, a pan, a shake, or a cut to a second
wall clip (wallcli/sim/views.py). Each clip is encoded, decoded with wallcli's reader and fed to
the view check, exactly as the commands do.

    python research/view/measure.py --n 25 --seconds 4        # 25 clips of each kind
"""
from __future__ import annotations

import argparse
import json
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

DOMAINS = ("base", "shifted", "wide", "steady")
# what the check promises to catch (README, Real footage), and fainter sprites reported apart
FAULTS = {"sprite": {"contrast": (0.4, 0.6)}, "pan": {"amplitude": 3.0}, "shake": {"rms": 1.0}, "cut": {},
          "faint": {"contrast": (0.15, 0.4)}}


def scene_frames(seed: int, domain: str, seconds: float, size=(320, 240)):
    from wallcli.sim.scene import SceneConfig, sample_scene

    rng = np.random.default_rng(seed)
    cfg = SceneConfig(people=int(rng.integers(0, 3)), duration=seconds, fps=30.0, width=size[0], height=size[1],
                      domain=domain, codec="libx264", crf=18, nuisance_p=0.5)
    return sample_scene(seed, cfg).frames()


def check(frames, n, path: Path, fps=30.0) -> dict:
    from wallcli.io.video import open_video
    from wallcli.sim.views import encode
    from wallcli.view.check import ViewCheck

    encode(frames, path, fps=fps)
    vc = ViewCheck()
    with open_video(path) as reader:
        for frame in reader.frames():
            vc(frame)
    return vc.summary()


def main() -> None:
    from wallcli.sim import views

    ap = argparse.ArgumentParser()
    ap.add_argument("--n", type=int, default=25, help="clips per domain and per fault")
    ap.add_argument("--seconds", type=float, default=4.0)
    ap.add_argument("--seed", type=int, default=1000)
    ap.add_argument("--json", type=Path, help="write every clip's verdict here")
    a = ap.parse_args()
    n_frames = int(round(a.seconds * 30))
    rows = []
    with tempfile.TemporaryDirectory() as tmp:
        clip = Path(tmp) / "c.mp4"
        t0 = time.time()
        for k in range(a.n):
            for j, dom in enumerate(DOMAINS):
                seed = a.seed + 10 * k + j
                v = check(scene_frames(seed, dom, a.seconds), n_frames, clip)
                rows.append({"kind": "wall", "domain": dom, "seed": seed, **v})
                print("wall", dom, seed, v["issues"], file=sys.stderr)
            for j, (fault, kw) in enumerate(FAULTS.items()):
                seed = a.seed + 10 * k + 5 + j
                rng = np.random.default_rng(seed + 7)
                dom = DOMAINS[(k + j) % len(DOMAINS)]
                src = scene_frames(seed, dom, a.seconds)
                if fault == "cut":
                    frames = views.cut(src, scene_frames(seed + 99991, dom, a.seconds), rng, n=n_frames)
                else:
                    fn = views.sprite if fault == "faint" else getattr(views, fault)
                    frames = fn(src, rng, n=n_frames, fps=30.0, **kw)
                v = check(frames, n_frames, clip)
                rows.append({"kind": fault, "domain": dom, "seed": seed, **v})
                print(fault, dom, seed, v["issues"], file=sys.stderr)
            print(f"{k + 1}/{a.n} rounds, {time.time() - t0:.0f} s", file=sys.stderr, flush=True)
    print(f"{'kind':8} {'clips':>5} {'flagged':>7} {'rate':>6}  issues")
    for kind in ("wall", *FAULTS):
        sel = [r for r in rows if r["kind"] == kind]
        bad = [r for r in sel if not r["usable"]]
        issues = {}
        for r in bad:
            for i in r["issues"]:
                issues[i] = issues.get(i, 0) + 1
        print(f"{kind:8} {len(sel):5d} {len(bad):7d} {len(bad) / max(len(sel), 1):6.1%}  {issues}")
    if a.json:
        a.json.write_text(json.dumps(rows, indent=1))


if __name__ == "__main__":
    main()
