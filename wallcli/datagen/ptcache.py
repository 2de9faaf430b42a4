"""Path-traced clean scenes, rendered once and kept, then re-noised for every draw of a data set.

Path tracing is the slow part of a path-traced training window (seconds a scene on two CPU cores),
while the camera (noise, gain, tone curve, vignetting, codec, lighting nuisances) costs as much as
in the analytic world. So a scene's *clean* wall irradiance is rendered once and cached, outside
the work tree (``$WALLCLI_CACHE/pt``, default ``~/.cache/wallcli/pt``), and
:func:`compose_windows` draws a fresh camera over it as many times as wanted: one clean scene
gives many windows, and a later session on the same machine continues the cache. Everything is
decided by (seed, index): a lost cache is re-rendered identically.

Monte-Carlo noise. At the sample counts that keep rendering fast, the path tracer's noise in the
wall's column profile is of the order of a camera's (research/ptcache/README.md). With one
sampler seed for every frame (pathtrace.py's correlated sampling) that error is a smooth function
of where the person stands: a slow, signal-like drift. Here frame t is rendered with seed
``t mod SEEDS`` and the empty room is rendered once per seed, so the static room still cancels
exactly in dE = E(t) - E_empty(seed) while the error changes from frame to frame: it behaves like
extra temporal camera noise, which the training windows tolerate, instead of a fake signal.
"""

from __future__ import annotations

import hashlib
import json
import os
import time
from pathlib import Path

import numpy as np

from wallcli.datagen.clips import FPS, WINDOW, placement_of, scene_plan

FORMAT = "wallcli.pt-clean-scene"
VERSION = 2  # 2: the changes (dE, alone) stored as float16
SEEDS = 8  # sampler seeds cycled over the frames (and empty-room renders per scene)
ALONE_STEP = 3  # two-person scenes: each person alone rendered every ALONE_STEP frames (for the SNR fit)
# frame rates of the footage the models meet (the transfer set's labels: 24 and 30 fps), plus 25
RATES = (24.0, 25.0, 30.0)


def cache_base() -> Path:
    """wallcli's cache folder: $WALLCLI_CACHE, or ~/.cache/wallcli."""
    return Path(os.environ.get("WALLCLI_CACHE") or os.path.join(os.path.expanduser("~"), ".cache", "wallcli"))


def cache_root() -> Path:
    return cache_base() / "pt"


def recipe(*, seed: int, task: str = "count", domain: str = "wide", placement: str = "transfer",
           grid=(16, 24), spp: int = 64, duration: float | None = None) -> dict:
    """What decides a cached scene besides its index; ``duration`` (s) fixes every scene's length
    (default: one window and 1.5-6 s more, as dataset mode draws it)."""
    rec = {"format": FORMAT, "version": VERSION, "seed": int(seed), "task": task, "domain": domain,
           "placement": placement, "grid": [int(g) for g in grid], "spp": int(spp), "seeds": SEEDS,
           "rates": list(RATES), "alone_step": ALONE_STEP}
    if duration is not None:
        rec["duration"] = float(duration)
    return rec


def folder(rec: dict, root: Path | None = None) -> Path:
    """One folder per recipe: scenes of another recipe are other scenes."""
    key = hashlib.sha256(json.dumps(rec, sort_keys=True).encode()).hexdigest()[:10]
    return (root or cache_root()) / f"{rec['task']}-{rec['domain']}-{rec['placement']}-s{rec['seed']}-{key}"


def _config(rec: dict, index: int):
    from wallcli.sim.scene import SceneConfig

    rng = np.random.default_rng(np.random.SeedSequence([rec["seed"], int(index), 7]))
    people, acts, label = scene_plan(rng, rec["task"], rec["domain"])
    duration = WINDOW / FPS + rng.uniform(1.5, 6.0)
    duration = float(rec.get("duration") or duration)
    fps = float(rng.choice(RATES))
    place = placement_of(rec["placement"], acts)
    cfg = SceneConfig(people=people, activities=acts or None, duration=duration, grid=tuple(rec["grid"]),
                      domain=rec["domain"], world="pt", spp=rec["spp"], fps=fps, **place)
    return cfg, label


