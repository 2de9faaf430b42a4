"""Training on labelled recordings, and the out-of-fold figures that choose between models.

The recordings' windows (:mod:`wallcli.train.recordings`) are written as one shard dataset per
fold, in the simulator's format, so the one training loop reads recordings, simulated windows, or
both. ``--folds K``: for each fold, a net trained on the other folds answers that fold's clips,
exactly as ``wallcli count``/``activity`` answer a clip (the card's stride, the windows' mean);
all folds together are the candidate's figure. No window of a clip is ever in two folds.
"""
from __future__ import annotations

import json
from pathlib import Path
from typing import Any

import numpy as np

from wallcli.errors import WallcliError
from wallcli.train.recordings import BINS, WINDOW, Recording, fold_of

BANDS = (("empty", None, None), ("<0 dB", None, 0.0), ("0-10 dB", 0.0, 10.0), (">=10 dB", 10.0, None))
Z95_ONE_SIDED = 1.6449


def truth(rec: Recording, task: str) -> Any:
    return rec.people if task == "count" else rec.activity


def band_of(rec: Recording) -> str:
    """The labels' band (as evaluate's by_band): empty rooms apart, then by the labels' SNR."""
    if rec.people == 0:
        return "empty"
    s = rec.snr_db
    if s is None or s < 0:
        return "<0 dB"
    return "0-10 dB" if s < 10 else ">=10 dB"


def write_fold_datasets(recs: list[Recording], task: str, root: Path, k: int) -> list[Path]:
    """One dataset folder per fold under ``root`` (k <= 1: one folder holding every clip)."""
    from wallcli.datagen.dataset import CLASSES, FORMAT, SHARD_FORMAT, VERSION
    from wallcli.io.arrays import save_npz
    from wallcli.io.writer import write_text_atomic

    classes = CLASSES[task]
    groups: dict[int, list[Recording]] = {}
    for r in recs:
        groups.setdefault(fold_of(r.name, k) if k > 1 else 0, []).append(r)
    out = []
    for f in range(max(k, 1)):
        d = root / f"fold-{f}"
        d.mkdir(parents=True, exist_ok=True)
        members = groups.get(f, [])
        if not members:
            raise WallcliError(f"fold {f} of {k} holds no clips: too few labelled clips for {k} folds")
        arrays = {"horizontal": np.concatenate([r.horizontal for r in members]),
                  "vertical": np.concatenate([r.vertical for r in members]),
                  "h_offset": np.concatenate([r.h_offset for r in members]),
                  "v_offset": np.concatenate([r.v_offset for r in members])}
        n = len(arrays["horizontal"])
        lab = np.concatenate([[classes.index(truth(r, task))] * len(r.starts) for r in members]).astype(np.int64)
        snr = np.concatenate([[np.nan if r.snr_db is None else r.snr_db] * len(r.starts) for r in members])
        arrays.update(label=lab, people=np.concatenate([[r.people] * len(r.starts) for r in members]).astype(np.int64),
                      activity=np.concatenate([[classes.index(r.activity) if task == "activity" else 0] * len(r.starts)
                                               for r in members]).astype(np.int64),
                      snr_db=snr.astype(np.float32), snr_db_weakest=snr.astype(np.float32))
        scenes = [{"clip": r.name, "seed": "recordings", "index": r.name} for r in members for _ in r.starts]
        save_npz(d / "shard-00000.npz", arrays, {"format": SHARD_FORMAT, "version": VERSION, "task": task,
                                                 "seed": "recordings", "scenes": scenes}, force=True)
        manifest = {"format": FORMAT, "version": VERSION, "task": task, "classes": classes, "window": WINDOW,
                    "bins": BINS, "seed": f"recordings fold {f} of {k}", "complete": True,
                    "recipe": {"recordings": sorted(r.name for r in members), "fold": f, "folds": k},
                    "shards": [{"file": "shard-00000.npz", "n": n}]}
        write_text_atomic(d / "dataset.json", json.dumps(manifest, indent=1), force=True)
        out.append(d)
    return out


def clip_probabilities(model, rec: Recording) -> np.ndarray:
    """The clip's answer as inference gives it: the mean of the model's window probabilities over
    the windows at the card's stride (for a two-stage count, both nets' means, then combined)."""
    ix = rec.eval_index(int(model.card["stride"]))
    wins = {"horizontal": rec.horizontal[ix], "vertical": rec.vertical[ix]}
    offs = {"horizontal": rec.h_offset[ix], "vertical": rec.v_offset[ix]}
    raw = model.classify({n: wins[n] for n in model.input_names}, {n: offs[n] for n in model.input_names})
    p = model.combine(raw.mean(axis=0))[0]
    return p / p.sum()


