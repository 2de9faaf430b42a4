"""Training throughput (windows/s) of the seed's nets on this CPU.

    .venv/bin/python bench/bench_train.py [--task count|activity] [--batch 32] [--threads 2]
        [--channels-last] [--compile] [--steps 10]

Measures full optimisation steps (forward, cross-entropy, backward, RMSProp) on random
inputs after warm-up steps; data loading and augmentation are not included.
"""
from __future__ import annotations

import argparse
import time

import torch
from torch import nn

from wallcli.train.nets import build


def main() -> None:
    ap = argparse.ArgumentParser()
    ap.add_argument("--task", default="count", choices=["count", "activity"])
    ap.add_argument("--batch", type=int, default=32)
    ap.add_argument("--threads", type=int, default=2)
    ap.add_argument("--steps", type=int, default=10)
    ap.add_argument("--warmup", type=int, default=2)
    ap.add_argument("--channels-last", action="store_true")
    ap.add_argument("--compile", action="store_true")
    a = ap.parse_args()
    torch.set_num_threads(a.threads)
    net = build(a.task)
    fmt = torch.channels_last if a.channels_last else torch.contiguous_format
    net = net.to(memory_format=fmt)
    opt = torch.optim.RMSprop(net.parameters(), lr=1e-3)
    loss_fn = nn.CrossEntropyLoss()
    n_in = 1 if a.task == "count" else 2
    xs = [torch.randn(a.batch, 3, 64, 256).contiguous(memory_format=fmt) for _ in range(n_in)]
    y = torch.randint(0, len(net.classes), (a.batch,))
    step_net = torch.compile(net) if a.compile else net

    def step() -> None:
        opt.zero_grad(set_to_none=True)
        loss = loss_fn(step_net(*xs), y)
        loss.backward()
        opt.step()

    for _ in range(a.warmup):
        step()
    t0 = time.perf_counter()
    for _ in range(a.steps):
        step()
    dt = time.perf_counter() - t0
    print(f"{a.task} batch={a.batch} threads={a.threads} channels_last={a.channels_last} "
          f"compile={a.compile}: {a.steps * a.batch / dt:.1f} windows/s ({dt / a.steps * 1000:.0f} ms/step)")


if __name__ == "__main__":
    main()