def render_clean(rec: dict, index: int) -> tuple[dict, dict]:
    """(arrays, meta) of scene ``index``: the wall's clean irradiance, nothing of a camera but its
    frame rate. Arrays: E0 (gy, gx, 3) the empty room (mean over the sampler seeds), dE (T, gy, gx,
    3) each frame's change from it, alone (P, T', gx, 3) each person's own relative column change
    at frames alone_t (T',) (two-person scenes only), wall_albedo (3,)."""
    from wallcli.sim.pathtrace import PathTracer
    from wallcli.sim.scene import sample_scene

    t0 = time.time()
    cfg, label = _config(rec, index)
    scene = sample_scene(rec["seed"], cfg, index=index)
    tracer = PathTracer(scene.room, scene.points, scene.people, scene.poses, spp=rec["spp"])
    tracer.mi.set_log_level(tracer.mi.LogLevel.Error)  # a multi-jittered count off a square warns per frame
    base = (int(rec["seed"]) * 1_000_003 + int(index) * 101) % 2**31
    seeds = [(base + k) % 2**31 for k in range(rec["seeds"])]
    empty = []
    for s in seeds:
        tracer.seed = s
        empty.append(tracer.irradiance(None))
    empty = np.stack(empty)
    T = len(scene.times)
    gy, gx = scene.points.shape[:2]
    dE = np.zeros((T, gy, gx, 3), np.float32)
    P = len(scene.people)
    alone_t = np.arange(0, T, ALONE_STEP) if P > 1 else np.zeros(0, int)
    alone = np.zeros((P if P > 1 else 0, len(alone_t), gx, 3), np.float32)
    E0 = empty.mean(axis=0)
    E0_safe = np.maximum(E0, 1e-12)
    for t in range(T) if P else ():
        k = t % len(seeds)
        tracer.seed = seeds[k]
        dE[t] = tracer.irradiance(t) - empty[k]
        if P > 1 and t % ALONE_STEP == 0:
            for j in range(P):
                alone[j, t // ALONE_STEP] = ((tracer.irradiance(t, who=[j]) - empty[k]) / E0_safe).mean(axis=0)
    truth = scene.truth()
    meta = {"format": FORMAT, "version": VERSION, "recipe": rec, "index": int(index), "label": int(label),
            "people": int(P), "activities": list(scene.activities), "activity": truth["activity"],
            "fps": float(scene.camera.fps), "frames": int(T), "room": truth["room"],
            "wall_region_m": truth["wall_region_m"], "persons": truth["persons"],
            "render_s": round(time.time() - t0, 2),
            "rendered_frames": int(len(seeds) + (T if P else 0) + len(alone_t) * (P if P > 1 else 0))}
    wall_albedo = np.clip(scene.room.albedo[2].mean(axis=(0, 1)), 0.05, 0.95).astype(np.float32)
    arrays = {"E0": E0.astype(np.float32), "dE": dE, "alone": alone, "alone_t": alone_t.astype(np.int32),
              "wall_albedo": wall_albedo}
    return arrays, meta


def scene_file(rec: dict, index: int, root: Path | None = None) -> Path:
    return folder(rec, root) / f"scene-{int(index):06d}.npz"


# The changes are stored as float16 rounded to 5 mantissa bits (a relative error of at most 1.6 %
# of each change, -40 dB: far under both the camera's noise and the path tracer's), which gzip
# packs to a quarter of float32. Bytes are what limits how many scenes a lent GPU machine can send
# back (64 MiB a call). E0 keeps float32: the static room is 100-1000 times any change.
STORED = ("dE", "alone")
MANTISSA_DROP = 5


def _round_f16(v: np.ndarray) -> np.ndarray:
    u = v.astype(np.float16).view(np.uint16).astype(np.uint32)
    keep = np.uint32(0xFFFF ^ ((1 << MANTISSA_DROP) - 1))
    return ((u + np.uint32(1 << (MANTISSA_DROP - 1))) & keep).astype(np.uint16).view(np.float16)


def to_stored(arrays: dict) -> dict:
    return {k: (_round_f16(v) if k in STORED else v) for k, v in arrays.items()}


def from_stored(arrays: dict) -> dict:
    return {k: (v.astype(np.float32) if k in STORED else v) for k, v in arrays.items()}


def load_scene(path: Path) -> tuple[dict, dict] | None:
    """A cached scene (changes back in float32), or None when it is missing, unreadable or of
    another format version (then it is rendered again)."""
    from wallcli.errors import WallcliError
    from wallcli.io.arrays import load_npz

    if not Path(path).is_file():
        return None
    try:
        arrays, meta = load_npz(path, kind=FORMAT)
    except WallcliError:
        return None
    if meta.get("version") != VERSION:
        return None
    return from_stored(arrays), meta


def store_scene(path: Path, arrays: dict, meta: dict) -> tuple[dict, dict]:
    """Write a rendered scene to the cache; returns it as :func:`load_scene` will read it."""
    from wallcli.io.arrays import save_npz

    path.parent.mkdir(parents=True, exist_ok=True)
    (path.parent / "recipe.json").write_text(json.dumps(meta["recipe"], indent=1))
    stored = to_stored(arrays)
    save_npz(path, stored, meta, force=True)
    return from_stored(stored), meta


def ensure_scene(rec: dict, index: int, root: Path | None = None) -> tuple[dict, dict]:
    """The cached scene, rendered and stored first when it is not there yet."""
    path = scene_file(rec, index, root)
    got = load_scene(path)
    if got is not None:
        return got
    return store_scene(path, *render_clean(rec, index))


class _Profiles:
    """What dataset mode's SNR fit reads of a scene (clips._window_snr_db): per frame the clean
    relative column and row change, and with two people each one's own column change."""

    def __init__(self, arrays: dict, meta: dict):
        E0 = np.maximum(arrays["E0"], 1e-12)
        rel = arrays["dE"] / E0
        cols, rows = rel.mean(axis=1), rel.mean(axis=2)
        T = len(cols)
        if meta["people"] > 1:
            t_at = arrays["alone_t"].astype(float)
            alone = [np.stack([np.interp(np.arange(T), t_at, a[:, g, c]) for g in range(a.shape[1]) for c in range(3)],
                              axis=1).reshape(T, a.shape[1], 3) for a in arrays["alone"]]
            self.clean_profiles = [(cols[t], rows[t], [a[t] for a in alone]) for t in range(T)]
        else:  # nobody: no profiles, no SNR (NaN), as in dataset mode
            self.clean_profiles = [(cols[t], rows[t]) for t in range(T)] if meta["people"] else []


def compose_windows(arrays: dict, meta: dict, draw: int, *, windows: int = 4, tmpdir: str | None = None,
                    domain: str = "wide", camera_overrides: dict | None = None) -> dict:
    """Windows of one cached scene under camera draw ``draw``: a fresh camera (noise, gain, tone
    curve, vignetting, codec, lighting nuisances) at the scene's frame rate, a real video file, and
    the real stplot path, exactly as :func:`wallcli.datagen.clips.render_windows` makes them."""
    from wallcli.datagen.clips import cut_windows, recorded_plot
    from wallcli.sim.camera import Camera, sample_camera
    from wallcli.sim.motion import ACTIVITIES

    rec = meta["recipe"]
    rng = np.random.default_rng(np.random.SeedSequence([rec["seed"], meta["index"], 11, int(draw)]))
    cam = sample_camera(rng, domain)
    for k, v in (camera_overrides or {}).items():  # tests, special sets; never the frame rate (the scene's)
        if k != "fps":
            setattr(cam, k, v)
    cam.fps = float(meta["fps"])
    E0, dE = arrays["E0"], arrays["dE"]
    T = len(dE)
    camera = Camera(cam, E0, arrays["wall_albedo"], T, rng)
    plot = recorded_plot((camera.render(dE[i], i, static_E=E0) for i in range(T)), cam, tmpdir)
    info = {"seed": rec["seed"], "index": meta["index"], "draw": int(draw), "world": "pt", "spp": rec["spp"],
            "people": meta["people"], "activity": meta["activity"], "activities": meta["activities"],
            "fps": cam.fps, "frames": T, "width": cam.width, "height": cam.height, "domain": domain,
            "camera": cam.to_dict(), "room": meta["room"],
            "distance_m": [round(float(np.median(np.array(p["positions"])[:, 1])), 2) for p in meta["persons"]]}
    return cut_windows(plot, cam, rng, windows, _Profiles(arrays, meta), label=meta["label"], people=meta["people"],
                       activity=ACTIVITIES.index(meta["activity"]), info=info)
