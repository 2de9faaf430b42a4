"""What each correction of issue 27 (aliased mains flicker, exposure steps and drift, camera shake)
costs in throughput: each command with each correction on, against the same command with all
off, in one run.

    .venv/bin/python bench/bench_corrections.py [--frames 600] [--repeat 3]

Clips: the 1080p30 bench clip (bench/clips.py) and the same wall at 320x240. Every job runs in a
fresh process (bench/measure.py); the variants of a command alternate within each repeat and
the fastest run of each counts. Ratios are throughput (frames/s) over that of the same command
with ``--no-deflicker --no-exposure``; CPU-time ratios move least when other work loads the
machine. Whole commands are timed, start-up included.

``--micro`` times the corrections' own work in this process, which a busy machine blurs less:
per 256-sample window of the classifiers (both plots, 64 bins) against the rest of the window's
work (normalisation and the model), and per 1080p frame of the SNR estimator against its own
work per frame without them. The least CPU time of many repeats counts.
"""
from __future__ import annotations

import argparse
import os
import sys
from pathlib import Path

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE))

from bench_speed import measure  # noqa: E402
from clips import OUT, clip_1080p, make_clip  # noqa: E402

VARIANTS = {  # name: extra options (snr has no shake correction: --no-shake is dropped for it)
    "off": ("--no-deflicker", "--no-exposure", "--no-shake"),
    "deflicker": ("--no-exposure", "--no-shake"),
    "exposure": ("--no-deflicker", "--no-shake"),
    "shake": ("--no-deflicker", "--no-exposure"),
    "all (default)": (),
}


def _options(cmd: str, extra: tuple) -> tuple:
    return tuple(o for o in extra if cmd != "snr" or o != "--no-shake")


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--frames", type=int, default=600)
    ap.add_argument("--repeat", type=int, default=3, help="runs per measurement; the fastest counts")
    ap.add_argument("--commands", default="count,activity,snr")
    ap.add_argument("--micro", action="store_true", help="time the corrections' own work instead (see above)")
    args = ap.parse_args()
    if args.micro:
        return micro(clip_1080p(args.frames))
    small = OUT / f"wall320_{args.frames}.mp4"
    if not small.exists():
        make_clip(small, args.frames, 320, 240)
    clips = {"1080p": clip_1080p(args.frames), "320x240": small}
    print(f"load average at start: {os.getloadavg()[0]:.1f}")
    print("| clip | command | correction | frames/s | ratio to off (wall) | ratio to off (CPU) |")
    print("|---|---|---|---|---|---|")
    for label, clip in clips.items():
        for cmd in args.commands.split(","):
            runs: dict[str, list[dict]] = {v: [] for v in VARIANTS}
            for _ in range(args.repeat):
                for v, extra in VARIANTS.items():
                    runs[v].append(measure("wallcli", cmd, str(clip), "--json", *_options(cmd, extra)))
            best = {v: min(r, key=lambda x: x["seconds"]) for v, r in runs.items()}
            cpu = {v: min(x["cpu_seconds"] for x in r) for v, r in runs.items()}
            for v in VARIANTS:
                fps = args.frames / best[v]["seconds"]
                print(f"| {label} | {cmd} | {v} | {fps:.0f} | {best['off']['seconds'] / best[v]['seconds']:.2f} | "
                      f"{cpu['off'] / cpu[v]:.2f} |", flush=True)
    print(f"load average at end: {os.getloadavg()[0]:.1f}")


def _best(fn, repeat: int = 30) -> float:
    """The least CPU time (this process, all threads) of ``repeat`` calls: other processes on a
    busy machine lengthen wall time far more."""
    import time

    out = []
    for _ in range(repeat):
        t0 = time.process_time()
        fn()
        out.append(time.process_time() - t0)
    return min(out)