def clip_signal_db(model, rec: Recording) -> float:
    """The clip's measured signal (the mean of its windows' ``window_signal_db``), as classify reports it."""
    from wallcli.signal.window import window_signal_db

    ix = rec.eval_index(int(model.card["stride"]))
    parts = [(getattr(rec, n)[ix], (rec.h_offset if n == "horizontal" else rec.v_offset)[ix]) for n in model.input_names]
    return round(float(np.mean(window_signal_db(parts))), 2)


def _interval(k: int, n: int) -> list[float] | None:
    """The 95 % interval of k right of n, rounded for the card: the exact (Clopper-Pearson) one
    that evaluate prints, so that a card and evaluate's table on the same clips agree."""
    from wallcli.evaluate.score import exact_ci

    ci = exact_ci(k, n)
    return None if ci is None else [round(ci[0], 4), round(ci[1], 4)]


def oof_table(recs: list[Recording], answers: dict[str, dict], task: str, classes: list) -> dict[str, Any]:
    """The card's ``recordings.out_of_fold`` block from per-clip answers {name: {label, confident}}."""
    by_band, conf = {}, np.zeros((len(classes), len(classes)), np.int64)
    conf_det = np.zeros_like(conf)
    det_right = det_n = dec_n = dec_right = 0
    for name, lo, hi in BANDS:
        sel = [r for r in recs if band_of(r) == name]
        right = sum(answers[r.name]["label"] == truth(r, task) for r in sel)
        dec = [r for r in sel if answers[r.name]["confident"]]
        by_band[name] = {"right": int(right), "clips": len(sel), "decided": len(dec),
                         "decided_right": int(sum(answers[r.name]["label"] == truth(r, task) for r in dec))}
    for r in recs:
        a = answers[r.name]
        conf[classes.index(truth(r, task)), classes.index(a["label"])] += 1
        if r.detectable is not False:
            conf_det[classes.index(truth(r, task)), classes.index(a["label"])] += 1
            det_n += 1
            det_right += a["label"] == truth(r, task)
            if a["confident"]:
                dec_n += 1
                dec_right += a["label"] == truth(r, task)
    return {"detectable": {"right": int(det_right), "clips": det_n,
                           "accuracy": round(det_right / det_n, 4) if det_n else None, "ci95": _interval(det_right, det_n),
                           "decided": dec_n, "decided_right": dec_right, "confusion_matrix": conf_det.tolist()},
            "by_band": by_band, "confusion_matrix": conf.tolist(),
            "confusion_matrix_axes": "rows: true class, columns: answer, both in the order of classes"}


def format_table(block: dict[str, Any], task: str) -> list[str]:
    """The out-of-fold table as lines for the terminal."""
    lines = [f"{'band':<10} {'right':>10} {'decided (right)':>16}"]
    for name, b in block["by_band"].items():
        lines.append(f"{name:<10} {b['right']:>4} of {b['clips']:<4} {b['decided']:>8} ({b['decided_right']})")
    d = block["detectable"]
    ci = d["ci95"] or [float("nan")] * 2
    lines.append(f"{'detectable':<10} {d['right']:>4} of {d['clips']:<4} {d['decided']:>8} ({d['decided_right']})"
                 f"   {d['accuracy'] or 0:.1%} (95 % CI {ci[0]:.0%}-{ci[1]:.0%})")
    return lines


def fit_trust(probs: np.ndarray, labels: np.ndarray, signal_db: np.ndarray, classes: list, *, level: float,
              min_support: int = 10, edges=(0.0, 10.0)) -> dict[str, Any]:
    """The card's ``confidence`` block fitted on out-of-fold clip answers.

    Per band of measured signal, one threshold shared by every answer but "nobody" (which is never
    decided): the lowest probability whose answers were right >= ``level`` with a 95 % one-sided
    Wilson bound, on at least ``min_support`` clips; null (undetermined) where no such probability
    exists. One threshold per band rather than per answer: a few hundred clips split over answers
    leave no cell large enough to back a 97 % claim (with no error at all, a 95 % bound of 97 % needs
    88 clips)."""
    from wallcli.infer.confidence import FORMAT, NOBODY, band_of, wilson_lower

    probs = np.asarray(probs, np.float64)
    labels = np.asarray(labels, np.int64)
    pred, pmax = probs.argmax(1), probs.max(1)
    bands = np.array([band_of(list(edges), s) for s in signal_db], np.int64)
    someone = np.array([classes[k] not in NOBODY for k in pred], bool)
    table = []
    for b in range(len(edges) + 1):
        sel = (bands == b) & someone
        order = np.argsort(-pmax[sel], kind="stable")
        p, ok = pmax[sel][order], (pred[sel] == labels[sel])[order]
        hits, m = np.cumsum(ok), np.arange(1, len(p) + 1)
        good = (wilson_lower(hits, m, Z95_ONE_SIDED) >= level) & (m >= min_support)
        t = round(float(p[int(np.flatnonzero(good).max())]), 4) if good.any() else None
        table.append([None if c in NOBODY else t for c in classes])
    return {"format": FORMAT, "level": level, "signal_edges_db": list(edges), "thresholds": table,
            "min_support": min_support, "bound": f"one-sided Wilson lower bound, z = {Z95_ONE_SIDED:g} (95 %)",
            "pooled": "one threshold per signal band, shared by every answer but nobody",
            "fitted_on": (f"out-of-fold answers on {len(labels)} labelled recordings (each answered by a model "
                          "that never trained on it), one answer per clip"),
            "thresholds_axes": "rows: signal bands (under the first edge, between edges, over the last); columns: "
                               "answers in the order of classes; null: never right that often"}


