"""A DVR's nominal-rate padding: frames replaced by copies of the one before (``simulate --dup-frames``).

A recorder that captures fewer frames than the rate it writes repeats the last captured frame to
fill the slots; the frame the camera would have captured there is lost. Copies come in runs (a
stall of a few frame slots), never on the first frame.
"""

from __future__ import annotations

from typing import Iterable, Iterator

import numpy as np

MAX_RUN = 3  # longest run of copies; runs are 1..MAX_RUN slots long, 2 on average


def dup_mask(n: int, share: float, rng: np.random.Generator) -> np.ndarray:
    """(n,) bool: True where a frame is a copy of the one before, about ``share`` of them."""
    mask = np.zeros(n, bool)
    if share <= 0 or n < 2:
        return mask
    mean_run = (1 + MAX_RUN) / 2
    # a run starts after a captured frame with this chance, so copies make up `share` of all slots
    start = min(share / (mean_run * (1 - share)), 1.0)
    i = 1
    while i < n:
        if rng.random() < start:
            run = int(rng.integers(1, MAX_RUN + 1))
            mask[i:i + run] = True
            i += run + 1  # a captured frame follows every run
        else:
            i += 1
    return mask


def pad_frames(frames: Iterable[np.ndarray], mask: np.ndarray) -> Iterator[np.ndarray]:
    """``frames`` with every slot that ``mask`` marks replaced by the last frame written."""
    last = None
    for i, frame in enumerate(frames):
        if last is not None and i < mask.size and mask[i]:
            yield last
            continue
        last = np.array(frame)  # a world may hand out a buffer it reuses
        yield frame
