"""``wallcli simulate``: physically grounded synthetic wall videos, or whole training sets."""

from __future__ import annotations

from pathlib import Path
from typing import Optional

import typer

from wallcli.cli.common import MAX_THREADS, force_help, number_option

ACTS = ("none", "walking", "crouching", "waving", "jumping")


def _pair(text: str, name: str, most: float) -> tuple[float, float]:
    from wallcli.errors import UsageError

    try:
        a, b = (float(v) for v in text.split(","))
    except ValueError:
        raise UsageError(f"{name} must be two numbers MIN,MAX (got {text!r})") from None
    if not (0 <= a <= b <= most):  # NaN fails this too
        raise UsageError(f"{name} needs 0 <= MIN <= MAX <= {most:g} (got {text!r})")
    return a, b


def _size(text: str, name: str, most: int, sep: str = "x") -> tuple[int, int]:
    from wallcli.errors import UsageError

    try:
        a, b = (int(v) for v in text.lower().split(sep))
    except ValueError:
        raise UsageError(f"{name} must look like 160{sep}120 (got {text!r})") from None
    if a < 2 or b < 2:
        raise UsageError(f"{name} is too small (got {text!r})")
    if a > most or b > most:
        raise UsageError(f"{name} is too large: at most {most}{sep}{most} (got {text!r})")
    return a, b


