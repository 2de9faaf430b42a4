"""``wallcli train count|activity --data DIR --out models/NAME.onnx``: train, export, write the card."""
from __future__ import annotations

from enum import Enum
from pathlib import Path
from typing import List, Optional

import typer

from wallcli.cli.common import force_help, number_option, threads_option

from wallcli.extras import TRAIN as INSTALL_HINT


class Task(str, Enum):
    count = "count"
    activity = "activity"


def train(
    task: Task = typer.Argument(..., help="Which network: 'count' (0/1/2 people) or 'activity'."),
    data: List[Path] = typer.Option([], "--data", help="Dataset folder from the simulator (dataset.json + shards); "
                                    "repeat it to train on several folders as one dataset."),
    clips: List[Path] = typer.Option([], "--clips", help="Folder of labelled recordings (any folder 'wallcli evaluate' "
                                     "reads: labels.csv or .json sidecars); repeatable. Each clip is cut into windows "
                                     "through the path inference takes (camera pipeline, corrections, both plots) every "
                                     "16 samples, cached in --clip-cache. With --data as well, both are trained on."),
    folds: int = number_option(0, "--folds", lo=0, hi=50, integer=True, help="With --clips: first train once per fold "
                               "(the clip's number in its file name mod K) on the other folds, answer that fold's clips "
                               "as 'wallcli count/activity' would, print the out-of-fold table and write it in the "
                               "card ('recordings'); the decided/undetermined thresholds are fitted on those answers. "
                               "0: no folds. Then the model is trained on every clip."),
    split: Optional[str] = typer.Option(None, "--split", help="activity with --clips: two answers the net confuses "
                                        "(e.g. 'waving,jumping'); where the net's answer is one of them, their probability "
                                        "is shared again by a logistic regression on the plots' physical features, fitted "
                                        "on the recordings (wallcli/infer/split.py), out of fold with --folds; with "
                                        "--data (activity datasets), on the simulator's scenes of the pair too, each set "
                                        "weighted to count as much as the other."),
    clip_cache: Optional[Path] = typer.Option(None, "--clip-cache", help="Where the recordings' windows are cached "
                                              "(default: $WALLCLI_CACHE/recordings or ~/.cache/wallcli/recordings)."),
    out: Path = typer.Option(..., "--out", "-o", help="Model to write (.onnx); its card goes beside it (.json)."),
    val: Optional[Path] = typer.Option(None, "--val", help="Validation dataset folder (default: hold out --val-fraction of --data)."),
    val_fraction: float = number_option(0.1, "--val-fraction", lo=0, hi=0.5, help="Share of --data held out when there is no --val."),
    epochs: int = number_option(20, "--epochs", lo=0, hi=100_000, integer=True, help="Total epochs (a resumed run continues up to this). "
                                "0, with --init and --clips: keep --init's net as it is and fit only what is fitted on the "
                                "recordings (--split, the decided/undetermined thresholds)."),
    batch_size: int = number_option(32, "--batch-size", lo=2, hi=65536, integer=True, help="Windows per optimisation step."),
    threads: int = threads_option("Torch CPU threads (0: torch's default)."),
    seed: int = number_option(0, "--seed", lo=0, hi=2**32 - 1, integer=True, help="Seed of initialisation, split, batch order and augmentation."),
    checkpoint: Optional[Path] = typer.Option(None, "--checkpoint", help="Checkpoint file (default: OUT with suffix .ckpt.pt)."),
    checkpoint_minutes: float = number_option(5.0, "--checkpoint-minutes", lo=0.1, hi=1e6, help="Minutes between checkpoints within an epoch."),
    resume: bool = typer.Option(True, "--resume/--no-resume", help="Continue from the checkpoint when it exists."),
    augment: bool = typer.Option(True, "--augment/--no-augment", help="Label-preserving augmentation (see wallcli/train/augment.py)."),
    name: Optional[str] = typer.Option(None, "--name", help="Model name in the card (default: wallcli-TASK)."),
    model_version: str = typer.Option("1.0.0", "--model-version", help="Model version in the card."),
    stride: int = number_option(64, "--stride", lo=1, hi=65536, integer=True, help="Default inference stride recorded in the card (frames)."),
    min_snr_db: Optional[float] = number_option(None, "--min-snr-db", lo=-200, hi=200, help="Skip training windows whose movers' "
                                               "noise-free signal is this many dB below the plot noise or more (per-window "
                                               "snr_db from the simulator); windows with nobody moving always stay. "
                                               "Validation keeps every window."),
    anneal: int = number_option(0, "--anneal", lo=0, hi=100_000, integer=True, help="Lower the learning rate over the last N epochs (cosine, "
                               "down to 1/100 of --lr); 0: a constant --lr throughout. Raising --epochs with "
                               "--anneal on a finished run continues it from its checkpoint."),
    ema: float = number_option(0.995, "--ema", lo=0, hi=0.9999, help="Per-step decay of the moving average of the "
                              "weights that is validated and exported (0: the raw weights)."),
    select: str = typer.Option("last", "--select", help="Export the weights after the last epoch ('last': the card's "
                               "validation accuracy is then a plain measurement) or of the epoch with the best "
                               "validation accuracy ('best')."),
    quantize: str = typer.Option("none", "--quantize", help="none: ship the float32 graph; int8: ship a statically "
                                 "quantised graph (about 1.6x faster on CPU; calibrated on 256 training windows, its "
                                 "validation accuracy measured again and written in the card)."),
    superpose: float = number_option(0.0, "--superpose", lo=0, hi=1, help="count only: share of training windows "
                                    "replaced by their sum with another window of the batch, labels added (light "
                                    "transport is linear; see wallcli/train/augment.py). 0: off."),
    preprocessing: str = typer.Option("v1", "--preprocessing", help="Window normalisation the net learns on, recorded "
                                      "in the card (inference follows the card): v1 = divided by the window's RMS; v2 = "
                                      "in units of the window's frame-to-frame noise, asinh-compressed, so a faint "
                                      "second mover is not scaled away by a strong first; v3 = v1 after the whole-wall light change (flicker, "
                                      "drift) is projected out of every sample (wallcli/signal/window.py)."),
    arch: str = typer.Option("paper", "--arch", help="Network: 'paper' = the paper's nets exactly (Sharma et al., ICCV 2021, supplementary §2; 'seed', "
                             "the name of earlier versions, is accepted for it) (count reads the "
                             "horizontal plot, activity both); 'lite' = both plots for either task, time averaged in "
                             "pairs and 32 channels (about a quarter of the paper's count net's work; wallcli/train/nets.py)."),
    balance: bool = typer.Option(False, "--balance", help="Weight the loss by the inverse frequency of each class "
                                 "among the training windows (rare classes count as much as common ones)."),
    calibrate: List[Path] = typer.Option([], "--calibrate", help="Simulated validation dataset(s) the net never trained "
                                         "on: fit the card's decided/undetermined thresholds there (per answer and band of "
                                         "measured signal; wallcli/infer/confidence.py). Without it, every answer of the "
                                         "model is 'undetermined'."),
    confidence_level: float = number_option(0.97, "--confidence-level", lo=0.5, hi=0.999, help="With --calibrate: "
                                           "how often a decided answer must have been right in calibration."),
    init: Optional[Path] = typer.Option(None, "--init", help="Start from the weights of an exported model of the same "
                                        "task (its .onnx, float or int8): fine-tuning. The card records which."),
    lr: float = number_option(1e-3, "--lr", lo=1e-7, hi=1, help="RMSProp learning rate (the paper's 1e-3; "
                             "--anneal ends at 1/100 of it). Lower it to fine-tune from --init."),
    device: str = typer.Option("cpu", "--device", help="Where the net trains: 'cpu', or 'cuda' on a machine with an "
                               "NVIDIA GPU and a CUDA build of PyTorch (batches are still read and augmented on the CPU)."),
    force: bool = typer.Option(False, "--force", help=force_help("OUT and its card")),
) -> None:
    """Train the paper's CNN on simulator windows and export it to ONNX with a model card.

    RMSProp (lr 1e-3) on cross-entropy, with label-preserving augmentation. A checkpoint is
    written every few minutes and after each epoch; running the same command again (or after
    Ctrl-C / kill) resumes exactly where it stopped. A moving average of the weights (--ema)
    is validated after every epoch and exported at the end (--select); the card records the
    data recipe, the training settings, the validation accuracy and confusion matrix, and the
    sha256 of the .onnx.
    Needs PyTorch and onnx: pip install torch==2.13.0 'onnx>=1.15' (from the top folder
    of the checkout: pip install torch==2.13.0 && pip install '.[train]').

    \b
    Examples:
      wallcli simulate --dataset 20000 --task count -o data/count --jobs 2
      wallcli simulate --dataset 2000 --task count --domain shifted -o data/val
      wallcli train count --data data/count --val data/val --out count.onnx
    """
    import importlib.util

    # both before any work: the export at the end needs onnx, and a run that trained for an hour
    # should not end in an import error
    missing = [m for m in ("torch", "onnx") if importlib.util.find_spec(m) is None]
    if missing:
        from wallcli.errors import WallcliError

        names = {"torch": "PyTorch", "onnx": "the onnx package"}
        raise WallcliError(f"training needs {' and '.join(names[m] for m in missing)}, which "
                           f"{'is' if len(missing) == 1 else 'are'} not installed", hint=INSTALL_HINT)
    import torch

    from wallcli.cli.output import console_err, log
    from wallcli.errors import UsageError
    from wallcli.infer.card import card_path
    from wallcli.io.writer import check_output, check_outputs
    from wallcli.train.augment import DESCRIPTION, SUPERPOSE_DESCRIPTION
    from wallcli.train.export import export_model
    from wallcli.train.loop import ANNEAL_FLOOR, TrainConfig, train as run_training

    if not data and not clips:
        raise UsageError("nothing to train on: give --data (simulated windows) or --clips (labelled recordings)")
    if folds == 1:
        raise UsageError("--folds must be 0 (none) or at least 2")
    if folds and not clips:
        raise UsageError("--folds needs --clips: folds split labelled recordings by clip")
    if epochs == 0 and (init is None or not clips):
        raise UsageError("--epochs 0 keeps --init's net as it is: it needs --init and --clips")
    split_pair = None
    if split is not None:
        split_pair = [c.strip() for c in split.split(",")]
        from wallcli.infer.card import TASK_CLASSES

        if task.value != "activity" or not clips:
            raise UsageError("--split applies to activity trained with --clips")
        if len(split_pair) != 2 or split_pair[0] == split_pair[1] or any(c not in TASK_CLASSES["activity"] for c in split_pair):
            raise UsageError(f"--split must name two activity classes, e.g. waving,jumping (got {split!r})")
    if select not in ("last", "best"):
        raise UsageError(f"--select must be last or best (got {select!r})")
    if quantize not in ("none", "int8"):
        raise UsageError(f"--quantize must be none or int8 (got {quantize!r})")
    if anneal > epochs:
        raise UsageError(f"--anneal {anneal} is more than --epochs {epochs}")
    if superpose > 0 and task.value != "count":
        raise UsageError("--superpose applies to count only (people add up; activities do not)")
    from wallcli.signal.window import NORMALIZATION, NORMALIZATION_TEXT, NORMALIZATION_V2

    from wallcli.signal.window import NORMALIZATION_V3
    from wallcli.train.nets import ARCHS

    versions = {"v1": NORMALIZATION, "v2": NORMALIZATION_V2, "v3": NORMALIZATION_V3}
    if preprocessing not in versions:
        raise UsageError(f"--preprocessing must be v1, v2 or v3 (got {preprocessing!r})")
    # 'paper' is what users type; 'seed' (the project's starting design) stays the name the
    # training code and existing model cards use for it
    arch = "seed" if arch == "paper" else arch
    if arch not in ARCHS:
        shown = ["paper" if a == "seed" else a for a in ARCHS]
        raise UsageError(f"--arch must be {' or '.join(shown)} (got {arch!r})")
    prep = versions[preprocessing]
    if device not in ("cpu", "cuda"):
        raise UsageError(f"--device must be cpu or cuda (got {device!r})")
    if device == "cuda" and not torch.cuda.is_available():
        raise UsageError("--device cuda: this PyTorch sees no CUDA GPU", hint="train with --device cpu")
    if out.suffix.lower() != ".onnx":
        raise UsageError(f"--out must end in .onnx: {out}")
    read = [f for d in [*data, val, *calibrate] if d is not None
            for f in [Path(d) / "dataset.json", *sorted(Path(d).glob("shard-*.npz"))]] + [init] + [Path(c) / "labels.csv" for c in clips]
    check_outputs([out, card_path(out)], force=force, inputs=read)
    # the checkpoint is read and rewritten by every run of this training (no --force needed), but
    # it must not be one of the data's files, or the model's
    check_output(checkpoint or out.with_suffix(".ckpt.pt"), force=True, inputs=[*read, out, card_path(out)])
    init_info = base = None
    if init is not None:
        from wallcli.infer.card import read_card, sha256_file

        if not init.is_file():
            raise UsageError(f"--init model not found: {init}")
        base = read_card(init)  # its card says which model it is (and checks nothing else here)
        if base.get("task") != task.value:
            raise UsageError(f"--init {init} is a {base.get('task')!r} model, not {task.value!r}")
        if base.get("preprocessing") != prep:
            raise UsageError(f"--init {init} was trained on {base.get('preprocessing')}, this run on {prep}")

        init_info = {"name": base.get("name"), "version": base.get("version"), "sha256": sha256_file(init),
                     "path": str(init.resolve())}
    cfg = TrainConfig(task=task.value, data=list(data), out=out, val=val, val_fraction=val_fraction, epochs=epochs,
                      batch_size=batch_size, threads=threads, seed=seed, checkpoint=checkpoint,
                      checkpoint_minutes=checkpoint_minutes, resume=resume, augment=augment,
                      min_snr_db=min_snr_db, ema=ema, select=select, superpose=superpose, preprocessing=prep,
                      anneal=anneal, init=init, lr=lr, arch=arch, balance=balance, device=device)

    # `kill PID` of a background run saves a checkpoint like Ctrl-C (then exits 1): wallcli.cli._signals,
    # installed by main(), turns both into wallcli.errors.Interrupted, which run_training catches.
    recordings = None
    if clips:
        from wallcli.cli._train_clips import prepare

        cfg, recordings = prepare(cfg, task.value, list(clips), list(data), folds, clip_cache, out,
                                  lambda: _TrainProgress(console_err), confidence_level, split_pair)
        if epochs == 0:
            from wallcli.cli._train_clips import keep_init

            card = keep_init(init, out, recordings, name=name, version=model_version, force=force)
            log(f"wrote {out} and {card_path(out).name}: the net of {init} unchanged (sha256 {card['sha256'][:12]}…)")
            return

    with _TrainProgress(console_err) as bar:
        result = run_training(cfg, bar.event)

    ds = result["dataset"]
    vds = result["val_dataset"]
    validation = None
    if result["validation"] is not None:
        v = result["validation"]
        validation = {
            "source": ({"dataset": str(val), "recipe": vds.manifest.get("recipe"), "seed": vds.manifest.get("seed")}
                       if vds is not None else f"{val_fraction:.0%} of the training dataset held out (seed {seed})"),
            "windows": v["windows"], "accuracy": v["accuracy"], "loss": v["loss"],
            "confusion_matrix": v["confusion_matrix"],
            "confusion_matrix_axes": "rows: true class, columns: predicted class, both in the order of classes",
            "epoch": result["best_epoch"],
        }
    fields = dict(
        name=name or f"wallcli-{task.value}", version=model_version, task=task.value, classes=ds.classes, stride=stride,
        preprocessing=prep, normalisation=NORMALIZATION_TEXT[prep],
        training_data={"dataset": [str(d) for d in cfg.data], "recipe": ds.recipes, "seed": [m.get("seed") for m in ds.manifests],
                       "windows": ds.n, "train_windows": result["train_windows"], "min_snr_db": min_snr_db,
                       "windows_seen": _windows_seen(ds.manifests, base)},
        training={**({"init": init_info} if init_info else {}), "arch": arch, "seed": seed, "epochs": epochs, "batch_size": batch_size, "optimizer": "RMSprop", "lr": cfg.lr,
                  **({"lr_schedule": f"constant {cfg.lr:g}, then cosine to {cfg.lr * ANNEAL_FLOOR:g} over the last {anneal} epochs"}
                     if anneal else {}),
                  "loss": "cross-entropy" + (", classes weighted by inverse training frequency" if balance else ""), "augmentation": ([SUPERPOSE_DESCRIPTION.format(p=superpose)] if superpose > 0 else [])
                  + (DESCRIPTION if augment else []),
                  "weight_average": {"ema_decay_per_step": ema, "exported": select},
                  "selected_epoch": result["best_epoch"], "history": result["history"],
                  "command": f"wallcli train {task.value} " + " ".join(f"--data {d}" for d in data)
                             + f" --out {out} --epochs {epochs} --batch-size {batch_size} --seed {seed} --ema {ema:g} --select {select}"
                             + "".join(f" --clips {c}" for c in clips) + (f" --folds {folds}" if folds else "")
                             + (f" --val {val}" if val else f" --val-fraction {cfg.val_fraction}")
                             + ("" if augment else " --no-augment")
                             + (f" --superpose {superpose:g}" if superpose > 0 else "")
                             + (f" --min-snr-db {min_snr_db:g}" if min_snr_db is not None else "")
                             + (f" --quantize {quantize}" if quantize != "none" else "")
                             + (f" --anneal {anneal}" if anneal else "")
                             + (f" --lr {lr:g}" if lr != 1e-3 else "")
                             + (f" --init {init}" if init is not None else "")
                             + (f" --preprocessing {preprocessing}" if preprocessing != "v1" else "")
                             + (f" --arch {arch}" if arch != "seed" else "")
                             + (" --balance" if balance else "")
                             + "".join(f" --calibrate {c}" for c in calibrate)
                             + (f" --confidence-level {confidence_level:g}" if calibrate else "")},
        validation=validation,
    )
    quant = _calibration(result, seed, prep) if quantize == "int8" else None
    card = export_model(result["net"], ds.inputs, out, fields, force=force, seed=seed, quantize=quant,
                        evaluation=_evaluation(result, prep))
    if recordings is not None:
        from wallcli.cli._train_clips import write_block

        card = write_block(out, recordings)
    if calibrate:
        from wallcli.train.calibrate import calibrate as fit_confidence

        block = fit_confidence(out, list(calibrate), level=confidence_level)
        on = block["calibrated_on"]
        log(f"confidence thresholds fitted on {on['windows']} windows: {on['coverage']:.0%} decided, "
            f"{on['accuracy_decided'] if on['accuracy_decided'] is not None else float('nan'):.1%} of them right (in-sample)")
        from wallcli.infer.card import read_card

        card = read_card(out)
    shipped = card.get("validation") or {}  # with --quantize, the int8 graph's figure (what ships)
    acc = f", validation accuracy {shipped['accuracy']:.1%} on {shipped['windows']} windows" if shipped else ""
    log(f"wrote {out} and {card_path(out).name} (sha256 {card['sha256'][:12]}…){acc}")


