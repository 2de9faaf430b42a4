"""Approach C: 14 physical features of each window (7 per plot), logistic regression, out of fold."""
import sys
import numpy as np
sys.path.insert(0, __import__('os').path.dirname(__file__))
from common import *
from wallcli.signal.window import window_signal_db


def plot_features(w, off):
    x = w.mean(-1)  # (n, bins, T): colours averaged
    x = x - x.mean(2, keepdims=True)
    db = window_signal_db([(w, off)])
    tot = (x ** 2).mean((1, 2)) + 1e-20
    g = x.mean(1)  # whole-wall signal (n, T)
    share = (g ** 2).mean(1) / tot
    s = np.linalg.svd(x, compute_uv=False)
    e = s ** 2 / (s ** 2).sum(1, keepdims=True)
    spec = np.abs(np.fft.rfft(g - g.mean(1, keepdims=True), axis=1)) ** 2
    spec[:, 0] = 0
    k = spec.argmax(1)
    peak = spec.max(1) / (spec.sum(1) + 1e-20)
    freq = k * 30.0 / x.shape[2]
    d = np.diff(x, axis=2)
    change = (d ** 2).mean((1, 2)) / tot
    return np.stack([db, share, e[:, 0], e[:, 1], peak, freq, np.log(change + 1e-9)], 1)


if __name__ == "__main__":
    recs = recordings()
    F = np.concatenate([np.concatenate([plot_features(r.horizontal, r.h_offset), plot_features(r.vertical, r.v_offset)], 1)
                        for r in recs]).astype(np.float32)
    E = dict(np.load(ROOT / "runs" / "emb.npz"))
    E["feat"] = F
    np.savez(ROOT / "runs" / "emb.npz", **E)
    print("ok", F.shape, np.isfinite(F).all())