def simulate(
    output: Path = typer.Option(..., "--output", "-o", help="Video to write (.mp4 = H.264, .mkv = lossless FFV1, .y4m = raw); "
                                "the ground truth goes beside it as .json. With --dataset: the folder for the shards."),
    people: Optional[int] = number_option(1, "--people", "-n", lo=0, hi=2, integer=True, help="Number of people in the hidden room (0, 1 or 2)."),
    activity: str = typer.Option("walking", "--activity", "-a", help="none | walking | crouching | waving | jumping | random; "
                                 "a comma list gives one per person (e.g. walking,waving). 'none' = standing still."),
    seed: int = number_option(0, "--seed", lo=0, hi=2**32 - 1, integer=True, help="Random seed: room, lamps, textures, people, paths, camera and noise all follow "
                             "from it. Same seed + options = identical video."),
    duration: float = number_option(12.0, "--duration", lo=0.2, hi=600, help="Clip length in seconds."),
    fps: float = number_option(30.0, "--fps", lo=15, hi=60, help="Frame rate."),
    size: str = typer.Option("320x240", "--size", help="Frame size WxH in pixels (even numbers for .mp4)."),
    grid: Optional[str] = typer.Option(None, "--grid", help="Wall points RxC where the irradiance is rendered and interpolated "
                                       "to pixels (default 64x64 for a video, 24x32 in dataset mode, for speed: the signal is smooth)."),
    crf: Optional[int] = number_option(None, "--crf", lo=0, hi=51, integer=True, help="H.264 quality for .mp4 and "
                                       ".mov (0 = lossless, 18 = visually clean and the default, 28 = strong "
                                       "compression that erases faint signals); refused for .mkv (lossless) and .y4m (raw)."),
    world: str = typer.Option("room", "--world", help="room: 3-D box room with articulated people; flatland: the paper's 2-D world (supplementary §4) "
                              "(people = 1-2 moving occluders, horizontal information only); pt: the same rooms and "
                              "motions path traced by Mitsuba 3 (people of boxes, three bounces; needs "
                              "pip install mitsuba==3.9.1; slow on a CPU, meant for a GPU); mixed (--dataset only): room "
                              "with some flatland count scenes."),
    draws: int = number_option(1, "--draws", lo=1, hi=1000, integer=True, help="--dataset --world pt: cameras drawn "
                               "over each clean path-traced scene (noise, gain, tone curve, codec, lighting nuisances "
                               "afresh each time); the clean scenes are rendered once into $WALLCLI_CACHE/pt "
                               "(default ~/.cache/wallcli/pt) and reused by later runs."),
    spp: int = number_option(256, "--spp", lo=1, hi=65536, integer=True, help="--world pt: path-traced samples per wall point "
                             "and frame (Monte Carlo noise in the people's signal falls as 1/sqrt(spp))."),
    domain: str = typer.Option("base", "--domain", help="base: training ranges; shifted: moved ranges of room size, lights, "
                               "clothing, body size, camera (an honest held-out validation set); wide: both and more (windows, ceiling "
                               "panels, small frames, lighting nuisances in half the clips, periodic waving and jumping half the "
                               "time); steady: wide with steady light in most rooms (nuisances in a sixth); bracket: steady with the bodies' "
                               "radiance (0.3-1.5x) and the shadows they cast on the room (0.5-3x) drawn per scene, so that "
                               "the analytic world brackets a path tracer's signal."),
    distance: str = typer.Option("1,5", "--distance", help="MIN,MAX distance of people from the wall (m)."),
    speed: str = typer.Option("0.5,1.8", "--speed", help="MIN,MAX walking speed (m/s)."),
    level: Optional[float] = number_option(None, "--level", lo=5, hi=250, help="Mean wall brightness in 8-bit codes (default: random from the seed)."),
    iso_gain: Optional[float] = number_option(None, "--iso-gain", lo=0, hi=100, help="Codes per photo-electron: photon shot noise grows with it "
                                             "(0.01 bright scene/low ISO .. 2 dim room/high ISO; default random)."),
    read_noise: Optional[float] = number_option(None, "--read-noise", lo=0, hi=255, help="Read noise, codes rms per sensor pixel (default random 0.3-3)."),
    sensor_pixels: Optional[float] = number_option(None, "--sensor-pixels", lo=1, hi=1e12, help="Sensor pixels the wall covers in the "
                                                  "imagined camera; the frame's noise is that of averaging them down "
                                                  "(default: the frame's own pixel count, i.e. no averaging)."),
    prnu: Optional[float] = number_option(None, "--prnu", lo=0, hi=0.5, help="Pixel response non-uniformity, relative (default random 0.2-2 %)."),
    gamma: Optional[float] = number_option(None, "--gamma", lo=0, hi=10, help="Tone curve exponent (2.2 ~ sRGB; 0 = linear; default random)."),
    noise_scale: float = number_option(1.0, "--noise-scale", lo=0, hi=100, help="Multiply all temporal noise (0 leaves only the rounding dither)."),
    drift: Optional[float] = number_option(None, "--drift", lo=0, hi=0.5, help="Slow light drift, relative amplitude (e.g. 0.005)."),
    flicker: Optional[float] = number_option(None, "--flicker", lo=0, hi=0.5, help="Mains flicker, relative amplitude, aliased to the frame rate."),
    mains: Optional[float] = number_option(None, "--mains", lo=50, hi=60, help="Mains frequency for flicker: 50 or 60 Hz."),
    rolling_shutter: Optional[float] = number_option(None, "--rolling-shutter", lo=0, hi=1, help="Rolling-shutter readout time as a "
                                                     "fraction of the frame interval: --flicker then shows as bright and dark "
                                                     "bands that travel down the frame (0 = global shutter, the default)."),
    ae_steps: Optional[int] = number_option(None, "--ae-steps", lo=0, hi=10, integer=True, help="Number of auto-exposure steps (each 0.5-3 %)."),
    shake: Optional[float] = number_option(None, "--shake", lo=0, hi=5, help="Camera shake, rms pixels (sub-pixel, e.g. 0.1)."),
    dup_frames: Optional[float] = number_option(None, "--dup-frames", lo=0, hi=0.5, help="Share of frames replaced by an exact "
                                                "copy of the frame before, in runs of 1-3, as a DVR pads to its nominal rate "
                                                "(the sidecar says how many: duplicated)."),
    tnr: Optional[float] = number_option(None, "--tnr", lo=0, hi=0.95, help="Temporal noise reduction as phones and DVRs "
                                         "apply it on still scenes: each frame blended with the last output, "
                                         "out = A prev + (1 - A) in (0.3-0.8 typical; the noise is then correlated "
                                         "from frame to frame)."),
    awb_drift: Optional[float] = number_option(None, "--awb-drift", lo=0, hi=0.2, help="Auto white balance hunting: slow "
                                               "per-colour gains, each wandering its own way by up to this relative "
                                               "amplitude (e.g. 0.01)."),
    overlay: bool = typer.Option(False, "--overlay", help="Burn in a CCTV clock (HH:MM:SS, with the date on frames 240 "
                                 "px wide or more) at the top left, white and flat, changing every second."),
    camera_name: Optional[str] = typer.Option(None, "--camera-name", help="With --overlay: also burn in this fixed "
                                              "text at the bottom right (e.g. 'CAM 01')."),
    clock_start: Optional[str] = typer.Option(None, "--clock-start", help="With --overlay: the clock's reading at the "
                                              "clip's start, HH:MM:SS (default 16:00:00; e.g. 16:00:53 steps its tens "
                                              "of seconds, minute and date digits mid-clip, not only the seconds)."),
    interlace: Optional[str] = typer.Option(None, "--interlace", help="tff | bff: render at twice --fps and weave "
                                            "the frames two by two into interlaced ones, the top (tff) or the "
                                            "bottom (bff) field first, half a frame apart."),
    nuisances: float = number_option(0.0, "--nuisances", lo=0, hi=1, help="Probability that random drift/flicker/AE steps/shake "
                                    "are switched on (explicit options above always apply)."),
    preview: Optional[Path] = typer.Option(None, "--preview", help="Also draw the room from above with the paths beside the "
                                           "video's space-time plots (PNG)."),
    json_out: bool = typer.Option(False, "--json", help="Print the ground truth (without per-frame positions) as JSON on stdout; "
                                  "with --dataset, a summary with the measured windows/s."),
    force: bool = typer.Option(False, "--force", help=force_help("OUTPUT, its .json ground truth and the --preview file")
                       + " With --dataset: rebuild every shard."),
    dataset: Optional[int] = number_option(None, "--dataset", lo=1, hi=10_000_000, integer=True, help="Dataset mode: write N labelled 256-frame windows "
                                          "(shards of .npz + dataset.json) to the -o folder instead of one video."),
    task: str = typer.Option("count", "--task", help="Dataset labels: count (0/1/2 people, every activity, mixed pairs) or "
                             "activity (none/walking/crouching/waving/jumping)."),
    jobs: int = number_option(0, "--jobs", "-j", lo=0, hi=MAX_THREADS, integer=True,
                              help="Dataset worker processes (0 = one per core, or 1 with --world pt, whose "
                              "renderer uses every core itself; at most 4 per core)."),
    windows_per_scene: int = number_option(4, "--windows-per-scene", lo=1, hi=16, integer=True, help="Overlapping windows cut from each rendered clip."),
    shard_scenes: int = number_option(32, "--shard-scenes", lo=1, hi=100_000, integer=True, help="Scenes per shard file."),
    placement: str = typer.Option("visible", "--placement", help="Dataset mode: where people go. visible: 0.8-4 m from the "
                                  "wall, walkers within 1.5 m of the observed patch (their signal stands above the noise); "
                                  "anywhere: 1-5 m, roaming 2.5 m, like single videos; wide: 1-5 m, roaming 2 m; transfer: as wide, but "
                                  "people moving in place 1-3 m from the wall, where real footage shows them."),
) -> None:
    """Render synthetic blank-wall videos with known ground truth, or datasets for training.

    A box room with random lamps, windows and textured surfaces; 0-2 people built of spheres
    walking, crouching, waving or jumping 1-5 m from the wall; the wall's irradiance is
    integrated exactly for every body sphere ((r/D)^2 cos(beta) form factors, soft lamp
    shadows), then a camera adds exposure, tone curve, shot/read noise, PRNU, 8-bit rounding,
    compression and optional drift, flicker, auto-exposure steps and shake.

    \b
    Examples:
      wallcli simulate -o walk.mp4 --people 1 --activity walking --seed 3
      wallcli simulate -o empty.mp4 --people 0 --preview empty.png
      wallcli simulate -o two.mkv --people 2 --activity walking,jumping
      wallcli simulate --dataset 20000 --task count -o data/count --jobs 2
      wallcli simulate --dataset 2000 --task activity --domain shifted -o val
    """
    from wallcli.errors import UsageError

    if world not in ("room", "flatland", "mixed", "pt"):
        raise UsageError(f"--world must be room, flatland, pt or mixed (got {world!r})")
    if domain not in ("base", "shifted", "wide", "steady", "bracket"):
        raise UsageError(f"--domain must be base, shifted, wide, steady or bracket (got {domain!r})")
    grid_rc = _size(grid, "--grid", 512) if grid else ((24, 32) if dataset is not None else (64, 64))
    # checked in both modes, so that a mistyped value is never silently ignored
    if task not in ("count", "activity"):
        raise UsageError(f"--task must be count or activity (got {task!r})")
    if placement not in ("visible", "anywhere", "wide", "transfer"):
        raise UsageError(f"--placement must be visible, anywhere, wide or transfer (got {placement!r})")
    if dataset is not None:
        if world == "flatland" and task != "count":
            raise UsageError("flatland has no activities: use --world flatland only with --task count")
        if crf is not None:  # each scene's camera draws its own codec and quality from --domain
            raise UsageError("--crf applies to one video; a --dataset's scenes draw their compression from --domain")
        if dup_frames or tnr or awb_drift or overlay or interlace:
            raise UsageError("--dup-frames, --tnr, --awb-drift, --overlay and --interlace apply to one video, not to a --dataset")
        return _dataset(output, dataset, task, seed, jobs, domain, world, windows_per_scene, shard_scenes, grid_rc, force,
                        json_out, placement, spp, draws)
    if world == "mixed":
        raise UsageError("--world mixed is for --dataset; a single video is room, flatland or pt")
    acts = [a.strip() for a in activity.split(",") if a.strip()]
    for a in acts:
        if a not in ACTS + ("random",):
            raise UsageError(f"unknown activity {a!r}; choose from {', '.join(ACTS)} or random")
    suffix = output.suffix.lower()
    if suffix not in (".mp4", ".mkv", ".y4m", ".mov"):
        raise UsageError(f"-o must end in .mp4, .mkv or .y4m (got {output})")
    if crf is not None and suffix not in (".mp4", ".mov"):
        # the file would be lossless while the sidecar said crf: what was asked for is not what is written
        raise UsageError(f"--crf sets H.264 compression (.mp4, .mov); {suffix} is written "
                         f"{'losslessly (FFV1)' if suffix == '.mkv' else 'raw'}, without it",
                         hint="drop --crf, or write .mp4")
    crf = 18 if crf is None else crf
    w, h = _size(size, "--size", 8192)
    if suffix in (".mp4", ".mov") and (w % 2 or h % 2):
        raise UsageError(f"H.264 needs an even frame size (got {w}x{h})")
    if w < 16 or h < 16:
        raise UsageError("--size must be at least 16x16")
    dist, spd = _pair(distance, "--distance", 50), _pair(speed, "--speed", 10)
    if dist[0] < 0.3:
        raise UsageError("--distance MIN must be at least 0.3 m (bodies must stay in front of the wall)")
    if mains is not None and mains not in (50.0, 60.0):
        raise UsageError("--mains must be 50 or 60")
    if interlace is not None and interlace not in ("tff", "bff"):
        raise UsageError(f"--interlace must be tff or bff (got {interlace!r})")
    if camera_name is not None and not overlay:
        raise UsageError("--camera-name is text of the --overlay; give --overlay too")
    if clock_start is not None:
        if not overlay:
            raise UsageError("--clock-start is the --overlay's clock; give --overlay too")
        parts = clock_start.split(":")
        if len(parts) != 3 or not all(p.isdigit() for p in parts) or not (
                int(parts[0]) < 24 and int(parts[1]) < 60 and int(parts[2]) < 60):
            raise UsageError(f"--clock-start must be HH:MM:SS (got {clock_start!r})")
    _video(**locals())


