"""Dataset mode: many simulated scenes -> shards of labelled 256-sample space-time windows.

Determinism: scene i of a dataset is fully decided by (seed, i), and shard k always holds scenes
[k * shard_scenes, (k + 1) * shard_scenes), so the same command writes the same shards whatever
the number of jobs, and an interrupted run resumes by skipping the shards already on disk.
"""

from __future__ import annotations

import json
import math
import multiprocessing as mp
import os
from pathlib import Path
from typing import Callable

import numpy as np

from wallcli.datagen.clips import BINS, COUNT_ACTS, FPS, WINDOW, render_windows
from wallcli.datagen.ptcache import FORMAT as PT_FORMAT, VERSION as PT_VERSION
from wallcli.io import jsonfile
from wallcli.sim.motion import ACTIVITIES

FORMAT, VERSION = "wallcli.dataset", 1
SHARD_FORMAT = "wallcli.dataset-shard"
CLASSES = {"count": [0, 1, 2], "activity": list(ACTIVITIES)}
ARRAYS = ("horizontal", "vertical", "label", "people", "activity", "snr_db", "snr_db_weakest", "h_offset", "v_offset")


def recipe(task, seed, n, domain, world, windows_per_scene, shard_scenes, grid, placement="visible", spp=256,
           draws=1) -> dict:
    rec = {"task": task, "seed": int(seed), "windows": int(n), "domain": domain, "world": world,
            "windows_per_scene": int(windows_per_scene), "shard_scenes": int(shard_scenes), "grid": list(grid),
            "placement": placement, "generator": "wallcli.datagen v1",
            # bodies shadow the room's other surfaces (sim/shadows.py): data made before is other data
            "physics": "room-shadows"}
    if world == "pt":  # path traced: its sample count is part of the data (other worlds' recipes unchanged)
        rec["spp"] = int(spp)
        # clean scenes from the cache (datagen/ptcache.py), each under `draws` fresh cameras
        rec["clean_cache"] = {"format": PT_FORMAT, "version": PT_VERSION, "draws": int(draws)}
    if task == "count":  # the movers' activity mix (a dataset made with another mix is another dataset)
        rec["count_activities"] = dict(zip(*COUNT_ACTS))
    return rec


def _shards(n: int, wps: int, per: int) -> list[tuple[int, list[int], int]]:
    """[(shard index, scene indices, windows kept)]: the last scene/shard is trimmed to exactly n."""
    scenes = math.ceil(n / wps)
    out = []
    for k in range(math.ceil(scenes / per)):
        idx = list(range(k * per, min(scenes, (k + 1) * per)))
        keep = min(n - k * per * wps, len(idx) * wps)
        out.append((k, idx, keep))
    return out


def _shard_ok(path: Path, keep: int) -> bool:
    from wallcli.errors import WallcliError
    from wallcli.io.arrays import load_npz

    if not path.is_file():
        return False
    try:
        arrays, meta = load_npz(path, kind=SHARD_FORMAT)
    except WallcliError:
        return False
    return all(k in arrays for k in ARRAYS) and len(arrays["label"]) == keep


