"""Is the seed count net's max over time what keeps it from telling one person from two?

    .venv/bin/python research/capacity.py train seed|flat|both DATA OUT.pt --epochs 6
    .venv/bin/python research/capacity.py eval VAL A.pt B.pt [C.pt ...] [--mean]

A control experiment, not a shippable model (seed notes §2 fix the head). ``seed`` is the
seed's CountNet; ``flat`` keeps its five conv blocks but replaces the max over the 13 time
steps by a linear layer over the whole 64 x 13 feature map, so the head knows which stretch of
the window holds what (two streaks that move together, or one after the other). ``both`` (session
11) is the activity net's shape with a 3-way head: a second trunk reads the vertical plot, so the
net sees the room's height as well as its width (a shadow cast by a second lamp falls at another
height than a second person's). All train with
the shipped recipe's settings (RMSProp 1e-3, ``--min-snr-db -10``, ``--superpose 0.25``,
augmentation, weight average; 2 % of DATA held out for the per-epoch line; one thread each, so
two runs share a 2-core machine; ``--threads`` for a run alone) and are scored in float32 on VAL. ``eval`` prints each one's
accuracy, visible-window accuracy, confusion and per-SNR figures, and the paired difference
(first minus second) on the visible windows with its scene-bootstrap interval; ``--mean`` also
scores the models' averaged probabilities (an ensemble) against the first model. Checkpoints
resume: running ``train`` again with more ``--epochs`` continues the same run.
"""
from __future__ import annotations

import argparse

import numpy as np
import torch
from torch import nn

import wallcli.train.loop as loop
from wallcli.infer.card import TASK_INPUTS
from wallcli.train.nets import FEATURES, SLOPE, ActivityNet, CountNet


class FlatCountNet(CountNet):
    """The seed's trunk; a head over the whole (64, 13) feature map instead of its max over time."""

    def __init__(self) -> None:
        super().__init__()
        self.head = nn.Sequential(nn.Flatten(), nn.Linear(FEATURES * 13, FEATURES), nn.LeakyReLU(SLOPE),
                                  nn.Linear(FEATURES, 3))

    def forward(self, horizontal: torch.Tensor) -> torch.Tensor:
        return self.head(self.trunk.feature_map(horizontal))


class TwoPlotCountNet(ActivityNet):
    """The activity net's two trunks and head, ending in 3 scores: count from both plots."""

    task = "count"

    def __init__(self) -> None:
        super().__init__()
        self.head[-1] = nn.Linear(32, 3)


def use_inputs(kind: str) -> None:
    # the data loader gathers the plots the task lists; "both" needs the vertical one too
    TASK_INPUTS["count"] = ["horizontal", "vertical"] if kind == "both" else ["horizontal"]


def make(kind: str) -> nn.Module:
    use_inputs(kind)
    return {"flat": FlatCountNet, "both": TwoPlotCountNet}.get(kind, CountNet)()


def train(kind: str, data: str, out: str, epochs: int, threads: int) -> None:
    use_inputs(kind)  # before loop.train opens the data set
    loop.build = lambda task: make(kind)
    cfg = loop.TrainConfig(task="count", data=data, out=out, val_fraction=0.02, epochs=epochs, threads=threads,
                           min_snr_db=-10.0, superpose=0.25, select="last", checkpoint=out + ".ckpt")

    def report(event: str, **kw) -> None:
        if event == "epoch_end":
            print({k: (round(v, 4) if isinstance(v, float) else v) for k, v in kw.items()}, flush=True)

    torch.save(loop.train(cfg, report)["net"].state_dict(), out)


def evaluate(val: str, paths: list[str], kinds: list[str], mean: bool = False) -> None:
    from wallcli.signal.window import normalize_window
    from wallcli.train.data import ShardDataset
    from wallcli.train.metrics import breakdown, paired_difference, visible_mask

    right, all_probs = [], []

    def report(name: str, p: np.ndarray, y: np.ndarray) -> None:
        r = breakdown(p, y, vis, scenes)
        right.append(p.argmax(1) == y)
        v = r["visible"]
        print(f"{name}: all {r['accuracy']:.1%}, visible {v['accuracy']:.1%} "
              f"({v['accuracy_95ci'][0]:.1%}-{v['accuracy_95ci'][1]:.1%}), {v['windows']} windows; "
              f"visible confusion {v['confusion_matrix']}")
        print("  by the least visible mover's SNR:",
              ", ".join(f"{b['snr_db']}: {b['accuracy']:.0%} ({b['windows']})" for b in r["accuracy_by_snr"]))

    for path, kind in zip(paths, kinds):
        net = make(kind)
        ds = ShardDataset(val, "count")
        vis, scenes = ds.visibility(), ds.scene_ids()
        net.load_state_dict(torch.load(path, weights_only=True))
        net.eval()
        probs, labels = [], []
        with torch.no_grad():
            for b in ds.plan(np.arange(ds.n), 128, np.random.default_rng(0), shuffle=False):
                g = ds.gather(b)
                xs = [torch.from_numpy(normalize_window(g[n])) for n in ds.inputs]
                probs.append(torch.softmax(net(*xs), 1).numpy())
                labels.append(g["label"])
        p, y = np.concatenate(probs), np.concatenate(labels)
        all_probs.append(p)
        report(f"{path} ({kind})", p, y)
    if mean:  # an ensemble: the models' probabilities averaged, compared with the first model
        report("mean of all", np.mean(all_probs, axis=0), y)
        right = [right[-1], right[0]]
    if len(right) == 2:
        seen = visible_mask(vis)
        d = paired_difference(right[0][seen], right[1][seen], scenes[seen])
        print(f"paired, visible windows, {'mean minus first' if mean else 'first minus second'}: "
              f"{d['difference']:+.1%} ({d['difference_95ci'][0]:+.1%} to {d['difference_95ci'][1]:+.1%})")


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    sub = ap.add_subparsers(dest="cmd", required=True)
    t = sub.add_parser("train")
    t.add_argument("kind", choices=["seed", "flat", "both"])
    t.add_argument("data")
    t.add_argument("out")
    t.add_argument("--epochs", type=int, default=6)
    t.add_argument("--threads", type=int, default=1)
    e = sub.add_parser("eval")
    e.add_argument("val")
    e.add_argument("--mean", action="store_true", help="also score the mean of the models' probabilities")
    e.add_argument("models", nargs="+", help="OUT.pt files; a name containing 'flat' is the flat head, "
                   "'both' the two-plot net")
    a = ap.parse_args()
    if a.cmd == "train":
        train(a.kind, a.data, a.out, a.epochs, a.threads)
    else:
        evaluate(a.val, a.models, ["flat" if "flat" in m else "both" if "both" in m else "seed" for m in a.models], a.mean)


if __name__ == "__main__":
    main()