def _video(output, people, activity, seed, duration, fps, w, h, grid_rc, crf, world, domain, dist, spd, level, iso_gain,
           read_noise, sensor_pixels, prnu, gamma, noise_scale, drift, flicker, mains, ae_steps, shake, nuisances,
           preview, json_out, force, acts, suffix, spp, rolling_shutter=None, dup_frames=None, tnr=None, awb_drift=None,
           overlay=False, camera_name=None, interlace=None, clock_start=None, **_):
    import json

    import numpy as np

    from wallcli.cli.output import progress
    from wallcli.io.writer import VideoWriter, atomic_paths, check_outputs, committed_together
    from wallcli.sim.camera import video_pix_fmt

    sidecar = output.with_suffix(".json")
    check_outputs([output, sidecar, preview], force=force)
    overrides = {k: v for k, v in dict(level=level, gain=iso_gain, read_noise=read_noise, prnu=prnu, gamma=gamma, drift=drift,
                                         flicker=flicker, mains=mains, ae_steps=ae_steps, shake=shake,
                                         rolling_shutter=rolling_shutter, tnr=tnr, awb_drift=awb_drift).items()
                 if v is not None}
    overrides["sensor_pixels"] = float(sensor_pixels) if sensor_pixels else float(w * h)
    codec = "ffv1" if suffix == ".mkv" else ("rawvideo" if suffix == ".y4m" else "libx264")
    if world == "flatland":
        from dataclasses import replace

        from wallcli.sim.world_flat import sample_flat_scene

        scene = sample_flat_scene(seed, None, int(people), duration=duration, domain=domain, fps=fps * (2 if interlace else 1),
                                  nuisance_p=nuisances)
        scene.camera = replace(scene.camera, width=w, height=h, codec=codec, crf=crf, noise_scale=noise_scale, **overrides)
    else:
        from wallcli.sim.scene import SceneConfig, sample_scene

        # interlaced: rendered at the field rate, two instants woven into each frame (sim/overlay.py)
        cfg = SceneConfig(people=people, activities=None if acts == ["random"] else acts, duration=duration,
                          fps=fps * (2 if interlace else 1),
                          width=w, height=h, grid=grid_rc, domain=domain, distance=dist, speed=spd, codec=codec, crf=crf,
                          noise_scale=noise_scale, nuisance_p=nuisances, camera_overrides=overrides,
                          world="pt" if world == "pt" else "room", spp=spp)
        if world == "pt":
            from wallcli.sim.pathtrace import require

            require()  # a missing extra is one clear error before any output is opened
        scene = sample_scene(seed, cfg)
    n = len(scene.times) // (2 if interlace else 1)
    from wallcli.sim.dvr import dup_mask, pad_frames
    from wallcli.sim.overlay import EPOCH, interlaced, stamp_rgb

    hh, mm, ss = (int(p) for p in (clock_start or "16:00:00").split(":"))
    start = EPOCH - EPOCH % 86400 + 3600 * hh + 60 * mm + ss  # the clock's reading at the clip's start

    # its own stream of the seed: the same seed with and without --dup-frames renders the same frames
    copies = dup_mask(n, float(dup_frames or 0.0), np.random.default_rng([seed, 0xD0B]))
    pix_fmt = video_pix_fmt(scene.camera) if suffix != ".y4m" else None
    # video and ground truth appear together or not at all (the sidecar is renamed first, so a
    # video that is there always has its truth beside it)
    # (and the preview and the JSON with them: committed_together)
    with committed_together(), atomic_paths([sidecar, output], force=force) as (tmp_truth, tmp_video):
        with VideoWriter(tmp_video, fps, w, h, codec=None if codec == "rawvideo" else codec, crf=crf,
                         pix_fmt=pix_fmt, repeatable=True) as vw:
            with progress("simulate", n) as advance:
                frames = interlaced(scene.frames(), interlace) if interlace else scene.frames()
                for i, frame in enumerate(pad_frames(frames, copies)):
                    vw.write(stamp_rgb(frame, i / fps, name=camera_name, start=start) if overlay else frame)
                    advance(1)
        truth = scene.truth()
        truth.update(video=output.name, codec=codec, crf=crf if codec == "libx264" else None)
        if dup_frames:
            truth.update(dup_frames=float(dup_frames), duplicated=int(copies.sum()))
        if overlay:
            truth.update(overlay="clock", camera_name=camera_name, clock_start=f"{hh:02d}:{mm:02d}:{ss:02d}")
        if interlace:  # the truth's per-frame positions are the top fields' (even-numbered renders)
            for person in truth.get("persons", []):
                person["positions"] = person["positions"][0::2][:n]
            truth.update(fps=fps, frames=n, interlace=interlace, field_rate=2 * fps)
        tmp_truth.write_text(json.dumps(truth, indent=None, separators=(",", ":")), encoding="utf-8")
        _finish(output, tmp_video, sidecar, truth, preview, json_out, force)
    from wallcli.cli.output import wrote
    from wallcli.wording import label_text

    who = label_text(truth["people"]) + (f", {truth['activity']}" if truth["people"] else "")
    wrote((output, f"{n} frames at {fps:g} fps, {w}x{h} pixels, {who}, seed {seed}"), (sidecar, "its ground truth"),
          (preview, "the room from above beside the space-time plots"))


