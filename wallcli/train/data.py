"""Training data: the simulator's shard datasets (``DIR/dataset.json`` + ``shard-NNNNN.npz``).

Shards can be larger than memory in total, so an epoch is planned as a list of batches of
global window indices: shards in a random order, grouped into chunks of at most
``buffer_windows`` windows, windows shuffled within a chunk.  The plan depends only on
(seed, epoch), which is what makes mid-epoch resume exact.  Shards are loaded on demand and
kept in a small cache of two chunks (a batch can straddle a chunk boundary).
"""
from __future__ import annotations

import json
from collections import OrderedDict
from pathlib import Path
from typing import Any

import numpy as np

from wallcli.sim import WIDE_DOMAINS

from wallcli.errors import WallcliError
from wallcli.infer.card import TASK_CLASSES, TASK_INPUTS

DATASET_FORMAT = "wallcli.dataset"
SHARD_FORMAT = "wallcli.dataset-shard"


OFFSETS = {"horizontal": "h_offset", "vertical": "v_offset"}


class ShardDataset:
    def __init__(self, root: Path | str | list, task: str, *, bins: int = 64, window: int = 256,
                 buffer_windows: int = 2048, inputs: list[str] | tuple[str, ...] | None = None) -> None:
        # several folders (e.g. two simulator runs with different seeds) act as one dataset
        roots = [Path(r) for r in root] if isinstance(root, (list, tuple)) else [Path(root)]
        if not roots:
            raise WallcliError("no dataset folder given")
        self.roots = roots
        self.manifests = [self._manifest(r, task, bins, window) for r in roots]
        self.manifest: dict[str, Any] = self.manifests[0]
        self.task = task
        # an activity net may learn from a count dataset of the 'wide' domain, whose scenes hold
        # movers of every activity: its windows with at most one mover, labelled by their activity
        self.relabel = [m.get("task") == "count" and task == "activity" for m in self.manifests]
        self.inputs = list(inputs) if inputs else TASK_INPUTS[task]
        self.classes = TASK_CLASSES[task]
        self.shape = (bins, window, 3)
        self.files = [r / s["file"] for r, m in zip(roots, self.manifests) for s in m["shards"]]
        self.sizes = np.array([int(s["n"]) for m in self.manifests for s in m["shards"]], dtype=np.int64)
        self.offsets = np.concatenate([[0], np.cumsum(self.sizes)])
        self.n = int(self.offsets[-1])
        if self.n == 0:
            raise WallcliError(f"{', '.join(map(str, roots))} holds no windows")
        self.buffer_windows = max(int(buffer_windows), 1)
        self._cache: OrderedDict[int, dict[str, np.ndarray]] = OrderedDict()
        self._cache_windows = 0

    @staticmethod
    def _manifest(root: Path, task: str, bins: int, window: int) -> dict[str, Any]:
        man_path = root / "dataset.json"
        if not man_path.is_file():
            raise WallcliError(f"{root} is not a wallcli dataset (no dataset.json)",
                               hint="create one with the simulator's dataset mode")
        try:
            man = json.loads(man_path.read_text(encoding="utf-8"))
        except (OSError, json.JSONDecodeError) as e:
            raise WallcliError(f"{man_path} is not valid JSON: {e}") from None
        if man.get("format") != DATASET_FORMAT or man.get("version") != 1:
            raise WallcliError(f"{man_path}: not a {DATASET_FORMAT} v1 manifest")
        if man.get("complete") is False:
            raise WallcliError(f"{root} is still being written (dataset.json says complete: false)",
                               hint="finish it by re-running the same dataset command")
        wide = (man.get("recipe") or {}).get("domain") in WIDE_DOMAINS
        if man.get("task") == "count" and task == "activity" and wide:
            return man
        if man.get("task") != task:
            raise WallcliError(f"{root} is a {man.get('task')!r} dataset, training a {task!r} model needs a {task!r} one")
        if list(man.get("classes", [])) != TASK_CLASSES[task]:
            raise WallcliError(f"{man_path}: classes {man.get('classes')} differ from {TASK_CLASSES[task]}")
        if man.get("window") != window or man.get("bins") != bins:
            raise WallcliError(f"{man_path}: windows are {man.get('bins')} bins x {man.get('window')} frames, "
                               f"the nets need {bins} x {window}")
        return man

    @property
    def recipes(self) -> list:
        return [m.get("recipe") for m in self.manifests]

    # -- shards -----------------------------------------------------------------------
    def _load_shard(self, i: int) -> dict[str, np.ndarray]:
        if i in self._cache:
            self._cache.move_to_end(i)
            return self._cache[i]
        from wallcli.io.arrays import load_npz

        arrays, _ = load_npz(self.files[i], kind=SHARD_FORMAT)
        n = int(self.sizes[i])
        out = {}
        for name in (*self.inputs, "label"):
            if name not in arrays:
                raise WallcliError(f"{self.files[i]}: missing array {name!r}")
            out[name] = arrays[name]
        if self._relabelled(i):
            out["label"] = arrays["activity"]
        for name in self.inputs:
            # the level each window is relative to (normalisation v3); zeros for older shards
            key = OFFSETS[name]
            out[key] = (arrays[key].astype(np.float32) if key in arrays
                        else np.zeros((n, self.shape[0], self.shape[2]), np.float32))
        for name in self.inputs:
            if out[name].shape != (n, *self.shape):
                raise WallcliError(f"{self.files[i]}: {name!r} has shape {out[name].shape}, "
                                   f"manifest says {(n, *self.shape)}")
            out[name] = out[name].astype(np.float32, copy=False)
        lab = out["label"].astype(np.int64)
        if lab.shape != (n,) or lab.min(initial=0) < 0 or lab.max(initial=0) >= len(self.classes):
            raise WallcliError(f"{self.files[i]}: labels must be {n} integers in 0..{len(self.classes) - 1}")
        out["label"] = lab
        self._cache[i] = out
        self._cache_windows += n
        # keep about two chunks: evict least recently used shards beyond that
        while self._cache_windows > 2 * self.buffer_windows and len(self._cache) > 1:
            _, old = self._cache.popitem(last=False)
            self._cache_windows -= len(old["label"])
        return out

    def _relabelled(self, shard: int) -> bool:
        k = int(np.searchsorted(np.cumsum([len(m["shards"]) for m in self.manifests]), shard, side="right"))
        return self.relabel[k]

    def _per_window(self, key, shards=None) -> np.ndarray:
        """One small array per window, read from every shard (or ``shards``): ``key(i)`` names it."""
        import zipfile

        out = np.zeros(self.n, np.int64)
        for i, f in enumerate(self.files):
            if shards is not None and i not in shards:
                continue
            try:
                with np.load(f, allow_pickle=False) as npz:
                    out[self.offsets[i]:self.offsets[i + 1]] = npz[key(i)]
            except (OSError, ValueError, KeyError, zipfile.BadZipFile) as e:
                raise WallcliError(f"{f} is not a readable shard ({e})") from None
        return out

    def labels(self) -> np.ndarray:
        """Every window's label, as training sees it (relabelled where the dataset is)."""
        return self._per_window(lambda i: "activity" if self._relabelled(i) else "label")

    def usable(self, indices: np.ndarray) -> np.ndarray:
        """``indices`` without windows this task cannot use: from a relabelled count dataset,
        those with two movers (an activity net answers for one person)."""
        indices = np.asarray(indices, dtype=np.int64)
        relabelled = {i for i in range(len(self.files)) if self._relabelled(i)}
        if not relabelled:
            return indices
        movers = self._per_window(lambda i: "label", relabelled)  # zeros elsewhere: kept
        return indices[movers[indices] <= 1]

    def gather(self, idx: np.ndarray) -> dict[str, np.ndarray]:
        """Raw windows (len(idx), bins, window, 3) per input, their level offsets (OFFSETS: (len(idx),
        bins, 3)), plus 'label', in the order of idx."""
        shard = np.searchsorted(self.offsets, idx, side="right") - 1
        out = {name: np.empty((len(idx), *self.shape), np.float32) for name in self.inputs}
        for name in self.inputs:
            out[OFFSETS[name]] = np.empty((len(idx), self.shape[0], self.shape[2]), np.float32)
        out["label"] = np.empty(len(idx), np.int64)
        for s in np.unique(shard):
            sel = np.nonzero(shard == s)[0]
            local = idx[sel] - self.offsets[s]
            arrs = self._load_shard(int(s))
            for name in out:
                out[name][sel] = arrs[name][local]
        return out

    def visibility(self) -> np.ndarray:
        """Per window, the least visible mover's SNR in the recorded plot, dB (NaN: nobody moving).

        Shards from before per-person visibility hold only ``snr_db`` (all movers together).
        """
        import zipfile

        snr = np.full(self.n, np.nan, np.float32)
        for i, f in enumerate(self.files):
            try:
                with np.load(f, allow_pickle=False) as npz:
                    key = "snr_db_weakest" if "snr_db_weakest" in npz.files else "snr_db"
                    if key not in npz.files:
                        raise WallcliError(f"{f} has no per-window snr_db; regenerate it to filter by visibility")
                    snr[self.offsets[i]:self.offsets[i + 1]] = npz[key]
            except (OSError, ValueError, zipfile.BadZipFile) as e:
                raise WallcliError(f"{f} is not a readable shard ({e})") from None
        return snr

    def scene_ids(self) -> np.ndarray:
        """Per window, an integer naming the simulated scene (seed, index) it was cut from; a window
        without a scene record counts as a scene of its own."""
        import json
        import zipfile

        keys: dict = {}
        ids = np.zeros(self.n, np.int64)
        for i, f in enumerate(self.files):
            try:
                with np.load(f, allow_pickle=False) as npz:
                    scenes = json.loads(str(npz["meta"][()]))["scenes"]
            except (OSError, ValueError, KeyError, TypeError, zipfile.BadZipFile) as e:
                raise WallcliError(f"{f} has no readable scene list ({e})") from None
            if len(scenes) != self.sizes[i]:
                raise WallcliError(f"{f}: {len(scenes)} scene records for {self.sizes[i]} windows")
            ids[self.offsets[i]:self.offsets[i + 1]] = [
                keys.setdefault((s.get("seed"), s.get("index")) if "index" in s else ("window", self.offsets[i] + j), len(keys))
                for j, s in enumerate(scenes)]
        return ids

    def visible(self, indices: np.ndarray, min_snr_db: float | None) -> np.ndarray:
        """``indices`` without windows whose movers are too faint to see (snr_db < min_snr_db).

        Windows with nobody moving (snr_db NaN) always stay. A label the data cannot support
        (a waving person 5 m away, 40 dB under the noise) teaches only guessing.
        """
        indices = np.asarray(indices, dtype=np.int64)
        if min_snr_db is None:
            return indices
        s = self.visibility()[indices]
        return indices[np.isnan(s) | (s >= min_snr_db)]

    # -- epochs -----------------------------------------------------------------------
    def plan(self, indices: np.ndarray, batch_size: int, rng: np.random.Generator,
             shuffle: bool = True) -> list[np.ndarray]:
        """Batches of global indices (a subset ``indices`` of the dataset) for one epoch."""
        indices = np.sort(np.asarray(indices, dtype=np.int64))
        if not shuffle:
            return [indices[i:i + batch_size] for i in range(0, len(indices), batch_size)]
        shard = np.searchsorted(self.offsets, indices, side="right") - 1
        order = rng.permutation(len(self.files))
        chunks: list[np.ndarray] = []
        cur: list[np.ndarray] = []
        cur_n = 0
        for s in order:
            sel = indices[shard == s]
            if cur and cur_n + len(sel) > self.buffer_windows:
                chunks.append(np.concatenate(cur))
                cur, cur_n = [], 0
            cur.append(sel)
            cur_n += len(sel)
        if cur:
            chunks.append(np.concatenate(cur))
        flat = np.concatenate([rng.permutation(c) for c in chunks]) if chunks else indices
        batches = [flat[i:i + batch_size] for i in range(0, len(flat), batch_size)]
        # batch norm cannot train on a single window
        if batches and len(batches[-1]) < 2:
            batches.pop()
        return batches


def split_validation(n: int, fraction: float, seed: int) -> tuple[np.ndarray, np.ndarray]:
    """(train, validation) global indices: a seeded random ``fraction`` held out."""
    rng = np.random.default_rng([seed, 0x5A11])
    perm = rng.permutation(n)
    k = int(round(n * fraction)) if fraction > 0 else 0
    k = min(max(k, 1 if fraction > 0 and n > 1 else 0), n - 1)
    return np.sort(perm[k:]), np.sort(perm[:k])
