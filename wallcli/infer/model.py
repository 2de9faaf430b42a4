"""A classifier model: an .onnx file, its card, and a lazily created onnxruntime session.

The file's bytes are read once, hashed and compared with the card's sha256 before any
session exists, and the session is built from those same bytes, so the model that runs is
the model that was checked (no window between the check and the load).
"""
from __future__ import annotations

from importlib import resources
from pathlib import Path
from typing import Any

import numpy as np

from wallcli.errors import WallcliError
from wallcli.infer.card import OUTPUT_NAME, read_card, sha256_bytes

SHIPPED = {"count": "count.onnx", "activity": "activity.onnx"}


def shipped_model_path(task: str) -> Path:
    """The model shipped with wallcli: package data ``wallcli.models`` (the repository's
    top-level ``models/`` folder, mapped to that package by pyproject.toml)."""
    name = SHIPPED[task]
    try:
        res = resources.files("wallcli.models") / name
        if res.is_file():
            return Path(str(res))
    except (ModuleNotFoundError, FileNotFoundError, NotADirectoryError, TypeError):
        pass
    # a source checkout run without installing (PYTHONPATH=.): the folder itself
    return Path(__file__).resolve().parents[2] / "models" / name


class Model:
    def __init__(self, path: Path, card: dict[str, Any], data: bytes, threads: int = 0) -> None:
        self.path = Path(path)
        self.card = card
        self._data = data
        self.threads = threads
        self._session = None
        from wallcli.infer.trust import problem

        # why the card's thresholds and figures may not be relied upon (None: sealed as measured)
        self.unvalidated = problem(card)

    @classmethod
    def load(cls, path: Path | str, *, task: str | None = None, threads: int = 0) -> "Model":
        path = Path(path)
        if not path.is_file():
            raise WallcliError(f"model not found: {path}")
        card = read_card(path)
        if task is not None and card["task"] != task:
            raise WallcliError(f"{path} is a {card['task']!r} model, but this command needs a {task!r} model")
        data = path.read_bytes()
        digest = sha256_bytes(data)
        if digest != card["sha256"].lower():
            raise WallcliError(
                f"model {path} does not match its card (sha256 {digest[:12]}…, card says {card['sha256'][:12]}…)",
                hint="the model file was modified or the card belongs to another model; re-export or re-install it")
        return cls(path, card, data, threads)

    # -- card shortcuts ---------------------------------------------------------------
    @property
    def task(self) -> str:
        return self.card["task"]

    @property
    def classes(self) -> list[Any]:
        return list(self.card["classes"])

    @property
    def input_names(self) -> list[str]:
        return [i["name"] for i in self.card["inputs"]]

    @property
    def window(self) -> int:
        return int(self.card["window"])

    @property
    def bins(self) -> int:
        return int(self.card["bins"])

    @property
    def fps(self) -> float:
        return float(self.card["fps"])

    def normalize(self, windows: np.ndarray, offset: np.ndarray | None = None) -> np.ndarray:
        """Raw plot windows (..., bins, window, 3) -> this model's input, as its card says.
        ``offset`` (..., bins, 3): the level subtracted from the windows (normalize_window)."""
        from wallcli.signal.window import normalize_window

        return normalize_window(windows, self.card["preprocessing"], offset)

    def info(self) -> dict[str, str]:
        return {"name": self.card["name"], "version": self.card["version"], "sha256": self.card["sha256"]}

    # -- the classifier interface the stages read (infer/windows, judge, result; shared with infer/twostage.TwoStageCount)
    single = True  # one net: its raw output is its answer

    def classify(self, wins: dict[str, np.ndarray], offsets: dict[str, np.ndarray]) -> np.ndarray:
        """Class probabilities (n, classes) of raw plot windows {name: (n, bins, window, 3)}, each
        normalised as this model's card says against its level ``offsets[name]`` (..., bins, 3)."""
        return self.predict({n: self.normalize(wins[n], offsets[n]) for n in self.input_names})

    def combine(self, raw: np.ndarray) -> np.ndarray:
        return np.atleast_2d(raw)

    def stages(self, raw: np.ndarray) -> None:
        return None

    def no_block_reason(self) -> None:
        return None

    # -- session ----------------------------------------------------------------------
    @property
    def session(self):
        if self._session is None:
            import onnxruntime as ort

            opts = ort.SessionOptions()
            # a window comes every second or two, between frames the decoder and the checks need
            # both cores: onnxruntime's pool must not spin waiting for the next one
            opts.add_session_config_entry("session.intra_op.allow_spinning", "0")
            if self.threads > 0:
                opts.intra_op_num_threads = self.threads
                opts.inter_op_num_threads = 1
            try:
                sess = ort.InferenceSession(self._data, sess_options=opts, providers=["CPUExecutionProvider"])
            except Exception as e:  # onnxruntime raises its own untyped errors for bad files
                raise WallcliError(f"cannot load model {self.path}: {str(e).splitlines()[0]}") from None
            self._check_session(sess)
            self._session = sess
        return self._session

    def _check_session(self, sess) -> None:
        """The card must describe the graph: same input names, ranks and fixed sizes."""
        got = {i.name: i.shape for i in sess.get_inputs()}
        if sorted(got) != sorted(self.input_names):
            raise WallcliError(f"model {self.path} has inputs {sorted(got)}, its card lists {self.input_names}",
                               hint="wrong card for this model")
        for spec in self.card["inputs"]:
            shape = got[spec["name"]]
            want = spec["shape"]
            if len(shape) != len(want) or any(
                    isinstance(s, int) and w is not None and s != w for s, w in zip(shape, want)):
                raise WallcliError(f"model {self.path} input {spec['name']!r} has shape {shape}, card says {want}",
                                   hint="wrong card for this model")
        out = sess.get_outputs()[0]
        if out.name != OUTPUT_NAME:
            raise WallcliError(f"model {self.path} output is {out.name!r}, expected {OUTPUT_NAME!r}")
        k = out.shape[-1] if out.shape else None
        if isinstance(k, int) and k != len(self.classes):
            raise WallcliError(f"model {self.path} outputs {k} classes, its card lists {len(self.classes)}",
                               hint="wrong card for this model")

    def predict(self, inputs: dict[str, np.ndarray], batch: int = 32) -> np.ndarray:
        """Class probabilities (N, classes), float64, for normalised windows (N, 3, bins, window)."""
        n = None
        for spec in self.card["inputs"]:
            name = spec["name"]
            if name not in inputs:
                raise WallcliError(f"model {self.path} needs input {name!r}")
            x = inputs[name]
            want = (3, self.bins, self.window)
            if x.ndim != 4 or tuple(x.shape[1:]) != want:
                raise WallcliError(
                    f"input {name!r} has shape {tuple(x.shape)}, the model expects (N, {', '.join(map(str, want))})"
                    " (batch, colour, space bins, time frames)",
                    hint=f"space-time plots must have {self.bins} bins; windows are {self.window} frames")
            if n is None:
                n = x.shape[0]
            elif x.shape[0] != n:
                raise WallcliError("inputs have different numbers of windows")
        sess = self.session
        out = []
        for i in range(0, n or 0, batch):
            feed = {k: np.ascontiguousarray(inputs[k][i:i + batch], dtype=np.float32) for k in self.input_names}
            out.append(sess.run([OUTPUT_NAME], feed)[0].astype(np.float64))
        if not out:
            return np.zeros((0, len(self.classes)))
        return np.concatenate(out)


def load_model(task: str, path: Path | str | None = None, *, threads: int = 0) -> Model:
    """The user's model (``--model PATH``) or the shipped one for ``task``."""
    if path is None:
        p = shipped_model_path(task)
        if not p.is_file():
            raise WallcliError(f"the shipped {task} model is missing ({p})",
                               hint="reinstall wallcli, or pass --model PATH to use your own")
        return Model.load(p, task=task, threads=threads)
    return Model.load(path, task=task, threads=threads)
