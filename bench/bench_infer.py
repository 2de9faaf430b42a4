"""Inference speed of count/activity: ms per window, --follow latency, pipeline frames/s.

    .venv/bin/python bench/bench_infer.py [--model-dir DIR] [--threads 1] [--follow] [--clip clip.mp4]

- ms per window: ``Model.predict`` on normalised windows, batch 1 (the --follow case) and
  batch 32 (whole clips), after warm-up; plus ``normalize_window`` alone.
- --follow: runs ``wallcli count - --follow`` as a subprocess and feeds it a Y4M stream at real
  time (30 fps) through a pipe; latency = time the JSON line is read minus the time the
  window's last frame was written.  Includes pipe, decoding, plot rows, resampling and the net.
- --clip: decode-only frames/s with PyAV vs ``wallcli count CLIP --json`` frames/s (target >= 0.6x).
- --int8: also times an int8 copy of each float32 model (``wallcli train --quantize int8``'s
  quantisation, calibrated here on random windows: a speed figure only, not an accuracy one).

Without --model-dir the shipped models are used; when those are missing and torch is
installed, randomly initialised nets are exported to a temporary folder (speed does not
depend on the weights).
"""
from __future__ import annotations

import argparse
import json
import os
import subprocess
import sys
import tempfile
import threading
import time
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]


def model_paths(model_dir: str | None) -> dict[str, Path]:
    from wallcli.infer.model import shipped_model_path

    if model_dir:
        return {t: Path(model_dir) / f"{t}.onnx" for t in ("count", "activity")}
    paths = {t: shipped_model_path(t) for t in ("count", "activity")}
    if all(p.is_file() for p in paths.values()):
        return paths
    import torch

    from wallcli.train.export import export_model
    from wallcli.train.nets import build

    tmp = Path(tempfile.mkdtemp(prefix="wallcli-bench-"))
    print(f"(shipped models missing: timing randomly initialised nets exported to {tmp})")
    for task in paths:
        torch.manual_seed(0)
        net = build(task).eval()
        export_model(net, list(net.input_names), tmp / f"{task}.onnx", dict(
            name=f"bench-{task}", version="0", task=task, classes=net.classes, training_data={},
            training={}, validation=None))
        paths[task] = tmp / f"{task}.onnx"
    return paths


def int8_copies(paths: dict[str, Path]) -> dict[str, Path]:
    """Quantised copies of the float32 models in a temporary folder (skips models already int8)."""
    from wallcli.infer.card import read_card
    from wallcli.train.quantize import quantize_int8

    tmp = Path(tempfile.mkdtemp(prefix="wallcli-int8-"))
    rng = np.random.default_rng(1)
    out = {}
    for task, path in paths.items():
        card = read_card(path)
        if card.get("onnx", {}).get("precision") == "int8":
            continue
        calib = {i["name"]: rng.standard_normal((32, 3, 64, 256)).astype(np.float32) for i in card["inputs"]}
        quantize_int8(path, tmp / f"{task}.onnx", calib)
        out[f"{task} int8"] = tmp / f"{task}.onnx"
    return out