def _identity(cfg, f: int, k: int, recs: list[Recording], extra: dict) -> str:
    import hashlib
    from dataclasses import asdict

    from wallcli.infer.card import sha256_file

    c = {key: str(v) for key, v in asdict(cfg).items() if key not in ("out", "checkpoint", "val", "data", "threads",
                                                                     "checkpoint_minutes", "resume", "device")}
    c.update(fold=f, folds=k, clips=sorted(r.name for r in recs), extra=extra,
             init=sha256_file(Path(cfg.init)) if cfg.init else None)
    return hashlib.sha256(json.dumps(c, sort_keys=True).encode()).hexdigest()[:16]


def cross_validate(cfg, fold_dirs: list[Path], sim_data: list[Path], recs: list[Recording], work: Path, *,
                   load, bars, log=None, extra: dict | None = None,
                   split: list | None = None, split_sim=None) -> dict[str, dict[str, Any]]:
    """Out-of-fold answers {clip: {"probs", "signal_db", "fold"}}: for each fold, the net trained by
    ``cfg`` on the other folds (and ``sim_data``), exported, loaded with ``load(path)`` as the
    commands load it, answers the fold's clips. Each fold's answers are kept in ``work``: a rerun
    (after Ctrl-C, or to train the final model) skips the folds already answered."""
    from wallcli.io.writer import write_text_atomic

    k = len(fold_dirs)
    answers: dict[str, dict[str, Any]] = {}
    for f in range(k):
        members = [r for r in recs if fold_of(r.name, k) == f]
        ident = _identity(cfg, f, k, recs, dict(extra or {}, split=split, split_sim=None if split_sim is None else
                                                            [len(split_sim[1]), float(np.sum(split_sim[0]))]))
        done = work / f"fold-{f}.answers.json"
        if done.is_file():
            try:
                got = json.loads(done.read_text(encoding="utf-8"))
                if got.get("identity") == ident:
                    answers.update(got["answers"])
                    if log:
                        log(f"fold {f + 1}/{k}: answers kept from an earlier run ({done})")
                    continue
            except (OSError, ValueError, KeyError):
                pass  # damaged: trained again
        if log and cfg.epochs == 0:
            log(f"fold {f + 1}/{k}: the net as it is; fitting on {len(recs) - len(members)} clips, answering {len(members)}")
        elif log:
            log(f"fold {f + 1}/{k}: training on {sum(len(r.starts) for r in recs if r not in members)} windows of "
                f"{len(recs) - len(members)} clips, answering {len(members)} clips")
        # --epochs 0: the net as it is, only the split (and the thresholds) come from the recordings
        model = load(Path(cfg.init) if cfg.epochs == 0 else
                     _train_fold(cfg, f, fold_dirs, sim_data, work / f"fold-{f}.onnx", work / f"fold-{f}-{ident}.ckpt.pt", bars))
        _attach_split(model, [r for r in recs if r not in members], split, split_sim)
        got = {r.name: {"probs": [float(p) for p in clip_probabilities(model, r)],
                        "signal_db": clip_signal_db(model, r), "fold": f} for r in members}
        write_text_atomic(done, json.dumps({"identity": ident, "answers": got}), force=True)
        (work / f"fold-{f}-{ident}.ckpt.pt").unlink(missing_ok=True)
        answers.update(got)
    return answers


