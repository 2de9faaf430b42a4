"""Labelled recordings as training windows: each clip cut through the path inference takes.

A folder that ``wallcli evaluate`` reads (``labels.csv`` or sidecars) becomes windows exactly as
``wallcli count`` and ``activity`` see them: the same decode, camera pipeline (repeats, overlays,
interlace), view check, light and shake corrections and resampling to the models' 30 fps; only
the stride differs (the trainer's). Each clip's windows are cached on disk, keyed by the clip's
bytes and this module's version, so a second run (another fold, another net) decodes nothing.

Folds are fixed by the file name, never drawn: the clip's number (the first run of digits in its
name) mod k, or, for a name without digits, a CRC-32 of the name mod k. Every window of a clip is
in its clip's fold, so no fold's model has seen any part of the clips it answers.
"""
from __future__ import annotations

import hashlib
import re
import zlib
from dataclasses import dataclass
from pathlib import Path
from typing import Callable

import numpy as np

from wallcli.errors import WallcliError

CACHE_VERSION = 1
HARVEST_STRIDE = 16  # samples at 30 fps between window starts; the card's stride (64) is a subset
BINS, WINDOW, FPS = 64, 256, 30.0
FOLD_RULE = ("the clip's number (the first run of digits in its file name) mod K; a name without digits: "
             "CRC-32 of the name mod K")


def fold_of(name: str, k: int) -> int:
    """The fold of a clip, from its file name alone (FOLD_RULE)."""
    stem = Path(name).name
    digits = re.findall(r"\d+", Path(stem).stem)
    if digits:
        return int(digits[0]) % k
    return zlib.crc32(stem.encode("utf-8")) % k


@dataclass
class Recording:
    """One labelled clip's windows: raw (corrected) plots and the levels they are relative to."""
    name: str
    people: int
    activity: str
    persons: int
    snr_db: float | None  # the labels' SNR (None: empty room or not given)
    detectable: bool | None
    starts: np.ndarray  # (n,) window start sample (30 fps)
    horizontal: np.ndarray  # (n, bins, window, 3) float32
    vertical: np.ndarray
    h_offset: np.ndarray  # (n, bins, 3)
    v_offset: np.ndarray
    usable: bool  # the view check's verdict on the whole clip
    frames: int  # resampled samples in the clip

    def eval_index(self, stride: int) -> np.ndarray:
        """Indices of the windows inference takes at ``stride`` (window_starts: the last aligned to the end)."""
        from wallcli.signal.window import window_starts

        want = window_starts(self.frames, WINDOW, stride)
        where = {int(s): i for i, s in enumerate(self.starts)}
        missing = [s for s in want if s not in where]
        if missing:
            raise WallcliError(f"{self.name}: windows at {missing} were not harvested (stride {stride} is not a "
                               f"multiple of {HARVEST_STRIDE})")
        return np.array([where[s] for s in want], np.int64)


class _Capture:
    """Quacks like :class:`wallcli.infer.model.Model` for :class:`WindowClassifier`: keeps each
    window as the model would receive it (corrected, before normalisation) and answers nothing."""

    single = True

    def __init__(self) -> None:
        self.card = {"task": "activity", "classes": ["none"], "inputs": [{"name": "horizontal"}, {"name": "vertical"}],
                     "window": WINDOW, "bins": BINS, "fps": FPS, "stride": HARVEST_STRIDE, "name": "capture",
                     "version": "0", "sha256": "0"}
        self.kept: list[dict[str, np.ndarray]] = []
        self.task, self.classes, self.window, self.bins, self.fps = "activity", ["none"], WINDOW, BINS, FPS
        self.input_names = ["horizontal", "vertical"]

    def classify(self, wins, offsets):
        n = wins["horizontal"].shape[0]
        for i in range(n):
            self.kept.append({"horizontal": np.array(wins["horizontal"][i], np.float32),
                              "vertical": np.array(wins["vertical"][i], np.float32),
                              "h_offset": np.broadcast_to(offsets["horizontal"], (n, BINS, 3))[i].astype(np.float32),
                              "v_offset": np.broadcast_to(offsets["vertical"], (n, BINS, 3))[i].astype(np.float32)})
        return np.ones((n, 1))

    def combine(self, raw):
        return np.atleast_2d(raw)

    def stages(self, raw):
        return None

    def no_block_reason(self):
        return None

    def info(self):
        return {"name": "capture", "version": "0", "sha256": "0"}


def _clip_key(path: Path) -> str:
    h = hashlib.sha256()
    with open(path, "rb") as fh:
        for chunk in iter(lambda: fh.read(1 << 20), b""):
            h.update(chunk)
    return f"v{CACHE_VERSION}-{h.hexdigest()[:24]}"


def harvest_clip(path: Path) -> dict[str, np.ndarray]:
    """Every window of ``path`` at HARVEST_STRIDE, as inference cuts and corrects it."""
    from wallcli.camera.corrections import Options
    from wallcli.infer.classify import classify_video

    cap = _Capture()
    result, _ = classify_video(cap, str(path), stride=HARVEST_STRIDE, corrections=Options())
    starts = np.array([int(round(w["start"] * FPS)) for w in result["windows"]], np.int64)
    if len(starts) != len(cap.kept):
        raise WallcliError(f"{path.name}: {len(cap.kept)} windows kept for {len(starts)} answered")
    frames = int(starts[-1]) + WINDOW
    out = {k: np.stack([w[k] for w in cap.kept]) for k in cap.kept[0]}
    out.update(starts=starts, frames=np.array(frames), usable=np.array(bool(result["view"]["usable"])))
    return out


def load_recordings(folders: list[Path], cache: Path, *, progress: Callable[[str], None] | None = None,
                    task: str | None = None) -> list[Recording]:
    """The windows of every labelled clip in ``folders`` (cached in ``cache``); clips with more
    than one person are kept for count and dropped for activity (one activity is not defined)."""
    from wallcli.evaluate.labels import read_labels
    from wallcli.io.arrays import load_npz, save_npz

    cache.mkdir(parents=True, exist_ok=True)
    out: list[Recording] = []
    for folder in folders:
        labels = read_labels(folder)
        for clip in labels.clips:
            if task == "activity" and clip.persons > 1:
                continue
            if not clip.path.is_file():
                raise WallcliError(f"{folder}: labelled clip {clip.file} is missing")
            f = cache / f"{_clip_key(clip.path)}.npz"
            arrays = None
            if f.is_file():
                try:
                    arrays, _ = load_npz(f, kind="wallcli.recording-windows")
                except WallcliError:
                    arrays = None  # a damaged cache entry is cut again
            if arrays is None:
                arrays = harvest_clip(clip.path)
                save_npz(f, arrays, {"format": "wallcli.recording-windows", "version": CACHE_VERSION,
                                     "clip": clip.file}, force=True)
            out.append(Recording(name=clip.file, people=clip.people, activity=clip.activity, persons=clip.persons,
                                 snr_db=clip.snr_db, detectable=clip.detectable, starts=np.asarray(arrays["starts"]),
                                 horizontal=arrays["horizontal"], vertical=arrays["vertical"],
                                 h_offset=arrays["h_offset"], v_offset=arrays["v_offset"],
                                 usable=bool(arrays["usable"]), frames=int(arrays["frames"])))
            if progress is not None:
                progress(clip.file)
    if not out:
        raise WallcliError(f"no labelled clips in {', '.join(map(str, folders))}")
    return out


def count_clips(folders: list[Path], task: str | None = None) -> int:
    from wallcli.evaluate.labels import read_labels

    return sum(1 for f in folders for c in read_labels(f).clips if not (task == "activity" and c.persons > 1))
