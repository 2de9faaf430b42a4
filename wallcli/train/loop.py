"""The training loop: RMSProp (lr 1e-3) on cross-entropy, as the seed says.

Resumable: a checkpoint (model, optimiser, best weights, history, position in the epoch)
is written atomically every ``checkpoint_minutes`` and at the end of every epoch.  The
epoch's batch order and augmentation depend only on (seed, epoch, batch), so a run
resumed after a kill continues exactly where the checkpoint left off.

The loop reports through ``on_event(kind, **fields)`` and knows nothing of terminals:
the CLI draws the progress bar.

Weight averaging: besides the weights RMSProp moves, the loop keeps an exponential moving
average of every weight and batch-norm statistic (decay ``ema``, per step).  RMSProp at the
seed's 1e-3 with batch norm jumps around (validation accuracy swung +-15 points between
epochs); the average is the same optimiser's trajectory, smoothed, and it is what gets
validated and exported.  ``select="last"`` exports the final weights, so the validation
accuracy in the card is measured, not picked as the best of many noisy tries; ``"best"``
exports the epoch with the best validation accuracy.
"""
from __future__ import annotations

import copy
import os
import time
from dataclasses import asdict, dataclass
from pathlib import Path
from typing import Any, Callable

import numpy as np
import torch
from torch import nn

from wallcli.errors import WallcliError
from wallcli.infer.card import sha256_file
from wallcli.signal.window import NORMALIZATION
from wallcli.train.augment import augment, superpose
from wallcli.train.data import OFFSETS, ShardDataset, split_validation
from wallcli.train.nets import build

CKPT_FORMAT = "wallcli.train-checkpoint"
ANNEAL_FLOOR = 0.01  # --anneal ends at 1e-5 from the seed's 1e-3


def learning_rate(cfg: "TrainConfig", epoch: int, batch: int, batches: int) -> float:
    """The seed's constant rate, then (``cfg.anneal`` > 0) a cosine down to ``lr * ANNEAL_FLOOR``
    over the last ``anneal`` epochs.  The seed is silent on a schedule; at a constant 1e-3 the
    count net's training accuracy creeps up by ~0.5 point an epoch after epoch 6, and the
    moving average alone does not settle it.  A function of (epoch, batch) only, so a resumed
    run gets the same rate as an uninterrupted one."""
    start = cfg.epochs - cfg.anneal
    if cfg.anneal <= 0 or epoch < start:
        return cfg.lr
    t = min(1.0, ((epoch - start) * batches + batch) / max(cfg.anneal * batches, 1))
    floor = cfg.lr * ANNEAL_FLOOR
    return float(floor + (cfg.lr - floor) * 0.5 * (1 + np.cos(np.pi * t)))

Event = Callable[..., None]


@dataclass
class TrainConfig:
    task: str
    data: Path | list
    out: Path
    val: Path | None = None
    val_fraction: float = 0.1  # held out of --data when there is no --val
    epochs: int = 20
    batch_size: int = 32
    threads: int = 0
    seed: int = 0
    lr: float = 1e-3
    anneal: int = 0  # the last ``anneal`` epochs lower the learning rate to lr * ANNEAL_FLOOR (cosine, per step)
    checkpoint: Path | None = None  # default: OUT with suffix .ckpt.pt
    checkpoint_minutes: float = 5.0
    resume: bool = True
    augment: bool = True
    channels_last: bool = True  # measured faster on CPU (bench/bench_train.py)
    buffer_windows: int = 2048
    min_snr_db: float | None = None  # drop training windows whose movers are fainter than this
    ema: float = 0.995  # per-step decay of the weight average (0: no averaging)
    select: str = "last"  # export the last epoch's weights, or the "best" on validation
    superpose: float = 0.0  # count: fraction of windows summed with another (augment.superpose)
    preprocessing: str = NORMALIZATION  # which normalize_window the net is trained on (the card records it)
    init: Path | None = None  # an exported model (.onnx) whose weights training starts from
    arch: str = "seed"  # wallcli.train.nets.ARCHS
    balance: bool = False  # weight the loss by inverse class frequency of the training windows
    device: str = "cpu"  # torch device of the net and its batches ("cuda" on a GPU machine); results do not depend on it beyond float rounding

    def checkpoint_path(self) -> Path:
        return Path(self.checkpoint) if self.checkpoint else Path(self.out).with_suffix(".ckpt.pt")


