"""The analytic world with and without room-surface shadows against Mitsuba path tracing, same scenes.

For each scene: the noise-free relative irradiance change dE/E0 of every frame on the same wall
points, from `--world room` (shadows on / off) and `--world pt`; then per scene
- corr_h, corr_v: correlation of the horizontal (column-mean) and vertical (row-mean) plots with pt's,
- wall share: the whole-wall mean's part of the signal power,
- power ratio: signal power over pt's.
No camera, no noise, no codec: the light transport alone.

    python research/shadows/compare.py --scenes 10 --frames 120 --grid 16x24 --spp 256 -o research/shadows/table.md
"""
from __future__ import annotations

import argparse
import json
import sys
import time

import numpy as np

from wallcli.sim.scene import SceneConfig, sample_scene

# one scene per row: people, activities; placed as the 'wide' placement puts them
PLAN = [(1, ["walking"]), (1, ["crouching"]), (1, ["waving"]), (1, ["jumping"]), (2, ["walking", "walking"]),
        (2, ["walking", "waving"]), (2, ["jumping", "crouching"]), (1, ["walking"]), (1, ["jumping"]), (1, ["waving"]),
        (2, ["waving", "jumping"]), (1, ["crouching"])]


def room_changes(scene, shadows: bool) -> np.ndarray:
    scene.config.shadows = shadows
    E0 = scene.static_irradiance()
    tracks = scene.sphere_tracks()
    gy, gx = scene.points.shape[:2]
    probes = scene.points[np.ix_([0, gy // 2, gy - 1], [0, gx // 2, gx - 1])].reshape(-1, 3)
    x0, x1, z0, z1 = scene.region
    view = np.array([(x0 + x1) / 2, 0.0, (z0 + z1) / 2])
    bbox = (x0 - 0.2, x1 + 0.2, z0 - 0.2, z1 + 0.2)
    out = []
    for i in range(len(scene.times)):
        C = np.concatenate([c[i] for c, _, _ in tracks])
        R = np.concatenate([r for _, r, _ in tracks])
        A = np.concatenate([a for _, _, a in tracks])
        out.append(scene._delta(C, R, A, probes, view, bbox) / np.maximum(E0, 1e-12))
    return np.array(out)


def pt_changes(scene, spp: int) -> np.ndarray:
    from wallcli.sim.pathtrace import PathTracer
    tr = PathTracer(scene.room, scene.points, scene.people, scene.poses, spp=spp, seed=scene.seed % 2**31)
    E0 = tr.irradiance(None)
    return np.array([(tr.irradiance(i) - E0) / np.maximum(E0, 1e-12) for i in range(len(scene.times))])


def stats(x: np.ndarray, ref: np.ndarray) -> dict:
    """x, ref: (T, gy, gx, 3) relative changes; green-weighted luminance as the plots' channels mean."""
    def plots(a):
        a = a.mean(axis=-1)
        a = a - a.mean(axis=0, keepdims=True)
        return a.mean(axis=1), a.mean(axis=2)  # horizontal (T, gx), vertical (T, gy)

    def corr(a, b):
        a, b = a.ravel(), b.ravel()
        return float(np.corrcoef(a, b)[0, 1]) if a.std() > 0 and b.std() > 0 else float("nan")

    def share(h):
        m = h.mean(axis=1, keepdims=True)
        return float((m**2).sum() * h.shape[1] / max((h**2).sum(), 1e-30))

    h, v = plots(x)
    rh, rv = plots(ref)
    return {"corr_h": corr(h, rh), "corr_v": corr(v, rv), "share": share(h), "share_pt": share(rh),
            "power_ratio": float((h**2).mean() / max((rh**2).mean(), 1e-30)), "rms_pt": float(np.sqrt((rh**2).mean()))}


def main(argv=None) -> int:
    ap = argparse.ArgumentParser()
    ap.add_argument("--scenes", type=int, default=10)
    ap.add_argument("--frames", type=int, default=120)
    ap.add_argument("--fps", type=float, default=15.0)
    ap.add_argument("--grid", default="16x24")
    ap.add_argument("--spp", type=int, default=256)
    ap.add_argument("--seed", type=int, default=900)
    ap.add_argument("--json", default=None)
    a = ap.parse_args(argv)
    gy, gx = (int(v) for v in a.grid.split("x"))
    rows = []
    for k in range(a.scenes):
        n, acts = PLAN[k % len(PLAN)]
        cfg = SceneConfig(people=n, activities=acts, duration=a.frames / a.fps, fps=a.fps, grid=(gy, gx),
                          domain="wide", distance=(1.0, 3.5), roam=2.0)
        scene = sample_scene(a.seed + k, cfg)
        t0 = time.time()
        on, off = room_changes(scene, True), room_changes(scene, False)
        t1 = time.time()
        pt = pt_changes(scene, a.spp)
        t2 = time.time()
        r = {"seed": a.seed + k, "acts": "+".join(acts), "lamps": len(scene.room.lamp_radius), "windows": len(scene.room.windows),
             "on": stats(on, pt), "off": stats(off, pt), "room_s": round(t1 - t0, 1), "pt_s": round(t2 - t1, 1)}
        rows.append(r)
        print(json.dumps(r), file=sys.stderr, flush=True)
    if a.json:
        with open(a.json, "w") as f:
            json.dump(rows, f, indent=1)
    print(table(rows))
    return 0


def table(rows) -> str:
    out = ["| seed | people | lights | corr h (off -> on) | corr v (off -> on) | whole-wall share off / on / pt | power / pt off -> on |",
           "|---|---|---|---|---|---|---|"]
    for r in rows:
        on, off = r["on"], r["off"]
        out.append(f"| {r['seed']} | {r['acts']} | {r['lamps']} lamps, {r['windows']} windows/panels | "
                   f"{off['corr_h']:.2f} -> **{on['corr_h']:.2f}** | {off['corr_v']:.2f} -> **{on['corr_v']:.2f}** | "
                   f"{off['share']:.2f} / **{on['share']:.2f}** / {on['share_pt']:.2f} | {off['power_ratio']:.2f} -> **{on['power_ratio']:.2f}** |")
    return "\n".join(out)


if __name__ == "__main__":
    raise SystemExit(main())
