"""One training scene: sample -> render -> encode a real video file -> the real stplot path -> windows.

The windows go through exactly the code real videos go through (``open_video`` ->
``compute_stplot`` -> ``resample``), including the codec, chroma subsampling and the reader's
colour conversion, so the model never sees a shortcut that only simulations have.
"""

from __future__ import annotations

import os
import tempfile
from pathlib import Path

import numpy as np

from wallcli.sim import WIDE_DOMAINS

from wallcli.sim.camera import interp_matrix, video_pix_fmt
from wallcli.sim.motion import ACTIVITIES
from wallcli.sim.scene import SceneConfig, sample_scene
from wallcli.sim.world_flat import sample_flat_scene

WINDOW, FPS, BINS = 256, 30.0, 64
# Where dataset people go. 'visible': 0.8-4 m from the wall and walking within 1.5 m of the observed
# patch, where their light change stands above a camera's noise (the seed's experiments put people
# 1.75-3.95 m away); 'anywhere': 1-5 m, roaming 2.5 m, as `simulate` videos do (many such windows
# carry no detectable signal, which only teaches a model to guess).
PLACEMENTS = {"visible": {"distance": (0.8, 4.0), "roam": 1.5}, "anywhere": {"distance": (1.0, 5.0), "roam": 2.5},
              # 'wide': 1-5 m, roaming 2 m, as people are in rooms; windows where they cannot be
              # seen are measured (snr_db) and left out of training by --min-snr-db
              "wide": {"distance": (1.0, 5.0), "roam": 2.0},
              # 'transfer': as 'wide', but people who move in place (crouch, wave, jump) stand 1-3 m
              # from the wall, close enough to be seen, as the footage users bring (and the transfer
              # set: median snr_db of its crouchers, wavers and jumpers 3-9 dB) shows them; 'wide'
              # put 89 % of them under the noise
              "transfer": {"distance": (1.0, 5.0), "roam": 2.0}}
IN_PLACE = {"distance": (1.0, 3.0), "roam": 2.0}


def placement_of(placement: str, activities: list[str]) -> dict:
    """Where the people of a scene go (SceneConfig's distance and roam)."""
    if placement == "transfer" and activities and all(a not in ("walking",) for a in activities):
        return dict(IN_PLACE)
    return dict(PLACEMENTS[placement])
# Class mixes. Count: the task counts people who *move*; someone standing still sways a centimetre,
# far under any camera's noise, so a standing person in a count scene would be label noise. Count
# scenes hold movers only, each drawing an activity independently (walking most often: it is the
# commonest way to be in a room and the hardest to tell one from two).
COUNT_ACTS = (["walking", "crouching", "waving", "jumping"], [0.46, 0.18, 0.18, 0.18])


def scene_plan(rng: np.random.Generator, task: str, domain: str = "base") -> tuple[int, list[str], int]:
    """(people, activities, label) for one scene, balanced over the task's classes.

    The 'wide' domain's count scenes serve both tasks: movers' activities are balanced, and a
    third of the empty rooms hold someone standing still (label 0: count counts movers), whose
    sway can be visible."""
    if task == "count" and domain in WIDE_DOMAINS:
        n = int(rng.integers(0, 3))
        if n == 0:
            return (1, ["none"], 0) if rng.random() < 0.35 else (0, [], 0)
        return n, [str(rng.choice(COUNT_ACTS[0])) for _ in range(n)], n
    if task == "count":
        n = int(rng.integers(0, 3))
        acts = [str(rng.choice(COUNT_ACTS[0], p=COUNT_ACTS[1])) for _ in range(n)]
        return n, acts, n
    label = int(rng.integers(0, len(ACTIVITIES)))
    act = ACTIVITIES[label]
    if act == "none":  # nobody, or someone standing still
        n = int(rng.random() < 0.5)
        return n, ["none"] * n, label
    return 1, [act], label


def _window_starts(length: int, k: int, rng) -> list[int]:
    """k window starts spread over the clip (overlapping when the clip is short), jittered."""
    span = length - WINDOW
    if span < 0:
        return []
    base = np.linspace(0, span, k)
    jitter = rng.uniform(-0.5, 0.5, k) * (span / max(k, 1))
    return sorted(int(v) for v in np.clip(np.rint(base + jitter), 0, span))