def _train_fold(cfg, f: int, fold_dirs: list[Path], sim_data: list[Path], onnx: Path, checkpoint: Path, bars) -> Path:
    """Fold ``f``'s net: trained on the other folds (and ``sim_data``), validated on its own, exported."""
    from dataclasses import replace

    from wallcli.train.export import export_model
    from wallcli.train.loop import train as run_training

    fcfg = replace(cfg, data=[d for i, d in enumerate(fold_dirs) if i != f] + list(sim_data), val=fold_dirs[f],
                   out=onnx, checkpoint=checkpoint)
    with bars() as bar:
        res = run_training(fcfg, bar.event)
    export_model(res["net"], res["dataset"].inputs, onnx,
                 {"name": f"fold-{f}", "version": "0", "task": cfg.task, "classes": res["dataset"].classes,
                  "preprocessing": cfg.preprocessing, "stride": 64, "training_data": {"folds": [str(d) for d in fcfg.data]},
                  "training": {"fold": f, "of": len(fold_dirs)}, "validation": None}, force=True, seed=cfg.seed)
    return onnx


def _split_data(recs: list[Recording], pair: list) -> tuple[np.ndarray, np.ndarray]:
    """Each detectable one-person clip of the pair: its windows' mean features (at the card's
    stride, as a clip's answer is made) and 1 for the pair's second answer."""
    from wallcli.signal.features import window_features

    use = [r for r in recs if r.activity in pair and r.persons <= 1 and r.detectable is not False]
    if len({r.activity for r in use}) < 2:
        raise WallcliError(f"--split {','.join(pair)}: the recordings need clips of both")
    X = []
    for r in use:
        ix = r.eval_index(64)
        X.append(window_features(r.horizontal[ix], r.vertical[ix], r.h_offset[ix], r.v_offset[ix]).mean(0))
    return np.array(X), np.array([1.0 if r.activity == pair[1] else 0.0 for r in use])


def _shard_files(d: Path) -> list[Path]:
    """The shards the data set's manifest lists (a folder may hold others: an older set's)."""
    from wallcli.io import jsonfile

    try:
        manifest = jsonfile.loads((d / "dataset.json").read_text(encoding="utf-8"))
        return [d / s["file"] for s in manifest["shards"]]
    except (OSError, ValueError, KeyError, TypeError):
        return sorted(d.glob("shard-*.npz"))


def simulated_split_data(data: list[Path], pair: list) -> tuple[np.ndarray, np.ndarray]:
    """The simulator's scenes of the pair in activity datasets ``data``: each scene's windows' mean
    features (a scene is a clip: its windows cut from one rendered room), 1 for the pair's second."""
    from wallcli.datagen.dataset import CLASSES
    from wallcli.io.arrays import load_npz
    from wallcli.signal.features import window_features

    want = [CLASSES["activity"].index(c) for c in pair]
    rows: dict[tuple, list] = {}
    for d in data:
        for f in _shard_files(Path(d)):
            a, meta = load_npz(f)
            lab = np.asarray(a["activity"] if "activity" in a else a["label"])
            keep = np.flatnonzero(np.isin(lab, want) & (np.asarray(a.get("people", np.ones_like(lab))) <= 1))
            if not len(keep):
                continue
            feats = window_features(a["horizontal"][keep], a["vertical"][keep], a["h_offset"][keep], a["v_offset"][keep])
            scenes = meta.get("scenes") or [{} for _ in lab]
            for i, row in zip(keep, feats):
                key = (str(d), scenes[i].get("seed"), scenes[i].get("index", f"{f.name}:{i}"))
                rows.setdefault(key, [int(lab[i] == want[1]), []])[1].append(row)
    if not rows:
        raise WallcliError(f"--split: no simulated windows of {pair[0]} or {pair[1]} in {', '.join(map(str, data))}")
    X = np.array([np.mean(v[1], axis=0) for v in rows.values()])
    return X, np.array([float(v[0]) for v in rows.values()])


def fit_split(recs: list[Recording], pair: list, sim: tuple[np.ndarray, np.ndarray] | None = None) -> dict[str, Any]:
    """The split fitted on the recordings' clips of the pair; with ``sim`` (simulated scenes), on
    both, each set weighted to count as much as the other in all."""
    from wallcli.infer.split import fit

    X, y = _split_data(recs, pair)
    what = f"{len(y)} labelled recordings of {pair[0]} or {pair[1]} (detectable, one person)"
    w = np.ones(len(y))
    if sim is not None:
        Xs, ys = sim
        w = np.concatenate([w, np.full(len(ys), len(y) / len(ys))])
        X, y = np.concatenate([X, Xs]), np.concatenate([y, ys])
        what += (f" and {len(ys)} simulated scenes of the pair, each set weighted to count as much as the other "
                 f"(a simulated scene weighs {w[-1]:.3f} of a recording)")
    block = fit(X, y, weights=w)
    block.update(pair=list(pair), fitted_on=what)
    return block


def _attach_split(model, train_recs: list[Recording], pair: list | None, sim=None) -> None:
    """The fold's model with a split fitted on the other folds' clips only (and ``sim``)."""
    if not pair:
        return
    from wallcli.infer.split import Split

    model.split = Split(fit_split(train_recs, pair, sim), list(model.classes))
