"""One clip, one decode: the classifier's answer and the measured SNR.

The answer is :func:`wallcli.infer.classify.classify_video` (or ``classify_plot`` for a ``.npz``),
the very function behind ``wallcli count`` and ``wallcli activity``, with the card's stride, so
evaluate's answers are the single commands' answers. The SNR comes from the same decoded frames
(a :class:`~wallcli.io.video.FrameTee` tap), with the estimator of ``wallcli snr`` (seed §4).

Which one number. ``wallcli snr`` gives the SNR per colour after averaging square blocks of 1..32
pixels. The models read space-time plots whose bins each average (ROI width / bins) x (ROI
height) pixels, so the number is the green channel's SNR at the block size whose area is nearest
(in ratio) to one bin's: 8 px for a 96x72 frame, 16 for 128x96, 32 (the largest measured) from
about 320x240 up. Green because luma is mostly green and the three channels' SNRs differ by a
fraction of a dB on wall videos; a block matched to the bins because that is the averaging the
model's input has had. On the transfer set's clips with a mover it follows the true signal as
closely as any block size does (Spearman 0.86; single pixels 0.31). ``snr_db`` = -99 means no
signal above the noise. ``wallcli snr INPUT --json`` reproduces it: ``scales[k].snr_db[1]`` where
``scales[k].block`` is the row's ``snr_block``.

Compression caveat: H.264 smooths noise over time, which this estimator (noise = half the
variance of frame differences) reads as signal, so lossy clips measure a few dB high.
"""
from __future__ import annotations

import math
import warnings
from pathlib import Path
from typing import Any

from wallcli.errors import WallcliError

GREEN = 1


def plot_block(roi, bins: int, blocks) -> int:
    """The block size among ``blocks`` whose area is nearest in ratio to one plot bin's."""
    area = max(roi[2] / bins, 1.0) * roi[3]
    return min(blocks, key=lambda n: (abs(math.log(n * n / area)), n))


def measure_clip(model, path: str | Path, *, stride: int, roi=None, threads: int = 0, corrections=None) -> dict[str, Any]:
    """{'result': the classifier's clip-level result (without its windows), 'snr_db', 'snr_block',
    'warnings'}. Raises WallcliError for a clip that cannot be analysed (missing, corrupt, too short)."""
    from wallcli.camera.corrections import Options
    from wallcli.infer.classify import classify_plot, classify_video, load_plot
    from wallcli.snr.estimate import FrameSnr

    corrections = corrections if corrections is not None else Options()

    path = Path(path)
    if not path.exists():
        raise WallcliError(f"no such file: {path.name}")
    snr_db = block = None
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        if path.suffix.lower() == ".npz":  # a space-time plot: the answer, but no pixels to measure
            result = classify_plot(model, load_plot(path, roi=roi, bins=model.bins), stride=stride, source=str(path),
                                   corrections=corrections)
        else:
            tap = FrameSnr(roi, corrections=corrections)
            result, _ = classify_video(model, str(path), stride=stride, roi=roi, threads=threads, taps=(tap,),
                                       corrections=corrections)
            res = tap.result()
            block = plot_block(res.roi, model.bins, [s.block for s in res.scales])
            snr_db = float(res.scale(block).snr_db[GREEN])
    result = dict(result)
    result["windows_n"] = len(result.pop("windows"))
    return {"result": result, "snr_db": snr_db, "snr_block": block,
            "snr_corrections": tap.acc.corrections if snr_db is not None and tap.acc is not None else None,
            "warnings": [" ".join(str(w.message).split()) for w in caught]}


# ------------------------------------------------------------------------------ worker processes
_WORKER: dict[str, Any] = {}


def init_worker(task: str, model_path: str, stride: int, roi, corrections=None, activity_path=None,
                single: bool = False) -> None:
    """Per process: the model loaded (and hash-checked) once, onnxruntime on one thread (the
    processes share out the cores). Ctrl-C is the parent's to handle: it stops the pool."""
    import os
    import signal

    os.environ.setdefault("OMP_NUM_THREADS", "1")
    signal.signal(signal.SIGINT, signal.SIG_IGN)
    from wallcli.infer.twostage import load_classifier

    model = load_classifier(task, model_path, threads=1, activity_path=activity_path, single=single)
    _WORKER.update(model=model, stride=stride, roi=roi, corrections=corrections)


def run_clip(path: str) -> dict[str, Any]:
    """:func:`measure_clip` in a worker; a failure is returned as {'error': one line}, not raised."""
    try:
        return measure_clip(_WORKER["model"], path, stride=_WORKER["stride"], roi=_WORKER["roi"], threads=1,
                            corrections=_WORKER.get("corrections"))
    except WallcliError as exc:
        return {"error": _one_line(str(exc))}
    except MemoryError:
        return {"error": "out of memory"}
    except Exception as exc:  # a decoder or library failure on one clip must not end the run
        return {"error": _one_line(f"{type(exc).__name__}: {exc}")}


def _one_line(text: str) -> str:
    return " ".join(text.split())
