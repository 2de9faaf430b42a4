"""Temporal noise reduction found in the decode: where it is, ``signal_db`` is an upper bound.

Phones and DVRs blend each frame with the previous output on still scenes (``out = a prev +
(1 - a) in``). The slow light a person casts passes almost untouched; the sensor noise comes out
correlated from frame to frame, and every noise figure here (half the mean square of consecutive
differences, paper suppl. §3.2) assumes it is not: a blend of 0.45-0.8 read ``signal_db`` 2-13 dB
too high on the transfer set's strong clips (research/pipelines/README_tnr_awb.md).

Measured where no signal is: the differences between luma pixels two columns apart (a wall's
light, a shadow, a gain change both alike; each pixel's noise is its own), in small tiles spread
over the frame. Per tile, ``d_k`` = the mean square of the change over k frames; for noise
independent from frame to frame ``d_2 = d_1``, for a recursive blend ``d_2 / d_1 = 1 + a``. The
median over the tiles of ``d_2 / d_1 - 1`` (a tile a shadow's edge crosses is an outlier) is the
noise's lag-1 autocorrelation ``lag1``.

Why it is not corrected: the blend cannot be told from noise that is correlated by itself.
An independent renderer's clean lossless clips measured lag1 up to 0.33 (its noise varies
slowly), its lossy ones up to 1.1 (a codec holds whole blocks' noise from frame to frame), and
undoing a blend of 0.8 after 8-bit rounding multiplies the rounding's noise by 60. So a clip
whose lag1 reaches MIN_LAG1 gets ``{"kind": "temporal_nr", "lag1", "bound": true}`` and no
answer is decided on its figure; a clip whose codec holds blocks (HELD of 8x8 luma blocks
unchanged from one frame to the next; a sensor's noise changes every pixel) is not judged.
"""

from __future__ import annotations

import numpy as np

TILE = 16  # tiles of TILE x TILE luma pixel differences
MAX_TILES = 64
MIN_FRAMES = 32  # frame pairs measured before anything is said
MIN_LAG1 = 0.4  # from here the noise is taken as blended (the transfer set's clean clips: <= 0.33;
# blends of 0.45-0.8 on its lossless strong clips: 0.27-0.82, most above 0.4)
HELD = 0.001  # share of 8x8 blocks held unchanged from which a codec, not the camera, set the noise
# (the transfer set: lossless 0, its CRF 10-14 clips 0.006-0.56; sensor noise of 0.35 codes: ~1e-14)