def _window_snr_db(scene, cam, h: np.ndarray, t: np.ndarray, starts: list[int]) -> tuple[np.ndarray, np.ndarray]:
    """Per window: how visible the people are in the plot that was actually recorded, in dB.

    The renderer's noise-free relative irradiance change, averaged over wall rows and resampled
    like the plot, is fitted to the window by least squares (one gain per person, since exposure,
    tone curve and vignetting scale it): SNR = power of the fitted signal / power of what is left
    (noise, camera nuisances, compression artefacts). A signal that the codec erased (H.264 skips
    blocks that barely change) or that drowns in noise scores low, whatever the scene's physics
    promised. Returns (all movers together, the least visible mover alone); NaN where nobody
    moves (or in flatland). Lets training and evaluation stratify windows by visibility.
    """
    both = np.full(len(starts), np.nan, np.float32)
    weakest = np.full(len(starts), np.nan, np.float32)
    profiles = getattr(scene, "clean_profiles", None)
    if not profiles:
        return both, weakest

    def prep(seq):
        return profile_on_plot(seq, cam.fps, h.shape[0])

    clean = prep([p[0] for p in profiles])
    if not np.any(clean):  # nobody in the scene
        return both, weakest
    people = [prep([p[2][j] for p in profiles]) for j in range(len(profiles[0][2]))] if len(profiles[0]) > 2 else [clean]
    for k, s in enumerate(starts):
        x = h[:, s : s + WINDOW].astype(np.float64)
        if x.shape[1] < WINDOW or clean.shape[1] < s + WINDOW:
            continue
        x = (x - x.mean(axis=1, keepdims=True)).ravel()
        each, total = _fit_snr_db(x, [c[:, s : s + WINDOW] for c in people])
        both[k], weakest[k] = total, each.min()
    return both, weakest


def profile_on_plot(seq: list[np.ndarray], fps: float, bins: int) -> np.ndarray:
    """Per-frame (gx, 3) noise-free profiles of the wall columns -> (bins, T', 3), at the plot's
    rate (FPS) and bins, so they can be fitted to the recorded plot."""
    from wallcli.signal.window import resample

    c = np.stack(seq, axis=1)
    c, _ = resample(c, np.arange(c.shape[1]) / fps, FPS)
    return np.einsum("bg,gtc->btc", interp_matrix(bins, c.shape[0]), c)


def _fit_snr_db(x: np.ndarray, signals: list[np.ndarray]) -> tuple[np.ndarray, float]:
    """Least-squares fit of x by the (mean-removed) signals, one gain each: (each one's fitted
    power over the residual's, all of them together over the residual's), in dB."""
    A = np.stack([(c - c.mean(axis=1, keepdims=True)).astype(np.float64).ravel() for c in signals], axis=1)
    norms = np.sum(A * A, axis=0)
    ok = norms > 0
    out = np.full(len(signals), -np.inf)
    if not ok.any():
        return out, -np.inf
    beta, *_ = np.linalg.lstsq(A[:, ok], x, rcond=None)
    fit = A[:, ok] @ beta
    rest = max(float(np.sum((x - fit) ** 2)), 1e-30)
    out[ok] = 10.0 * np.log10(np.maximum(beta**2 * norms[ok], 1e-30) / rest)
    return out, float(10.0 * np.log10(max(float(np.sum(fit * fit)), 1e-30) / rest))


