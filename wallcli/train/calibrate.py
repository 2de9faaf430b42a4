"""Fit a model's decided/undetermined thresholds on simulated validation windows; write them in its card.

The exported graph itself (onnxruntime, as users run it) scores every usable window of the
validation datasets; each window's signal is measured as inference measures it
(``window_signal_db``); ``wallcli.infer.confidence.fit`` turns both into the card's
``confidence`` block. The .onnx file is untouched (the card's sha256 covers only it), and the
card is rewritten atomically.
"""
from __future__ import annotations

from pathlib import Path
from typing import Any

import numpy as np

from wallcli.infer.card import card_path, card_text, read_card
from wallcli.infer.confidence import fit
from wallcli.signal.window import window_signal_db

DEFAULT_EDGES = [0.0]  # two bands: a few hundred validation windows cannot fill more


def score_dataset(model_path: Path, data: list[Path], *, batch: int = 128) -> dict[str, np.ndarray]:
    """Probabilities, labels, measured signal and visibility of every usable window of ``data``."""
    from wallcli.infer.model import Model
    from wallcli.train.data import OFFSETS, ShardDataset

    model = Model.load(model_path)
    ds = ShardDataset([Path(d) for d in data], model.task, inputs=model.input_names)
    idx = ds.usable(np.arange(ds.n))
    probs, signal, labels = [], [], []
    for i in range(0, len(idx), batch):
        b = ds.gather(idx[i:i + batch])
        probs.append(model.predict({n: model.normalize(b[n], b[OFFSETS[n]]) for n in model.input_names}))
        signal.append(window_signal_db([(b[n], b[OFFSETS[n]]) for n in model.input_names]))
        labels.append(b["label"])
    return {"probs": np.concatenate(probs), "labels": np.concatenate(labels), "signal_db": np.concatenate(signal),
            "visibility": ds.visibility()[idx], "scenes": ds.scene_ids()[idx], "classes": model.classes}


DEFAULT_MIN_SNR_DB = -20.0


def calibrate(model_path: Path, data: list[Path], *, level: float, edges: list[float] | None = None,
              min_snr_db: float | None = DEFAULT_MIN_SNR_DB) -> dict[str, Any]:
    """Write the ``confidence`` block into the card of ``model_path``; returns the block.

    ``min_snr_db``: only windows whose least visible mover is at least this far from the plot's
    noise (or that hold nobody moving) are calibrated on. A person far under the camera's noise
    is no evidence any method can read; counting them in would make every 'nobody' undetermined
    for ever. The card says so (``validated_range``): a decided answer is validated for people
    whose light reaches the camera at least that strongly.
    """
    from wallcli.io.writer import write_text_atomic

    edges = list(DEFAULT_EDGES if edges is None else edges)
    parts = [score_dataset(model_path, [d]) for d in data]  # scored apart: each set is also checked alone
    s = {k: (np.concatenate([p[k] for p in parts]) if isinstance(parts[0][k], np.ndarray) else parts[0][k])
         for k in parts[0]}
    s["group"] = np.concatenate([np.full(len(p["labels"]), i) for i, p in enumerate(parts)])
    if min_snr_db is not None:
        keep = np.isnan(s["visibility"]) | (s["visibility"] >= min_snr_db)
        s = {k: (v[keep] if isinstance(v, np.ndarray) else v) for k, v in s.items()}
    block = fit(s["probs"], s["labels"], s["signal_db"], s["classes"], level=level, edges=edges,
                groups=s["group"] if len(data) > 1 else None)
    pred = s["probs"].argmax(1)
    right = pred == s["labels"]
    decided = np.array([_decided(block, p, db) for p, db in zip(s["probs"], s["signal_db"])])
    block["validated_range"] = ("all windows" if min_snr_db is None else
                                f"windows whose least visible mover is at least {min_snr_db:g} dB against the plot's "
                                "noise (the simulator's snr_db_weakest), or where nobody moves")
    block["calibrated_on"] = {
        "datasets": [str(d) for d in data], "windows": int(len(right)),
        "accuracy": round(float(right.mean()), 4),
        "coverage": round(float(decided.mean()), 4),
        "accuracy_decided": round(float(right[decided].mean()), 4) if decided.any() else None,
        "note": "simulated validation windows the model never trained on; thresholds are fitted here, so "
                "these in-sample figures are optimistic: see the card's transfer block for held-out ones",
    }
    card = read_card(model_path)
    card["confidence"] = block
    write_text_atomic(card_path(model_path), card_text(card), force=True)
    return block


def _decided(block, probs, db) -> bool:
    from wallcli.infer.confidence import judge

    return judge(block, probs, db, list(range(len(probs))))[0]
