"""Fill the path-traced clean-scene cache (wallcli/datagen/ptcache.py) in the background.

    python research/ptcache/fill.py --seed 500 --start 0 --stop 3000 --jobs 2 [--spp 64 --grid 16x24] [--budget S]

``--budget S`` stops starting scenes after S seconds and ends (scenes in flight are lost), so that
a timed call on a lent machine (research/transfer/device_run.sh pt) leaves time to pack.

Scenes already cached are skipped, so an interrupted run (or a later session on the same machine)
continues where it stopped. Prints one line a scene and the running throughput in path-traced
frames a second.
"""
from __future__ import annotations

import argparse
import multiprocessing as mp
import os
import time


def _one(args):
    rec, index = args
    from wallcli.datagen.ptcache import load_scene, render_clean, scene_file, store_scene

    path = scene_file(rec, index)
    if load_scene(path) is not None:
        return index, 0, 0.0, None
    t = time.time()
    arrays, meta = render_clean(rec, index)
    store_scene(path, arrays, meta)
    return index, meta["rendered_frames"], time.time() - t, f"{meta['people']}p {'+'.join(meta['activities']) or 'empty'}"


def main(argv=None) -> int:
    ap = argparse.ArgumentParser()
    ap.add_argument("--seed", type=int, default=500)
    ap.add_argument("--start", type=int, default=0)
    ap.add_argument("--stop", type=int, default=3000)
    ap.add_argument("--jobs", type=int, default=2)
    ap.add_argument("--spp", type=int, default=64)
    ap.add_argument("--grid", default="16x24")
    ap.add_argument("--task", default="count")
    ap.add_argument("--placement", default="transfer")
    ap.add_argument("--budget", type=float, default=0.0, help="seconds; 0: no limit")
    a = ap.parse_args(argv)
    from wallcli.datagen.ptcache import recipe

    gy, gx = (int(v) for v in a.grid.split("x"))
    rec = recipe(seed=a.seed, task=a.task, grid=(gy, gx), spp=a.spp, placement=a.placement)
    os.environ.setdefault("OMP_NUM_THREADS", "1")
    t0, frames, done = time.time(), 0, 0
    ctx = mp.get_context("spawn")
    with ctx.Pool(a.jobs) as pool:
        for index, n, dt, what in pool.imap_unordered(_one, [(rec, i) for i in range(a.start, a.stop)]):
            if a.budget and time.time() - t0 > a.budget:
                print(f"budget of {a.budget:.0f} s spent: stopping", flush=True)
                pool.terminate()
                break
            if what is None:
                continue
            frames += n
            done += 1
            el = time.time() - t0
            print(f"scene {index} {what}: {n} frames in {dt:.1f} s; {done} scenes, {frames / el:.1f} frames/s overall",
                  flush=True)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