def _calibration(result, seed: int, preprocessing: str, calib_windows: int = 256) -> dict:
    """Normalised calibration windows for int8 quantisation, drawn from the training set."""
    import numpy as np

    from wallcli.signal.window import normalize_window

    ds = result["dataset"]
    rng = np.random.default_rng([seed, 0xC0A1])
    tr = np.sort(rng.choice(result["train_indices"], min(calib_windows, len(result["train_indices"])), replace=False))
    from wallcli.train.data import OFFSETS

    b = ds.gather(tr)
    return {"calib": {n: normalize_window(b[n], preprocessing, b[OFFSETS[n]]) for n in ds.inputs}}


def _evaluation(result, preprocessing: str) -> dict | None:
    """The validation windows as the exported graph sees them, with each one's visibility and scene."""
    import numpy as np

    from wallcli.errors import WallcliError
    from wallcli.signal.window import normalize_window

    vds, idx = result["eval_dataset"], np.asarray(result["val_indices"])
    if not len(idx):
        return None
    vb = vds.gather(idx)
    try:
        visibility = vds.visibility()[idx]
    except WallcliError:  # a dataset that does not record its movers' SNR: no visible-window figures
        visibility = None
    from wallcli.train.data import OFFSETS

    return {"feeds": {n: normalize_window(vb[n], preprocessing, vb[OFFSETS[n]]) for n in vds.inputs}, "labels": vb["label"],
            "visibility": visibility, "scenes": vds.scene_ids()[idx]}