def _finish(output, tmp_video, sidecar, truth, preview, json_out, force) -> None:
    from wallcli.cli.output import emit_json

    if preview is not None:
        from wallcli.io.video import open_video
        from wallcli.plots.scene import save_preview
        from wallcli.signal.stplot import compute_stplot

        with open_video(tmp_video) as reader:  # the video is placed with the preview, not before
            plot = compute_stplot(reader)
        save_preview(preview, truth, plot, force=force)
    if json_out:
        emit_json({k: v for k, v in truth.items() if k != "persons"} | {
            "output": str(output), "sidecar": str(sidecar),
            "persons": [{k: v for k, v in p.items() if k != "positions"} for p in truth.get("persons", [])]})


def _say_uncached(n, task, seed, domain, placement, grid_rc, spp, wps, draws) -> None:
    """Warn before a path-traced data set renders clean scenes here: a cache filled elsewhere (a
    lent GPU) is only used by the same recipe, and a grid or sample count that differs from it
    silently means hours of path tracing on the CPU."""
    from wallcli.cli.output import console_err, warn
    from wallcli.datagen import ptcache

    rec = ptcache.recipe(seed=seed, task=task, domain=domain, placement=placement, grid=grid_rc, spp=spp)
    needed = -(-(-(-n // wps)) // draws)
    folder = ptcache.folder(rec)
    missing = sum(1 for i in range(needed) if not ptcache.scene_file(rec, i).is_file())
    if missing:
        others = sorted(p.name for p in folder.parent.glob(f"{task}-{domain}-{placement}-s{seed}-*")) if folder.parent.is_dir() else []
        warn(f"{missing} of the {needed} clean path-traced scenes are not in the cache "
                          f"({folder}): they are rendered here first, at {spp} spp on a {grid_rc[0]}x{grid_rc[1]} grid"
                          + (f"; the cache holds this seed under other recipes ({', '.join(others)}: another --grid "
                             "or --spp?)" if others else ""))
    else:
        console_err.print(f"all {needed} clean path-traced scenes are cached ({folder})")


def _dataset(output, n, task, seed, jobs, domain, world, wps, shard_scenes, grid_rc, force, json_out, placement, spp=256,
             draws=1) -> None:
    import os
    import time

    from wallcli.cli.output import console_err, emit_json, progress
    from wallcli.datagen.dataset import build_dataset
    from wallcli.errors import WallcliError

    if output.exists() and not output.is_dir():
        raise WallcliError(f"dataset output must be a folder: {output} is a file")
    if not output.parent.is_dir() and str(output.parent):
        raise WallcliError(f"output folder does not exist: {output.parent}")
    if world == "pt":
        from wallcli.sim.pathtrace import require

        require()  # checked here, once, not in every worker
        jobs = jobs or 1  # Mitsuba already renders each frame on every core (or on the GPU)
        _say_uncached(n, task, seed, domain, placement, grid_rc, spp, wps, draws)
    jobs = jobs or os.cpu_count() or 1
    t0 = time.perf_counter()
    with progress(f"dataset ({task})", n) as advance:
        manifest = build_dataset(output, n, task, seed=seed, jobs=jobs, domain=domain, world=world,
                                 windows_per_scene=wps, shard_scenes=shard_scenes, grid=grid_rc, force=force, placement=placement,
                                 spp=spp, draws=draws,
                                 advance=advance, log=lambda m: console_err.print(m))
    dt = time.perf_counter() - t0
    console_err.print(f"wrote {n} windows in {len(manifest['shards'])} shard(s) to {output} in {dt:.1f} s")
    if json_out:
        emit_json({"output": str(output), "task": task, "windows": n, "shards": len(manifest["shards"]),
                   "seconds": round(dt, 2), "windows_per_second": round(n / dt, 3), "seed": seed, "domain": domain,
                   "world": world})