def render_windows(seed: int, index: int, task: str, *, domain: str = "base", world: str = "room",
                   windows: int = 3, grid: tuple[int, int] = (24, 32), tmpdir: str | None = None,
                   camera_overrides: dict | None = None, placement: str = "visible", spp: int = 256) -> dict:
    """All windows of scene ``index``: arrays (k, BINS, WINDOW, 3) + labels + the scene's parameters."""
    rng = np.random.default_rng(np.random.SeedSequence([int(seed), int(index), 7]))
    people, acts, label = scene_plan(rng, task, domain)
    if world == "mixed":
        world = "flatland" if (task == "count" and rng.random() < 0.25) else "room"
    duration = WINDOW / FPS + rng.uniform(1.5, 6.0)
    if world == "flatland":
        if task != "count":
            raise ValueError("flatland has no activities; use it for the count task")
        scene = sample_flat_scene(seed, index, people, duration=duration, domain=domain)
        for k, v in (camera_overrides or {}).items():
            setattr(scene.camera, k, v)
        acts = ["walking"] * people
    else:
        cfg = SceneConfig(people=people, activities=acts or None, duration=duration, grid=grid, domain=domain,
                          camera_overrides=dict(camera_overrides or {}), world="pt" if world == "pt" else "room", spp=spp,
                          **placement_of(placement, acts))
        scene = sample_scene(seed, cfg, index=index)
        scene.clean_profiles = []
    cam = scene.camera
    plot = recorded_plot(scene.frames(), cam, tmpdir)
    truth = scene.truth()
    meta = {k: truth[k] for k in ("people", "activity", "activities", "fps", "frames", "width", "height", "domain")}
    meta.update(seed=int(seed), index=int(index), world=world, camera=truth["camera"],
                room=truth.get("room"), distance_m=[round(float(np.median(np.array(p["positions"])[:, 1])), 2) for p in truth["persons"]])
    return cut_windows(plot, cam, rng, windows, scene, label=label, people=len(acts),
                       activity=ACTIVITIES.index(truth["activity"]), info=meta)


def recorded_plot(frames, cam, tmpdir: str | None = None):
    """The space-time plot of ``frames`` (uint8 RGB) as camera ``cam`` records them: a real video
    file (its codec, CRF and chroma), read back through the real stplot path."""
    from wallcli.io.video import open_video
    from wallcli.io.writer import VideoWriter
    from wallcli.signal.stplot import compute_stplot

    suffix = ".mkv" if cam.codec == "ffv1" else ".mp4"
    fd, name = tempfile.mkstemp(suffix=suffix, dir=tmpdir)
    os.close(fd)
    path = Path(name)
    try:
        with VideoWriter(path, cam.fps, cam.width, cam.height, codec=cam.codec, crf=cam.crf,
                         pix_fmt=video_pix_fmt(cam), preset="veryfast", repeatable=True) as w:
            for frame in frames:
                w.write(frame)
        with open_video(path) as reader:
            return compute_stplot(reader, bins=BINS)
    finally:
        path.unlink(missing_ok=True)


def cut_windows(plot, cam, rng, windows: int, profiles, *, label: int, people: int, activity: int, info: dict) -> dict:
    """A recorded plot's training windows (k, BINS, WINDOW, 3) at FPS, their labels, their measured
    visibility (``profiles``: what :func:`_window_snr_db` reads, the clean profiles of the scene) and
    ``info`` per window, as a dataset shard holds them."""
    from wallcli.signal.window import resample

    h, t = resample(plot.horizontal, plot.time, FPS)
    v, _ = resample(plot.vertical, plot.time, FPS)
    starts = _window_starts(h.shape[1], windows, rng)
    snr, snr_weakest = _window_snr_db(profiles, cam, h, t, starts)
    return {
        "horizontal": np.stack([h[:, s : s + WINDOW] for s in starts]).astype(np.float32),
        "vertical": np.stack([v[:, s : s + WINDOW] for s in starts]).astype(np.float32),
        "label": np.full(len(starts), label, np.int64),
        "people": np.full(len(starts), people, np.int64),
        "activity": np.full(len(starts), activity, np.int64),
        "snr_db": snr,
        "snr_db_weakest": snr_weakest,
        # the clip's mean raw level per position and colour (the plot is that mean removed): what
        # normalisation v3 needs to tell a whole-wall light change from a person
        "h_offset": np.repeat(plot.h_mean[None].astype(np.float32), len(starts), axis=0),
        "v_offset": np.repeat(plot.v_mean[None].astype(np.float32), len(starts), axis=0),
        "scenes": [dict(info, window_start_s=round(s / FPS, 3)) for s in starts],
    }
