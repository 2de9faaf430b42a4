"""Horizontal and vertical space-time plots (green, temporal mean removed, each scaled to its own
99th percentile: `fs`, in 8-bit codes) of any stplot outputs, one row each, e.g. transfer walkers
above simulated ones (walkers_vs_sim.jpg):

    python research/transfer/draw_compare.py out.png data/tp/t020_p1_walking.npz data/cmp/w3.npz ...
"""
import sys, numpy as np, matplotlib; matplotlib.use("Agg"); import matplotlib.pyplot as plt
from wallcli.io.arrays import load_npz
from wallcli.signal.stplot import FORMAT, from_arrays
paths = sys.argv[2:]
fig, axes = plt.subplots(len(paths), 2, figsize=(12, 1.5 * len(paths)))
for ax, n in zip(axes, paths):
    p = from_arrays(*load_npz(n, kind=FORMAT))
    for a, arr, nm in ((ax[0], p.horizontal, "H"), (ax[1], p.vertical, "V")):
        g = arr[..., 1] - arr[..., 1].mean(axis=1, keepdims=True)
        s = np.percentile(np.abs(g), 99) + 1e-9
        a.imshow(g, aspect="auto", cmap="RdBu", vmin=-s, vmax=s)
        a.set_title(f"{n.split('/')[-1]} {nm} fs={s:.3f}", fontsize=7)
        a.set_xticks([]); a.set_yticks([])
plt.tight_layout(); plt.savefig(sys.argv[1], dpi=60)
