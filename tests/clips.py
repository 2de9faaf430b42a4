"""Test clips written with PyAV, from a function of the frame index (float RGB, 0-255)."""

from __future__ import annotations

from fractions import Fraction
from pathlib import Path
from typing import Callable

import av
import numpy as np


def write_clip(
    path: Path,
    frame_fn: Callable[[int], np.ndarray],
    n: int,
    *,
    fps: Fraction | int = 30,
    codec: str = "libx264",
    pix_fmt: str = "yuv420p",
    options: dict | None = None,
    fmt: str | None = None,
    pts_fn: Callable[[int], int] | None = None,
    time_base: Fraction | None = None,
    audio: bool = False,
) -> Path:
    """Encode ``n`` frames; ``frame_fn(i)`` gives float RGB, quantised here (as a camera would)."""
    fps = Fraction(fps)
    with av.open(str(path), "w", format=fmt) as c:
        s = c.add_stream(codec, rate=fps)
        first = np.asarray(frame_fn(0))
        s.height, s.width = first.shape[:2]
        s.pix_fmt = pix_fmt
        if options is None and codec == "libx264":
            options = {"crf": "0" if pix_fmt == "yuv444p" else "12", "preset": "ultrafast"}
        if options:
            s.options = options
        if time_base is not None:
            s.time_base = time_base
        if pix_fmt.startswith("yuv"):
            s.codec_context.colorspace = 6
            s.codec_context.color_range = 1
        a = c.add_stream("aac", rate=8000) if audio else None
        for i in range(n):
            img = first if i == 0 else np.asarray(frame_fn(i))
            if img.ndim == 2:
                frame = av.VideoFrame.from_ndarray(np.clip(np.rint(img), 0, 255).astype(np.uint8), format="gray")
            else:
                frame = av.VideoFrame.from_ndarray(np.clip(np.rint(img), 0, 255).astype(np.uint8), format="rgb24")
            if pts_fn is not None:
                frame.pts = pts_fn(i)
                frame.time_base = time_base or Fraction(1, 1) / fps  # (reading s.time_base here gives pts 0)
            for p in s.encode(frame):
                c.mux(p)
            if a is not None:
                samples = np.zeros((1, int(8000 / float(fps))), np.float32)
                af = av.AudioFrame.from_ndarray(samples, format="fltp", layout="mono")
                af.sample_rate = 8000
                for p in a.encode(af):
                    c.mux(p)
        for p in s.encode():
            c.mux(p)
        if a is not None:
            for p in a.encode():
                c.mux(p)
    return Path(path)


def write_plot(path: Path, seconds: float = 9.0, fps: float = 30.0, bins: int = 64, seed: int = 0) -> Path:
    """A space-time plot file as ``wallcli stplot -o`` writes it (noise), long enough for one window."""
    from wallcli.io.arrays import save_npz
    from wallcli.signal.stplot import FORMAT

    rng = np.random.default_rng(seed)
    t = np.arange(int(round(fps * seconds))) / fps
    h, v = (rng.normal(0, 0.05, (bins, t.size, 3)).astype(np.float32) for _ in range(2))
    save_npz(path, {"horizontal": h, "vertical": v, "time": t},
             {"format": FORMAT, "format_version": 1, "bins": bins, "fps": fps, "roi": [0, 0, 64, 48]})
    return Path(path)


MODELS = Path(__file__).resolve().parents[1] / "models"


def model_with(tmp_path: Path, **changes) -> Path:
    """A copy of the shipped count model whose card has ``changes`` (dotted keys: ``two_stage.prior_two_vs_one``)."""
    import json
    import shutil

    shutil.copy(MODELS / "count.onnx", tmp_path / "m.onnx")
    card = json.loads((MODELS / "count.json").read_text())
    for key, value in changes.items():
        target = card
        *parents, leaf = key.split(".")
        for p in parents:
            target = target[p]
        target[leaf] = value
    (tmp_path / "m.json").write_text(json.dumps(card))
    return tmp_path / "m.onnx"


def grey_wall(i: int, h: int = 24, w: int = 32) -> np.ndarray:
    """Frame ``i`` of a flat grey wall with a little noise (seeded by the frame index)."""
    return np.full((h, w, 3), 120.0) + np.random.default_rng(i).normal(0, 1.0, (h, w, 3))


def tiny_clip(path: Path) -> Path:
    """12 lossless frames of ``grey_wall``: enough for the commands that fail before they decode."""
    return write_clip(path, grey_wall, 12, fps=30, codec="ffv1", pix_fmt="bgr0", options={})


def one_error(err: str) -> str:
    """The single 'Error: ...' line a bad input must give, with no traceback."""
    lines = err.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith("Error:") and "Traceback" not in err, err
    return lines[0]


# a small simulated walker: a window fits and a decode takes a fraction of a second
SIM = ["--size", "64x48", "--duration", "10.5", "--fps", "30", "--grid", "16x16", "--crf", "12"]


def simulated_walk(path: Path) -> Path:
    """``wallcli simulate`` one walker (seed 1) to ``path``, in process."""
    import pytest

    from wallcli.cli.app import main

    with pytest.raises(SystemExit) as exit_:
        main(["simulate", "-o", str(path), "--people", "1", "--activity", "walking", "--seed", "1", *SIM])
    assert exit_.value.code == 0
    return path
