"""Tiny shard datasets in the simulator's format, with a pattern a net can learn fast."""
from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest

torch = pytest.importorskip("torch")

from wallcli.io.arrays import save_npz  # noqa: E402
from wallcli.infer.card import TASK_CLASSES  # noqa: E402


def _windows(labels: np.ndarray, rng: np.random.Generator, bins: int = 64, t: int = 256) -> np.ndarray:
    """Class k = k bright streaks slanting across the plot, in noise (count-like)."""
    x = rng.normal(0.0, 0.05, size=(len(labels), bins, t, 3)).astype(np.float32)
    tt = np.arange(t)
    for i, k in enumerate(labels):
        for j in range(int(k)):
            speed = rng.uniform(0.1, 0.3) * rng.choice([-1, 1])
            pos = (rng.uniform(0, bins) + speed * tt) % bins
            for c in range(3):
                x[i, :, :, c] += 1.0 * np.exp(-0.5 * ((np.arange(bins)[:, None] - pos[None]) / 2.0) ** 2)
    return x


def write_dataset(root: Path, task: str, n: int, *, seed: int = 0, shards: int = 2, visibility: bool = False) -> Path:
    """n windows; with ``visibility``, as the simulator writes them: two windows per scene, each
    with its movers' SNR (NaN where nobody moves)."""
    root.mkdir(parents=True, exist_ok=True)
    rng = np.random.default_rng(seed)
    classes = TASK_CLASSES[task]
    labels = np.arange(n) % min(len(classes), 3)  # the learnable pattern covers up to 3 classes
    rng.shuffle(labels)
    entries = []
    for s, part in enumerate(np.array_split(np.arange(n), shards)):
        lab = labels[part]
        arrays = {"horizontal": _windows(lab, rng), "vertical": _windows(lab, rng), "label": lab.astype(np.int64),
                  "people": np.minimum(lab, 2).astype(np.int64), "activity": lab.astype(np.int64)}
        scenes = [{"k": int(k)} for k in lab]
        if visibility:
            snr = np.where(lab > 0, rng.uniform(-25.0, 15.0, len(lab)), np.nan).astype(np.float32)
            arrays.update(snr_db=snr, snr_db_weakest=snr)
            scenes = [dict(sc, seed=seed, index=int(i) // 2) for sc, i in zip(scenes, part)]
        name = f"shard-{s:05d}.npz"
        save_npz(root / name, arrays, {"format": "wallcli.dataset-shard", "task": task, "seed": seed, "scenes": scenes})
        entries.append({"file": name, "n": int(len(lab))})
    (root / "dataset.json").write_text(json.dumps({
        "format": "wallcli.dataset", "version": 1, "task": task, "classes": classes, "fps": 30, "window": 256,
        "bins": 64, "seed": seed, "recipe": {"generator": "tests/train/conftest.py streaks"}, "shards": entries}))
    return root


@pytest.fixture
def make_dataset(tmp_path):
    def make(task: str = "count", n: int = 64, *, seed: int = 0, shards: int = 2, name: str = "data",
             visibility: bool = False) -> Path:
        return write_dataset(tmp_path / name, task, n, seed=seed, shards=shards, visibility=visibility)
    return make


@pytest.fixture
def cli_code():
    """Run ``wallcli`` in-process and return its exit code only, leaving captured output to the
    test (the top-level ``run_cli`` fixture reads it away)."""
    from wallcli.cli.app import main

    def run(args):
        try:
            main([str(a) for a in args])
        except SystemExit as exc:
            return exc.code or 0
        return 0
    return run
