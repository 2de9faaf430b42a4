"""The task a worker runs: one video in, one results line out (a dict), never an exception for
a bad video.

Runs inside Dask worker processes: everything it needs travels in :class:`ScanConfig` (plain
data), the models are loaded once per process and kept, and a watchdog gives up on a video
whose decoder stops producing frames.
"""
from __future__ import annotations

import os
import threading
import time
from dataclasses import dataclass, field
from typing import Any, Callable

from wallcli.errors import WallcliError

_MODELS: dict[tuple[str, int], Any] = {}  # (task, onnxruntime threads) -> Model, per process


@dataclass(frozen=True)
class ScanConfig:
    tasks: tuple[str, ...]
    windows: bool = False  # keep each classification's "windows" list in the line
    timeout: float = 300.0  # seconds without a decoded frame before a video is given up; 0 = never
    decoder_threads: int = 1  # one core per worker: FFmpeg's own threads would only compete
    onnx_threads: int = 1
    deflicker: bool = True  # the corrections (wallcli.camera.corrections) run on every video
    exposure: bool = True
    shake: bool = True
    # what the client runs (identity()); a worker that differs answers with an error line
    expected: dict = field(default_factory=dict)

    def options(self) -> dict[str, bool]:
        """The options that change a line's answers, as the line records them (a resume compares them)."""
        return {"deflicker": self.deflicker, "exposure": self.exposure, "shake": self.shake, "windows": self.windows}


def model_files() -> dict[str, str]:
    """sha256 of each shipped model file, as installed here."""
    from wallcli.infer.card import sha256_file
    from wallcli.infer.model import SHIPPED, shipped_model_path

    out = {}
    for task in SHIPPED:
        p = shipped_model_path(task)
        out[task] = sha256_file(p) if p.is_file() else "missing"
    return out


_IDENTITY: dict = {}


def identity() -> dict:
    """What a worker must share with the client for its answers to be the client's (computed
    once per process: the installed files do not change under a running program)."""
    from wallcli import __version__

    if not _IDENTITY:
        _IDENTITY.update({"wallcli": __version__, "models": model_files()})
    return dict(_IDENTITY)


def describe(ident: dict) -> str:
    models = ", ".join(f"{t} {str(s)[:12]}" for t, s in sorted((ident.get("models") or {}).items()))
    return f"wallcli {ident.get('wallcli')} ({models})"


def _model(task: str, threads: int):
    from wallcli.infer.twostage import load_classifier

    key = (task, threads)
    if key not in _MODELS:  # count: in two stages, as `wallcli count` answers
        _MODELS[key] = load_classifier(task, threads=threads)
    return _MODELS[key]


class Stalled(Exception):
    pass


def run_with_watchdog(fn: Callable[[Callable[[], None]], Any], timeout: float) -> Any:
    """``fn(beat)`` in a thread; give up when ``beat()`` has not been called for ``timeout`` s.

    A decoder can hang inside FFmpeg (a stalled network read, a pathological file) where no
    Python code runs to notice. The thread is then left behind (a daemon, idle if truly stuck;
    one that wakes up stops at its next ``beat()``), and the worker goes on with its next video.
    """
    if not timeout or timeout <= 0:
        return fn(lambda: None)
    last = [time.monotonic()]
    abandoned = threading.Event()
    box: dict[str, Any] = {}

    def beat() -> None:
        if abandoned.is_set():
            raise Stalled
        last[0] = time.monotonic()

    def run() -> None:
        try:
            box["value"] = fn(beat)
        except BaseException as exc:  # noqa: BLE001 - handed to the waiting thread
            box["error"] = exc

    worker = threading.Thread(target=run, daemon=True, name="wallcli-scan-video")
    worker.start()
    while True:
        worker.join(timeout=min(1.0, timeout))
        if not worker.is_alive():
            break
        if time.monotonic() - last[0] > timeout:
            abandoned.set()
            raise Stalled(f"no progress for {timeout:g} s (a hanging decoder?); given up")
    if "error" in box:
        raise box["error"]
    return box.get("value")


def _hash(path: str, beat: Callable[[], None]) -> tuple[int, str]:
    import hashlib

    h = hashlib.sha256()
    size = 0
    with open(path, "rb") as fh:
        for chunk in iter(lambda: fh.read(1 << 22), b""):
            h.update(chunk)
            size += len(chunk)
            beat()
    return size, h.hexdigest()


def _one_line(message: str) -> str:
    return " ".join(str(message).split()) or "failed"


def scan_video(source: str, config: ScanConfig) -> dict[str, Any]:
    """The results line of one video (CONTRACT.md, ``wallcli scan``); errors become ``"error"``."""
    import warnings

    from wallcli.batch.analyse import CLASSIFY, analyse
    from wallcli.batch.inputs import is_url
    from wallcli.io.video import VideoWarning

    # the reader also reports trouble as Python warnings, which would print on the worker's
    # stderr, over the client's progress bar; they reach the line through the reader instead
    warnings.simplefilter("ignore", VideoWarning)
    t0 = time.perf_counter()
    line: dict[str, Any] = {"input": source, "size": None, "sha256": None, "duration": None, "frames": None,
                            "tasks": list(config.tasks), "options": config.options()}
    try:
        if config.expected and identity() != config.expected:
            raise WallcliError(f"this worker runs {describe(identity())}, the client {describe(config.expected)}")
        models = {t: _model(t, config.onnx_threads) for t in CLASSIFY if t in config.tasks}

        def job(beat):
            if not is_url(source) and os.path.isfile(source):
                line["size"], line["sha256"] = _hash(source, beat)
            from wallcli.camera.corrections import Options

            return analyse(source, config.tasks, models, decoder_threads=config.decoder_threads, on_frame=beat,
                           corrections=Options(config.deflicker, config.exposure, config.shake))

        out = run_with_watchdog(job, config.timeout)
    except (WallcliError, Stalled, OSError, MemoryError) as exc:
        return {**line, "seconds": round(time.perf_counter() - t0, 3), "error": _one_line(exc)}
    except Exception as exc:  # noqa: BLE001 - one video's surprise must not stop the other thousand
        return {**line, "seconds": round(time.perf_counter() - t0, 3),
                "error": _one_line(f"internal error: {type(exc).__name__}: {exc}")}
    line.update(duration=out["duration"], frames=out["frames"])
    for task in config.tasks:
        obj = dict(out[task])
        if task in CLASSIFY and not config.windows:
            obj.pop("windows", None)
        line[task] = obj
    line["view"] = out["view"]
    line["corrections"] = out["corrections"]
    line["warnings"] = out["warnings"]
    line["seconds"] = round(time.perf_counter() - t0, 3)
    line["error"] = None
    return line