def _tiles(h: int, w: int, tile: int = TILE, max_tiles: int = MAX_TILES) -> list[tuple[int, int]]:
    """Top-left corners of up to ``max_tiles`` tiles of ``tile`` px spread over an (h, w) plane,
    4 px from its edges."""
    ny, nx = max((h - 8) // tile, 0), max((w - 10) // tile, 0)
    if not ny or not nx:
        return []
    gy = int(min(ny, max(1, round(np.sqrt(max_tiles * ny / nx)))))
    gx = int(min(nx, max(1, max_tiles // gy)))
    ys = np.linspace(4, h - 4 - tile, gy).astype(int)
    xs = np.linspace(4, w - 6 - tile, gx).astype(int)
    return [(int(y), int(x)) for y in ys for x in xs]


class TemporalNoise:
    """A frame tap (``FrameTee``) measuring how correlated the noise is from one frame to the next.

    Memory: three sampled tile stacks, whatever the length. A gap in the timestamps starts a new
    run (a difference across it is not one frame's).
    """

    def __init__(self) -> None:
        self._corners = None
        self._shape = None
        self._hist: list = []  # the last two frames' (tiles, luma, differences)
        self._d = None  # (2, tiles): sums of squared changes over 1 and 2 frames
        self.pairs = 0
        self._blocks = self._held = 0
        self._flat = self._flat_for = None  # the tiles' offsets in a plane's memory, for its row spacing

    def __call__(self, frame) -> None:
        y = frame.planes.y
        if self._corners is None:
            self._corners, self._shape = _tiles(*y.shape), y.shape
            self._d = np.zeros((2, len(self._corners)))
            r, c = (np.array([k[i] for k in self._corners], np.intp).reshape(-1, 1, 1) for i in (0, 1))
            self._at = (r + np.arange(TILE).reshape(1, -1, 1), c + np.arange(TILE + 2).reshape(1, 1, -1))
        if not self._corners or y.shape != self._shape:
            return
        if getattr(frame, "gap", 0.0):
            self._hist = []
        # every tile in one gather, in the plane's own integer codes: the differences and their
        # squares are exact integers, summed as integers (the same sums), a few numpy calls a frame
        luma = self._gather(y)
        z = luma[:, :, 2:].astype(np.int32) - luma[:, :, :-2]
        if self._hist:
            prev_luma, prev_z = self._hist[-1]
            # 8x8 blocks with no sample changed: each block row's 8 comparisons read as one 64-bit word
            changed = np.not_equal(luma[:, :, :TILE], prev_luma[:, :, :TILE]).view(np.uint64)
            moved = np.count_nonzero(changed.reshape(len(z), TILE // 8, 8, TILE // 8).any(axis=2))
            self._blocks += len(z) * (TILE // 8) ** 2
            self._held += len(z) * (TILE // 8) ** 2 - int(moved)
            if len(self._hist) == 2:
                wide = np.int32 if y.dtype == np.uint8 else np.int64  # (8 bits: 256 squares of 510 at most)
                for k, before in ((0, prev_z), (1, self._hist[0][1])):
                    dz = (z - before).astype(wide, copy=False)
                    self._d[k] += np.einsum("ijk,ijk->i", dz, dz)
                self.pairs += 1
        self._hist = (self._hist + [(luma, z)])[-2:]

    def _gather(self, y: np.ndarray) -> np.ndarray:
        """The tiles' luma (tiles, TILE, TILE + 2): a take of precomputed offsets into the plane's
        memory where its rows are evenly spaced (a decoder's plane), else an index of the plane."""
        item = y.itemsize
        if y.strides[1] != item or y.strides[0] % item or y.strides[0] < y.shape[1] * item:
            return y[self._at]
        if self._flat_for != y.strides[0]:
            self._flat_for = y.strides[0]
            self._flat = (self._at[0] * (y.strides[0] // item) + self._at[1]).astype(np.intp)
        if y.flags.c_contiguous:
            return np.take(y.reshape(-1), self._flat)
        rows = y.strides[0] // item  # (a padded row: the plane's memory to its last sample, as one row)
        flat = np.lib.stride_tricks.as_strided(y, shape=((y.shape[0] - 1) * rows + y.shape[1],), strides=(item,))
        return np.take(flat, self._flat)

    def lag1(self) -> float | None:
        """The noise's lag-1 autocorrelation (median over the tiles), None before MIN_FRAMES or
        where a codec holds blocks."""
        if self.pairs < MIN_FRAMES or not self._blocks or self._held > HELD * self._blocks:
            return None
        ok = self._d[0] > 0
        if not ok.any():
            return None
        return float(np.median(self._d[1, ok] / self._d[0, ok]) - 1.0)

    def correction(self) -> dict | None:
        """The ``corrections`` entry (docs/contract.md), None when the noise is not blended."""
        r = self.lag1()
        if r is None or r < MIN_LAG1:
            return None
        return {"kind": "temporal_nr", "lag1": round(r, 3), "bound": True}


REASON = ("signal_db is an upper bound: the noise is correlated from frame to frame (temporal noise "
          "reduction, lag-1 {lag1:.2f}), which the noise estimate assumes it is not")


def bound_result(result: dict, found: dict | None) -> dict:
    """``result`` (a count/activity clip object) with ``found`` listed under ``corrections`` and,
    where the figure is only an upper bound, no answer decided on it (clip and windows)."""
    if not found:
        return result
    result["corrections"].append(found)
    if found.get("bound"):
        reason = REASON.format(lag1=found["lag1"])
        for rec in [result, *result.get("windows", [])]:
            # a view that is no wall keeps its reason; any other quoted the inflated figure
            if (rec.get("view") or {}).get("usable", True):
                rec["confident"], rec["reason"] = False, reason
    return result