class _TrainProgress:
    """Progress bar with running loss/accuracy; plain epoch lines when stderr is not a terminal."""

    def __init__(self, console) -> None:
        self.console = console
        self.bar = None
        self.task = None
        self.last = None  # latest step, for the plain log line written at each checkpoint

    def __enter__(self) -> "_TrainProgress":
        if self.console.is_terminal:
            from rich.progress import BarColumn, MofNCompleteColumn, Progress, TextColumn, TimeElapsedColumn, TimeRemainingColumn

            self.bar = Progress(TextColumn("{task.description}"), BarColumn(), MofNCompleteColumn(),
                                TextColumn("loss {task.fields[loss]:.4f} acc {task.fields[acc]:.1%}"),
                                TimeElapsedColumn(), TimeRemainingColumn(), console=self.console)
            self.bar.__enter__()
        return self

    def __exit__(self, *exc) -> None:
        if self.bar is not None:
            self.bar.__exit__(*exc)

    def event(self, kind: str, **f) -> None:
        if kind == "resume":
            self.console.print(f"resuming from {f['path']} at epoch {f['epoch'] + 1}, batch {f['batch']}")
        elif kind == "epoch_start" and self.bar is not None:
            if self.task is not None:
                self.bar.remove_task(self.task)
            self.task = self.bar.add_task(f"epoch {f['epoch'] + 1}/{f['epochs']}", total=f["batches"],
                                          completed=f["done"], loss=float("nan"), acc=0.0)
        elif kind == "step":
            self.last = f
            if self.bar is not None:
                self.bar.update(self.task, completed=f["batch"], loss=f["loss"], acc=f["accuracy"])
        elif kind == "checkpoint" and self.bar is None and self.last is not None and f["batch"]:
            # logs of background runs get a line every few minutes, not only per epoch
            s = self.last
            self.console.print(f"epoch {s['epoch'] + 1} batch {s['batch']}/{s['batches']}: loss {s['loss']:.4f} "
                               f"acc {s['accuracy']:.1%} (checkpoint saved)")
        elif kind == "epoch_end":
            val = f"  val acc {f['val_accuracy']:.1%} loss {f['val_loss']:.4f}" if f["val_accuracy"] is not None else ""
            loss = f"{f['train_loss']:.4f}" if f["train_loss"] is not None else "-"
            acc = f"{f['train_accuracy']:.1%}" if f["train_accuracy"] is not None else "-"
            self.console.print(f"epoch {f['epoch']}: loss {loss} acc {acc}  "
                               f"{f['train_windows_per_s']:.1f} windows/s{val}")


def _windows_seen(manifests: list, init_card: dict | None) -> dict:
    from wallcli.train.provenance import windows_seen

    return windows_seen(manifests, init_card)