def bench_windows(paths: dict[str, Path], threads: int, repeat: int) -> None:
    from wallcli.infer.model import Model
    from wallcli.signal.window import normalize_window

    rng = np.random.default_rng(0)
    raw = rng.normal(size=(32, 64, 256, 3)).astype(np.float32)
    from wallcli.signal.window import NORMALIZATION_TEXT

    for prep in NORMALIZATION_TEXT:
        t0 = time.perf_counter()
        for _ in range(repeat):
            normalize_window(raw, prep)
        print(f"normalize_window {prep.split()[-1]}: {(time.perf_counter() - t0) / repeat / 32 * 1000:.3f} ms per window")
    for task, path in paths.items():
        if task.endswith(" int8"):  # a bare session: the copy has no card of its own
            import onnxruntime as ort

            opts = ort.SessionOptions()
            if threads > 0:
                opts.intra_op_num_threads = threads
            sess = ort.InferenceSession(str(path), opts, providers=["CPUExecutionProvider"])
            names = [i.name for i in sess.get_inputs()]
            for batch in (1, 32):
                feed = {n: normalize_window(raw[:batch]) for n in names}
                sess.run(None, feed)
                n = max(repeat * (32 // batch) // 4, 5)
                t0 = time.perf_counter()
                for _ in range(n):
                    sess.run(None, feed)
                dt = (time.perf_counter() - t0) / n / batch * 1000
                print(f"{task:13s} threads={threads} batch={batch:2d}: {dt:.2f} ms per window")
            continue
        m = Model.load(path, task=task, threads=threads)
        for batch in (1, 32):
            x = normalize_window(raw[:batch])
            feed = {n: x for n in m.input_names}
            m.predict(feed)  # warm-up (session creation, allocations)
            t0 = time.perf_counter()
            n = max(repeat * (32 // batch) // 4, 5)
            for _ in range(n):
                m.predict(feed, batch=batch)
            dt = (time.perf_counter() - t0) / n / batch * 1000
            print(f"{task:8s} threads={threads} batch={batch:2d}: {dt:.2f} ms per window")


def _y4m_frames(n: int, w: int = 320, h: int = 180) -> tuple[bytes, list[bytes]]:
    header = f"YUV4MPEG2 W{w} H{h} F30:1 Ip A1:1 C444\n".encode()
    rng = np.random.default_rng(0)
    frames = []
    for i in range(n):
        y = np.full((h, w), 120, np.uint8) + rng.integers(0, 3, (h, w), dtype=np.uint8)
        uv = np.full((2, h, w), 128, np.uint8)
        frames.append(b"FRAME\n" + y.tobytes() + uv.tobytes())
    return header, frames


def bench_follow(paths: dict[str, Path], threads: int, seconds: float) -> None:
    n = int(seconds * 30)
    header, frames = _y4m_frames(n)
    env = dict(os.environ, PYTHONPATH=str(ROOT))
    cmd = [sys.executable, "-m", "wallcli", "count", "-", "--follow", "--model", str(paths["count"]),
           "--threads", str(threads)]
    p = subprocess.Popen(cmd, stdin=subprocess.PIPE, stdout=subprocess.PIPE, stderr=subprocess.PIPE, env=env)
    written: dict[int, float] = {}

    def feed() -> None:
        p.stdin.write(header)
        start = time.perf_counter()
        for i, f in enumerate(frames):
            delay = start + i / 30 - time.perf_counter()
            if delay > 0:
                time.sleep(delay)
            p.stdin.write(f)
            p.stdin.flush()
            written[i] = time.perf_counter()
        p.stdin.close()

    th = threading.Thread(target=feed, daemon=True)
    th.start()
    lat = []
    for line in p.stdout:
        now = time.perf_counter()
        rec = json.loads(line)
        last = round(rec["start"] * 30) + 255  # index of the window's last frame (30 fps input)
        if last in written:
            lat.append((now - written[last]) * 1000)
    th.join()
    p.wait()
    if p.returncode:
        print(p.stderr.read().decode())
        raise SystemExit("follow run failed")
    lat_a = np.array(lat)
    print(f"--follow latency over {len(lat)} windows (last frame written -> JSON line read): "
          f"median {np.median(lat_a):.1f} ms, max {lat_a.max():.1f} ms")


def bench_clip(clip: str, paths: dict[str, Path], threads: int) -> None:
    import av

    t0 = time.perf_counter()
    with av.open(clip) as c:
        s = c.streams.video[0]
        s.thread_type = "AUTO"
        frames = sum(1 for _ in c.decode(s))
    dec = frames / (time.perf_counter() - t0)
    env = dict(os.environ, PYTHONPATH=str(ROOT))
    t0 = time.perf_counter()
    subprocess.run([sys.executable, "-m", "wallcli", "count", clip, "--json", "--model", str(paths["count"]),
                    "--threads", str(threads)], check=True, env=env, stdout=subprocess.DEVNULL)
    full = frames / (time.perf_counter() - t0)
    print(f"{clip}: {frames} frames; PyAV decode only {dec:.1f} frames/s; wallcli count {full:.1f} frames/s "
          f"({full / dec:.2f}x, target >= 0.6x)")


def main() -> None:
    ap = argparse.ArgumentParser()
    ap.add_argument("--model-dir")
    ap.add_argument("--threads", type=int, default=1)
    ap.add_argument("--repeat", type=int, default=20)
    ap.add_argument("--follow", action="store_true")
    ap.add_argument("--follow-seconds", type=float, default=20.0)
    ap.add_argument("--clip")
    ap.add_argument("--int8", action="store_true", help="also time int8 copies of float32 models")
    a = ap.parse_args()
    paths = model_paths(a.model_dir)
    bench_windows({**paths, **(int8_copies(paths) if a.int8 else {})}, a.threads, a.repeat)
    if a.follow:
        bench_follow(paths, a.threads, a.follow_seconds)
    if a.clip:
        bench_clip(a.clip, paths, a.threads)


if __name__ == "__main__":
    main()
