"""The tracks drawn over the horizontal plots of recordings with motion-capture truth (truth dotted).

    python research/track/draw.py OUT.png NAME...   (e.g. t122_p1_walking.mp4 t206_p1_walking.mp4)
"""
from __future__ import annotations

import sys
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

sys.path.insert(0, str(Path(__file__).resolve().parent))
from data import clips  # noqa: E402
from wallcli.signal.track import darkness, track_rows  # noqa: E402
from wallcli.train.recordings import FPS  # noqa: E402


def main() -> None:
    out, names = Path(sys.argv[1]), sys.argv[2:]
    cs = {c.name: c for c in clips() if c.name in names}
    fig, axes = plt.subplots(len(names), 1, figsize=(11, 2.3 * len(names)), squeeze=False)
    for ax, name in zip(axes[:, 0], names):
        c = cs[name]
        T = c.h.shape[0]
        t = np.arange(T) / FPS
        d = -darkness(c.h, FPS)
        lim = np.percentile(np.abs(d), 99)
        ax.imshow(d.T, aspect="auto", cmap="gray", vmin=-lim, vmax=lim, extent=(0, t[-1], 1, 0))
        for k, x in enumerate(c.x):
            ax.plot(t[::6], x[::6], ".", ms=2, color="yr"[k % 2], label=f"truth {k} ({c.activities[k]})")
        for k in track_rows(c.h, t, FPS):
            ax.plot(k.t, k.x, "-", lw=1.5, color="cyan")
        ax.set_ylim(1, 0)
        ax.set_title(f"{name}  snr {c.snr_db}  (cyan: tracks; dots: truth)", fontsize=8, loc="left")
        ax.legend(fontsize=6, loc="upper right")
    fig.tight_layout()
    fig.savefig(out, dpi=70)


if __name__ == "__main__":
    main()