def _to_tensor(x: np.ndarray, channels_last: bool, preprocessing: str = NORMALIZATION,
               offset: np.ndarray | None = None) -> torch.Tensor:
    from wallcli.signal.window import normalize_window

    t = torch.from_numpy(np.ascontiguousarray(normalize_window(x, preprocessing, offset), dtype=np.float32))
    return t.contiguous(memory_format=torch.channels_last) if channels_last else t


def evaluate(net: nn.Module, ds: ShardDataset, indices: np.ndarray, batch_size: int,
             channels_last: bool = False, preprocessing: str = NORMALIZATION, device: str = "cpu") -> dict[str, Any]:
    """Accuracy, mean loss and confusion matrix (rows: true class, columns: predicted)."""
    k = len(ds.classes)
    cm = np.zeros((k, k), np.int64)
    loss_sum = 0.0
    was_training = net.training
    net.eval()
    with torch.no_grad():
        for idx in ds.plan(indices, batch_size, np.random.default_rng(0), shuffle=False):
            b = ds.gather(idx)
            logits = net(*[_to_tensor(b[n], channels_last, preprocessing, b.get(OFFSETS[n])).to(device) for n in ds.inputs])
            y = torch.from_numpy(b["label"]).to(device)
            loss_sum += float(nn.functional.cross_entropy(logits, y, reduction="sum"))
            np.add.at(cm, (b["label"], logits.argmax(1).cpu().numpy()), 1)
    net.train(was_training)
    n = int(cm.sum())
    return {"windows": n, "accuracy": float(np.trace(cm) / n) if n else float("nan"),
            "loss": loss_sum / n if n else float("nan"), "confusion_matrix": cm.tolist()}


def _ema_update(ema: dict[str, torch.Tensor], net: nn.Module, decay: float) -> None:
    with torch.no_grad():
        for k, v in net.state_dict().items():
            if v.dtype.is_floating_point:
                ema[k].mul_(decay).add_(v.detach(), alpha=1 - decay)
            else:  # batch counters
                ema[k].copy_(v)


def _save_checkpoint(path: Path, state: dict[str, Any]) -> None:
    path.parent.mkdir(parents=True, exist_ok=True)
    tmp = path.with_name(f".{path.name}.tmp.{os.getpid()}")
    try:
        torch.save(state, tmp)
        os.replace(tmp, path)
    finally:
        if tmp.exists():
            tmp.unlink()


def _identity(cfg: TrainConfig, ds: ShardDataset) -> dict[str, Any]:
    # what must match for a checkpoint to be resumable into this run
    return {"task": cfg.task, "windows": ds.n, "dataset_seed": [m.get("seed") for m in ds.manifests], "ema": cfg.ema,
            "superpose": cfg.superpose, "seed": cfg.seed, "batch_size": cfg.batch_size, "min_snr_db": cfg.min_snr_db, "val_fraction": cfg.val_fraction if cfg.val is None else None,
            **({} if cfg.preprocessing == NORMALIZATION else {"preprocessing": cfg.preprocessing}),
            **({} if cfg.arch == "seed" else {"arch": cfg.arch}),
            **({"balance": True} if cfg.balance else {}),
            **({} if cfg.init is None else {"init": sha256_file(Path(cfg.init))}),
            **({} if cfg.lr == 1e-3 else {"lr": cfg.lr})}


