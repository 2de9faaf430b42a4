"""What window labels from the motion-capture truth would change (issue 53, item 2).

For every harvested window (stride 16, 256 samples) of a recording with truth (t061 on): how many
people move in it by the truth (a person moves in a window when their body box or place changes on
at least a quarter of its samples), against the clip's label, and for windows of rooms with people,
the share of the window someone is in front of the view. Pure counting; nothing is fitted.

    python research/recordings/window_truth.py
"""
from __future__ import annotations

import collections
import sys
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))
sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "track"))
from common import recordings  # noqa: E402
from data import truth_x  # noqa: E402
from wallcli.train.recordings import WINDOW  # noqa: E402


def main() -> None:
    same, differ, inview = 0, collections.Counter(), []
    for r in recordings():
        tx = truth_x(r.name, r.frames)
        if tx is None:
            continue
        x, moving, acts = tx
        for s in r.starts:
            k = int((moving[:, s:s + WINDOW].mean(axis=1) >= 0.25).sum()) if len(moving) else 0
            if k == r.people:
                same += 1
            else:
                differ[(r.people, k, r.activity)] += 1
            if r.people:
                xs = x[:, s:s + WINDOW]
                inview.append((float(((xs >= 0) & (xs <= 1)).any(axis=0).mean()), r.activity))
    print(f"windows whose truth count equals the clip's label: {same} of {same + sum(differ.values())}")
    for (lab, k, act), n in sorted(differ.items()):
        print(f"  label {lab} ({act}), truth says {k} moving: {n} windows")
    f = np.array([v for v, _ in inview])
    print(f"windows of rooms with people: {len(f)}; someone in front of the view for a share of the window: "
          f"quartiles {np.percentile(f, [25, 50, 75]).round(2).tolist()}; never: {int((f == 0).sum())} "
          f"({dict(collections.Counter(a for v, a in inview if v == 0))})")


if __name__ == "__main__":
    main()
