import sys, glob, csv, numpy as np, matplotlib; matplotlib.use("Agg"); import matplotlib.pyplot as plt
from wallcli.io.arrays import load_npz
from wallcli.signal.stplot import FORMAT, from_arrays
from wallcli.signal.window import resample
labs = {r["file"][:-4]: r for r in csv.DictReader(open("/work/shared/transfer/labels.csv"))}
names = sys.argv[2:]
fig, axes = plt.subplots(len(names), 2, figsize=(12, 1.6*len(names)))
for ax, n in zip(axes, names):
    p = from_arrays(*load_npz(f"data/tp/{n}.npz", kind=FORMAT))
    for a, arr, nm in ((ax[0], p.horizontal, "H"), (ax[1], p.vertical, "V")):
        g = arr[..., 1]
        s = np.percentile(np.abs(g), 99) + 1e-9
        a.imshow(g, aspect="auto", cmap="RdBu", vmin=-s, vmax=s)
        r = labs[n]
        a.set_title(f"{n} {nm} sig={r['signal']} {r['lighting']} crf={r['crf']} fs={s:.3f}", fontsize=7)
        a.set_xticks([]); a.set_yticks([])
plt.tight_layout(); plt.savefig(sys.argv[1], dpi=int(__import__("os").environ.get("DPI", 70)))