def train(cfg: TrainConfig, on_event: Event | None = None) -> dict[str, Any]:
    """Train (or resume) and return {"net", "validation", "history", ...} for export."""
    emit = on_event or (lambda kind, **kw: None)
    if cfg.threads > 0:
        torch.set_num_threads(cfg.threads)
    torch.manual_seed(cfg.seed)
    inputs = list(build(cfg.task, cfg.arch).input_names)
    ds = ShardDataset(cfg.data, cfg.task, buffer_windows=cfg.buffer_windows, inputs=inputs)
    if cfg.val is not None:
        val_ds = ShardDataset(cfg.val, cfg.task, buffer_windows=cfg.buffer_windows, inputs=inputs)
        train_idx, val_idx = np.arange(ds.n), val_ds.usable(np.arange(val_ds.n))
    else:
        val_ds = ds
        train_idx, val_idx = split_validation(ds.n, cfg.val_fraction, cfg.seed)
        val_idx = ds.usable(val_idx)
    train_idx = ds.visible(ds.usable(train_idx), cfg.min_snr_db)
    if len(train_idx) < 2:
        raise WallcliError(f"{cfg.data} has too few windows to train on ({ds.n})")

    net = build(cfg.task, cfg.arch)
    ckpt_path = cfg.checkpoint_path()
    if cfg.init is not None and not (cfg.resume and ckpt_path.is_file()):  # a checkpoint replaces these weights
        from wallcli.train.init import init_from_onnx

        # 64 training windows set the batch-norm statistics the folded graph no longer has
        pick = np.sort(np.random.default_rng([cfg.seed, 0x1417]).choice(train_idx, min(64, len(train_idx)), replace=False))
        b = ds.gather(pick)
        init_from_onnx(net, cfg.init, [_to_tensor(b[n], False, cfg.preprocessing, b.get(OFFSETS[n])) for n in ds.inputs])
    dev = torch.device(cfg.device)
    net = net.to(dev)
    if cfg.channels_last:
        net = net.to(memory_format=torch.channels_last)
    opt = torch.optim.RMSprop(net.parameters(), lr=cfg.lr)
    weight = None
    if cfg.balance:
        # a rare class (waving, jumping: few of them visible) must not be traded for the common one
        counts = np.bincount(ds.labels()[train_idx], minlength=len(ds.classes)).astype(np.float64)
        weight = torch.tensor(np.where(counts > 0, counts.sum() / (len(counts) * np.maximum(counts, 1)), 0.0),
                              dtype=torch.float32, device=dev)
    loss_fn = nn.CrossEntropyLoss(weight=weight)
    ident = _identity(cfg, ds)
    epoch, start_batch, history, step = 0, 0, [], 0
    ema = {k: v.detach().clone() for k, v in net.state_dict().items()} if cfg.ema > 0 else None
    best: dict[str, Any] = {"accuracy": -1.0, "epoch": None, "state": None, "validation": None}
    if cfg.resume and ckpt_path.is_file():
        try:
            ck = torch.load(ckpt_path, map_location="cpu", weights_only=True)  # data only, never code
        except Exception as e:  # a truncated or foreign file
            raise WallcliError(f"cannot read checkpoint {ckpt_path}: {e}", hint="delete it or pass --no-resume") from None
        if ck.get("format") != CKPT_FORMAT or ck.get("identity") != ident:
            raise WallcliError(f"checkpoint {ckpt_path} belongs to a different run ({ck.get('identity')})",
                               hint="use the same data, seed and batch size, or pass --no-resume to start over")
        net.load_state_dict(ck["model"])
        opt.load_state_dict(ck["optimizer"])
        epoch, start_batch, history, best = ck["epoch"], ck["batch"], ck["history"], ck["best"]
        step = ck.get("step", 0)
        if ema is not None:
            ema = {k: v.to(dev) for k, v in ck["ema"].items()}
        emit("resume", epoch=epoch, batch=start_batch, path=ckpt_path)

    def checkpoint(ep: int, batch: int) -> None:
        _save_checkpoint(ckpt_path, {
            "format": CKPT_FORMAT, "version": 1, "identity": ident, "config": {k: str(v) for k, v in asdict(cfg).items()},
            "model": net.state_dict(), "optimizer": opt.state_dict(), "epoch": ep, "batch": batch,
            "history": history, "best": best, "step": step, "ema": ema, "torch": str(torch.__version__)})
        emit("checkpoint", path=ckpt_path, epoch=ep, batch=batch)

    last_ckpt = time.monotonic()
    net.train()
    while epoch < cfg.epochs:
        batches = ds.plan(train_idx, cfg.batch_size, np.random.default_rng([cfg.seed, epoch]))
        emit("epoch_start", epoch=epoch, epochs=cfg.epochs, batches=len(batches), done=start_batch)
        seen = correct = 0
        loss_sum = 0.0
        t0 = time.monotonic()
        next_batch = start_batch
        try:
            for bi in range(start_batch, len(batches)):
                b = ds.gather(batches[bi])
                if cfg.superpose > 0:
                    b = superpose(b, ds.inputs, np.random.default_rng([cfg.seed, epoch, bi, 0x5AB]), cfg.superpose)
                if cfg.augment:
                    b = augment(b, ds.inputs, np.random.default_rng([cfg.seed, epoch, bi, 0xA06]))
                xs = [_to_tensor(b[n], cfg.channels_last, cfg.preprocessing, b.get(OFFSETS[n])).to(dev, non_blocking=True)
                      for n in ds.inputs]
                y = torch.from_numpy(b["label"]).to(dev)
                for g in opt.param_groups:
                    g["lr"] = learning_rate(cfg, epoch, bi, len(batches))
                opt.zero_grad(set_to_none=True)
                logits = net(*xs)
                loss = loss_fn(logits, y)
                if not torch.isfinite(loss):
                    raise WallcliError(f"training diverged (loss {float(loss)}) at epoch {epoch + 1} batch {bi + 1}")
                loss.backward()
                opt.step()
                step += 1
                if ema is not None:
                    _ema_update(ema, net, min(cfg.ema, (1 + step) / (10 + step)))
                next_batch = bi + 1
                n = len(y)
                seen += n
                loss_sum += float(loss.detach()) * n
                correct += int((logits.argmax(1) == y).sum())
                emit("step", epoch=epoch, batch=bi + 1, batches=len(batches), loss=loss_sum / seen, accuracy=correct / seen)
                if time.monotonic() - last_ckpt > cfg.checkpoint_minutes * 60:
                    checkpoint(epoch, bi + 1)
                    last_ckpt = time.monotonic()
        except KeyboardInterrupt:
            # resume after the last completed step; the epoch's running loss/accuracy restart
            checkpoint(epoch, next_batch)
            raise
        eval_net = net
        if ema is not None:
            eval_net = copy.deepcopy(net)
            eval_net.load_state_dict(ema)
        val = (evaluate(eval_net, val_ds, val_idx, max(cfg.batch_size, 64), cfg.channels_last, cfg.preprocessing, dev)
               if len(val_idx) else None)
        rec = {"epoch": epoch + 1, "train_loss": loss_sum / seen if seen else None,
               "train_accuracy": correct / seen if seen else None, "lr_end": opt.param_groups[0]["lr"], "train_windows_per_s": seen / max(time.monotonic() - t0, 1e-9),
               "val_accuracy": val["accuracy"] if val else None, "val_loss": val["loss"] if val else None}
        history.append(rec)
        if cfg.select == "last" or val is None or val["accuracy"] > best["accuracy"]:
            best = {"accuracy": val["accuracy"] if val else -1.0, "epoch": epoch + 1,
                    "state": copy.deepcopy(eval_net.state_dict()), "validation": val}
        epoch, start_batch = epoch + 1, 0
        emit("epoch_end", **rec)
        checkpoint(epoch, 0)
        last_ckpt = time.monotonic()

    if best["state"] is not None:
        net.load_state_dict(best["state"])
    net = net.to("cpu")  # export, quantisation and the card's evaluation run on the CPU
    net.eval()
    return {"net": net, "dataset": ds, "val_dataset": val_ds if cfg.val is not None else None,
            "validation": best["validation"], "best_epoch": best["epoch"], "history": history,
            "train_windows": int(len(train_idx)), "val_windows": int(len(val_idx)),
            "train_indices": train_idx, "val_indices": val_idx, "eval_dataset": val_ds}