def _work(args):
    seed, index, task, domain, world, wps, grid, cam, placement, spp, draws = args
    if world == "pt":
        # the path tracer's clean irradiance is rendered once and cached outside the work tree;
        # scene `index` is clean scene index // draws under camera draw index % draws
        from wallcli.datagen import ptcache

        rec = ptcache.recipe(seed=seed, task=task, domain=domain, placement=placement, grid=grid, spp=spp)
        arrays, meta = ptcache.ensure_scene(rec, index // draws)
        return index, ptcache.compose_windows(arrays, meta, index % draws, windows=wps, domain=domain,
                                              camera_overrides=cam)
    out = render_windows(seed, index, task, domain=domain, world=world, windows=wps, grid=tuple(grid),
                         camera_overrides=cam, placement=placement, spp=spp)
    return index, out


def _terminated(signum, frame):
    raise SystemExit(0)


def _init_worker():
    # one BLAS thread per worker: the cores are already shared out by processes
    os.environ.setdefault("OMP_NUM_THREADS", "1")
    # Pool.terminate() sends SIGTERM: exit quietly (not the CLI's KeyboardInterrupt handler,
    # inherited through fork, which would print a traceback per worker) and through the
    # `finally` blocks, so render_windows removes its temporary video.
    import signal

    signal.signal(signal.SIGTERM, _terminated)
    np.seterr(all="ignore")


def build_dataset(out_dir: str | os.PathLike, n: int, task: str, *, seed: int = 0, jobs: int = 1,
                  domain: str = "base", world: str = "room", windows_per_scene: int = 4,
                  shard_scenes: int = 32, grid=(24, 32), force: bool = False,
                  advance: Callable[[int], None] | None = None, log: Callable[[str], None] | None = None,
                  camera_overrides: dict | None = None, placement: str = "visible", spp: int = 256,
                  draws: int = 1) -> dict:
    """Write (or finish) the dataset in ``out_dir``; returns the manifest.

    ``camera_overrides`` fixes camera parameters for every scene (tests, special sets); it is
    recorded in the recipe.
    """
    from wallcli.errors import WallcliError
    from wallcli.io.arrays import save_npz
    from wallcli.io.writer import output_folder, write_text_atomic

    out = output_folder(out_dir)
    rec = recipe(task, seed, n, domain, world, windows_per_scene, shard_scenes, grid, placement, spp, draws)
    if camera_overrides:
        rec["camera_overrides"] = dict(camera_overrides)
    manifest_path = out / "dataset.json"
    if manifest_path.exists() and not force:
        try:
            old = jsonfile.loads(manifest_path.read_text(encoding="utf-8"), allow_nan=True)
        except (OSError, ValueError) as exc:  # JSONDecodeError and UnicodeDecodeError are ValueErrors
            raise WallcliError(f"{manifest_path} is unreadable ({exc})", hint="use --force to start over") from exc
        if old.get("recipe") != rec:
            raise WallcliError(f"{out} holds a different dataset ({old.get('recipe')})",
                               hint="use the same options to resume, another folder, or --force to overwrite")
    plan = _shards(n, windows_per_scene, shard_scenes)
    manifest = {"format": FORMAT, "version": VERSION, "task": task, "classes": CLASSES[task], "fps": int(FPS),
                "window": WINDOW, "bins": BINS, "seed": int(seed), "recipe": rec,
                "shards": [{"file": f"shard-{k:05d}.npz", "n": keep} for k, _, keep in plan],
                "complete": False,
                "notes": "windows are stplot output (clip mean removed, 8-bit code units), resampled to 30 fps, "
                         "not normalised; label = people (count) or activity index (activity)"}
    write_text_atomic(manifest_path, json.dumps(manifest, indent=1), force=True)
    # shards of an earlier, larger dataset (--force with fewer windows) are not this one's: a
    # reader that globs shard-*.npz would train on them
    planned = {s["file"] for s in manifest["shards"]}
    for stale in out.glob("shard-*.npz"):
        if stale.name not in planned:
            stale.unlink(missing_ok=True)
    todo = []
    for k, idx, keep in plan:
        path = out / f"shard-{k:05d}.npz"
        if not force and _shard_ok(path, keep):
            if advance:
                advance(keep)
            continue
        todo.append((k, idx, keep))
    if log and len(todo) < len(plan):
        log(f"resuming: {len(plan) - len(todo)} of {len(plan)} shards already done")
    pending = {k: {"idx": idx, "keep": keep, "got": {}} for k, idx, keep in todo}
    owner = {i: k for k, idx, _ in todo for i in idx}
    tasks = [(seed, i, task, domain, world, windows_per_scene, list(grid), camera_overrides, placement, spp, draws)
             for k, idx, _ in todo for i in idx]
    if tasks:
        ctx = mp.get_context("fork") if hasattr(os, "fork") else mp.get_context()
        pool = ctx.Pool(max(1, int(jobs)), initializer=_init_worker) if jobs > 1 else None
        it = pool.imap(_work, tasks, chunksize=1) if pool else map(_work, tasks)
        try:
            for index, res in it:
                k = owner[index]
                sh = pending[k]
                sh["got"][index] = res
                if advance:
                    advance(len(res["label"]))
                if len(sh["got"]) == len(sh["idx"]):
                    _write_shard(out / f"shard-{k:05d}.npz", sh, task, seed, save_npz)
                    del pending[k]
        finally:
            if pool:
                pool.terminate()
                pool.join()
    manifest["complete"] = True
    write_text_atomic(manifest_path, json.dumps(manifest, indent=1), force=True)
    return manifest


def _write_shard(path: Path, shard: dict, task: str, seed: int, save_npz) -> None:
    parts = [shard["got"][i] for i in shard["idx"]]
    arrays = {k: np.concatenate([p[k] for p in parts])[: shard["keep"]] for k in ARRAYS}
    scenes = [s for p in parts for s in p["scenes"]][: shard["keep"]]
    meta = {"format": SHARD_FORMAT, "version": VERSION, "task": task, "seed": int(seed), "scenes": scenes}
    save_npz(path, arrays, meta, force=True)
