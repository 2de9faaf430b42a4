"""Is there anything to find in a window whose mover is under -10 dB? A check without a net.

    .venv/bin/python research/visibility_bound.py data/val_count4 [--task count]

A detector that knows where the people's light lives (the visible windows put 80-90 % of their
power below ~1 Hz in time and ~3 cycles across the 64 positions, where the camera's white noise
puts little) scores each window by its power in that low band, in absolute terms and as a share
of the window's power. Its AUC (0.5 = chance, 1 = perfect) for telling windows with nobody
moving from windows with movers in each SNR band shows how much signal the plots still hold
there, independently of any trained model. The bands here are of all movers' signal together
(``snr_db``): the question is whether anyone shows at all.
"""
from __future__ import annotations

import argparse

import numpy as np

from wallcli.train.data import ShardDataset
from wallcli.train.metrics import SNR_EDGES


def auc(neg: np.ndarray, pos: np.ndarray) -> float:
    """P(score of a positive > score of a negative), ties counting half."""
    if len(neg) == 0 or len(pos) == 0:
        return float("nan")
    d = pos[:, None] - neg[None, :]
    return float((d > 0).mean() + 0.5 * (d == 0).mean())


def band_scores(x: np.ndarray, fps: float = 30.0, max_cycles: int = 3, max_hz: float = 1.0) -> tuple[np.ndarray, np.ndarray]:
    """(log power in the low band, its share of the window's power) per window of (n, bins, T, 3)."""
    x = x.astype(np.float64)
    x = x - x.mean(axis=2, keepdims=True)
    spec = np.abs(np.fft.fft(np.fft.rfft(x, axis=2), axis=1)) ** 2  # (n, spatial freq, temporal freq, 3)
    ft = np.fft.rfftfreq(x.shape[2], 1.0 / fps)
    fs = np.abs(np.fft.fftfreq(x.shape[1], 1.0 / x.shape[1]))
    low = spec[:, fs <= max_cycles][:, :, ft <= max_hz].sum(axis=(1, 2, 3))
    total = np.maximum(spec.sum(axis=(1, 2, 3)), 1e-30)
    return np.log(np.maximum(low, 1e-30)), low / total


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("data")
    ap.add_argument("--task", choices=["count", "activity"], default="count")
    a = ap.parse_args()
    ds = ShardDataset(a.data, a.task)
    # all movers together (snr_db), not the least visible one: the question is whether anyone shows
    vis = np.concatenate([np.load(f, allow_pickle=False)["snr_db"] for f in ds.files]).astype(np.float64)
    absolute, share = [], []
    for i in range(len(ds.files)):
        ab, sh = band_scores(ds._load_shard(i)["horizontal"])
        absolute.append(ab)
        share.append(sh)
    absolute, share = np.concatenate(absolute), np.concatenate(share)
    empty = np.isnan(vis)
    print(f"{a.data}: {int(empty.sum())} windows with nobody moving, {int((~empty).sum())} with movers")
    print("AUC of a low-band power detector, nobody moving vs movers whose signal (all together) is at:")
    for lo, hi in zip(SNR_EDGES[:-1], SNR_EDGES[1:]):
        sel = ~empty & (vis >= lo) & (vis < hi)
        if sel.any():
            print(f"  {lo:>6} .. {hi:<6} dB ({int(sel.sum()):4d} windows): absolute power {auc(absolute[empty], absolute[sel]):.2f}, "
                  f"share of power {auc(share[empty], share[sel]):.2f}")


if __name__ == "__main__":
    main()