def micro(clip: Path) -> None:
    import numpy as np

    from wallcli.camera import corrections as corr
    from wallcli.infer.model import load_model
    from wallcli.infer.stream import RowStream
    from wallcli.infer.windows import predict_window
    from wallcli.io.video import open_video
    from wallcli.signal.blocks import check_roi
    from wallcli.snr.estimate import SnrAccumulator

    models = {t: load_model(t, None) for t in ("count", "activity")}
    with open_video(str(clip)) as reader:
        rows = RowStream(reader, bins=64, fps=30.0, vertical=True)
        got = [r for _, r in zip(range(256), rows)]
        ref = rows.ref
    win = np.stack([r for _, r in got], axis=1)  # (2 bins, 256, 3)
    # a 1 % flicker line, so that deflicker has its fit to do
    t = np.arange(256) / 30.0
    win = ((win + ref[:, None]) * (1 + 0.01 * np.sin(2 * np.pi * 10 * t))[None, :, None] - ref[:, None]).astype(np.float32)
    print("| CPU per window (256 samples; one every 64 frames) | off | deflicker | exposure | both | ratio, both |")
    print("|---|---|---|---|---|---|")
    for task, model in models.items():
        ms = {name: 1e3 * _best(lambda o=o: predict_window(model, win, ref, native=30.0, options=o))
              for name, o in (("off", corr.OFF), ("deflicker", corr.Options(True, False, False)),
                              ("exposure", corr.Options(False, True, False)), ("both", corr.Options(True, True, False)))}
        print(f"| {task} | {ms['off']:.1f} ms | {ms['deflicker']:.1f} ms | {ms['exposure']:.1f} ms | {ms['both']:.1f} ms "
              f"| {ms['off'] / ms['both']:.2f} |")
    n = 160
    with open_video(str(clip)) as reader:
        frames = []
        for f, _ in zip(reader.frames(), range(n)):
            p = f.planes
            frames.append(type(p)(p.y.copy(), None if p.u is None else p.u.copy(), None if p.v is None else p.v.copy(),
                                  **{k: getattr(p, k) for k in ("kind", "sub_x", "sub_y", "depth", "matrix", "full_range")}))
    roi = check_roi(None, frames[0].width, frames[0].height)

    def snr(o):
        acc = SnrAccumulator(roi, corrections=o, fps=30.0)
        for p in frames:
            acc.update(p)
        acc.result()

    # the shake's registration: every frame's shift on both axes (count reads only the horizontal
    # profile, so its luma rows are summed for it alone)
    from wallcli.signal.blocks import RgbProjector

    def project(register: bool, vertical: bool):
        proj = RgbProjector(roi, 64, vertical=vertical, register=register)
        for p in frames:
            proj(p)

    for vertical, label in ((False, "count (horizontal)"), (True, "activity (both)")):
        off = 1e3 * _best(lambda: project(False, vertical), 5) / n
        on = 1e3 * _best(lambda: project(True, vertical), 5) / n
        print(f"| profiles per 1080p frame, {label} | {off:.2f} ms | registered: {on:.2f} ms | ratio {off / on:.2f} |")
    ms = {name: 1e3 * _best(lambda o=o: snr(o), 5) / n
          for name, o in (("off", corr.OFF), ("deflicker", corr.Options(True, False, False)),
                          ("exposure", corr.Options(False, True, False)), ("both", corr.Options(True, True, False)),
                          ("shake", corr.Options(False, False, True)), ("all", corr.Options()))}
    print(f"| snr, per 1080p frame | {ms['off']:.2f} ms | {ms['deflicker']:.2f} ms | {ms['exposure']:.2f} ms | "
          f"{ms['both']:.2f} ms | {ms['off'] / ms['both']:.2f} |")
    print(f"| snr, per 1080p frame, shake alone / all | {ms['off']:.2f} ms | {ms['shake']:.2f} ms | {ms['all']:.2f} ms | "
          f"ratio all: {ms['off'] / ms['all']:.2f} |")


if __name__ == "__main__":
    main()
