"""Which sample count does the path-traced training data need? (issue 35, point 2)

For path-traced scenes of the kind the dataset renders (domain 'wide', placement 'wide', one
mover, the grid the cache uses), the Monte-Carlo noise of the wall's column profile of dE/E at
N spp is measured against a 1024-spp reference of the same frames, and compared with the camera
noise of one column's mean in one frame (the transfer set's definition of its snr_db) for a
camera drawn from the 'wide' sampler at the cache's frame size.

    python research/ptcache/spp_noise.py [--scenes 12] [--frames 40] [--grid 16x24] [--ref 1024] [--spps 8,16,32,64,128]

Prints a table: per spp, the MC noise over the camera noise (median and 90th percentile over
scenes whose reference signal is within 6 dB of the camera noise, i.e. scenes near 0 dB, and
over all scenes), and frames/s.
"""
from __future__ import annotations

import argparse
import time

import numpy as np

from wallcli.datagen.clips import PLACEMENTS
from wallcli.sim.camera import sample_camera
from wallcli.sim.pathtrace import PathTracer
from wallcli.sim.scene import SceneConfig, sample_scene

SPPS = (8, 16, 32, 64, 128)


def column_noise(rng, width=96, height=72) -> float:
    """Relative temporal noise of one column's mean in one frame for a 'wide' camera."""
    p = sample_camera(rng, "wide")
    per_pixel_codes = np.sqrt(p.level * p.gain + p.read_noise**2) / np.sqrt(p.sensor_pixels / (width * height))
    per_pixel_codes = max(per_pixel_codes, 0.35)
    return float(per_pixel_codes / p.level / np.sqrt(height))


def profile(tr: PathTracer, frames: int) -> np.ndarray:
    E0 = np.maximum(tr.irradiance(None), 1e-12)
    return np.stack([((tr.irradiance(i) - E0) / E0).mean(axis=(0, 2)) for i in range(frames)])


def main(argv=None) -> int:
    ap = argparse.ArgumentParser()
    ap.add_argument("--scenes", type=int, default=12)
    ap.add_argument("--frames", type=int, default=40)
    ap.add_argument("--grid", default="16x24")
    ap.add_argument("--seed", type=int, default=900)
    ap.add_argument("--ref", type=int, default=1024, help="the reference's samples per point")
    ap.add_argument("--spps", default=",".join(map(str, SPPS)))
    a = ap.parse_args(argv)
    spps = [int(v) for v in a.spps.split(",")]
    gy, gx = (int(v) for v in a.grid.split("x"))
    rng = np.random.default_rng(a.seed)
    rows = []
    acts = ["walking", "crouching", "waving", "jumping"]
    for k in range(a.scenes):
        act = acts[k % 4]
        cfg = SceneConfig(people=1, activities=[act], duration=a.frames / 30 + 0.1, fps=30, grid=(gy, gx), domain="wide",
                          **PLACEMENTS["wide"])
        sc = sample_scene(a.seed, cfg, index=k)
        ref = profile(PathTracer(sc.room, sc.points, sc.people, sc.poses, spp=a.ref, seed=k), a.frames)
        sig = float(np.sqrt(np.mean((ref - ref.mean(0)) ** 2)))
        cam = column_noise(rng)
        row = {"act": act, "snr_db": 20 * np.log10(max(sig, 1e-12) / cam)}
        for spp in spps:
            tr = PathTracer(sc.room, sc.points, sc.people, sc.poses, spp=spp, seed=k)
            t = time.time()
            pr = profile(tr, a.frames)
            row[f"fps{spp}"] = (a.frames + 1) / (time.time() - t)
            row[spp] = float(np.sqrt(np.mean((pr - ref) ** 2))) / cam
        rows.append(row)
        print(f"scene {k} {act:9s} snr {row['snr_db']:6.1f} dB  " + "  ".join(f"{s}:{row[s]:.2f}" for s in spps), flush=True)
    near = [r for r in rows if abs(r["snr_db"]) <= 6]
    print(f"\n{len(rows)} scenes, {len(near)} within 6 dB of 0 dB; grid {gy}x{gx}")
    print("| spp | MC / camera noise, near 0 dB: median | 90th pct | all scenes: median | 90th pct | frames/s (one process) |")
    print("|---|---|---|---|---|---|")
    print(f"reference: {a.ref} spp")
    for s in spps:
        nv = np.array([r[s] for r in near]) if near else np.array([np.nan])
        av = np.array([r[s] for r in rows])
        fps = np.median([r[f"fps{s}"] for r in rows])
        print(f"| {s} | {np.median(nv):.3f} | {np.percentile(nv, 90):.3f} | {np.median(av):.3f} | {np.percentile(av, 90):.3f} | {fps:.1f} |")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
