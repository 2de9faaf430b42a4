"""Median clean signal of simulated 'wide' scenes per activity and lighting, to set beside the
transfer set's labels.csv (its `signal` column: the clean wall's column-profile relative std).

    python research/transfer/sim_signal.py [SCENES_PER_ACTIVITY]

Compares distributions only: no transfer clip is read here.
"""

import sys

import numpy as np

from wallcli.sim.scene import SceneConfig, sample_scene


def lighting(room) -> str:
    kinds = {s for s, *_ in room.windows}
    lamps = len(room.lamp_radius) > 0
    if not kinds:
        return "lamps"
    if kinds == {4}:
        return "ceiling" + ("+lamps" if lamps else "")
    return ("ceiling_window" if 4 in kinds else "window") + ("+lamps" if lamps else "")


def signal(seed: int, activity: str) -> tuple[str, float]:
    cfg = SceneConfig(people=1, activities=[activity], duration=6.0, fps=15, grid=(12, 16), domain="wide",
                      distance=(1.0, 5.0), roam=2.0, nuisance_p=0.0)
    sc = sample_scene(seed, cfg)
    sc.clean_profiles = []
    for _ in sc.frames():
        pass
    cols = np.array([p[0][:, 1] for p in sc.clean_profiles])  # (T, gx) green relative change
    # the std over columns and time of the change the people make, their still presence included
    # (labels.csv gives people standing still signals up to 1.6e-3, so its measure includes it),
    # and the part that moves (the temporal mean removed), which is what a detector sees
    return lighting(sc.room), float(cols.std()), float((cols - cols.mean(axis=0)).std())


def main(n: int) -> None:
    for act in ("walking", "crouching", "waving", "jumping"):
        rows = [signal(1000 + i, act) for i in range(n)]
        by = {}
        for k, v, _ in rows:
            by.setdefault(k, []).append(v)
        med, moving = np.median([r[1] for r in rows]), np.median([r[2] for r in rows])
        print(f"{act:10s} median {med:.1e} (moving part {moving:.1e})  "
              + "  ".join(f"{k} {np.median(v):.1e} (n={len(v)})" for k, v in sorted(by.items())))


if __name__ == "__main__":
    main(int(sys.argv[1]) if len(sys.argv) > 1 else 12)
