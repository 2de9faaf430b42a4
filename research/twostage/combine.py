"""Count from both nets: is anybody there (two detectors), then how many (the count net).

The seed's count net reads the horizontal plot only; a person crouching, waving or jumping in
place shows mostly in the vertical plot and as a whole-wall flicker, which that net reads as
nobody or as two. The activity net reads both plots. Two-stage answer, fixed before any
measurement (no parameter is fitted):

  stage 1, presence: the two nets are two detectors of 'nobody moves' (count p(0), activity
      p(none)); their evidence is combined as a product of experts with even priors,
      p_nobody = a b / (a b + (1 - a)(1 - b)); nobody when p_nobody > 1/2;
  stage 2, how many: one or two by the count net's p(1) against p(2).

    python research/twostage/combine.py runs/ans_transfer.json [runs/ans_proxy.json ...]
    python research/twostage/combine.py --sim data/steady62        # simulated windows, one clip = one scene

Prints, per input, clips right by band for the count net alone and for the two-stage answer,
and the paired difference (clips gained / lost, exact McNemar p).
"""
from __future__ import annotations

import argparse
import json
import math
from pathlib import Path

import numpy as np

BANDS = (("empty", None, None), ("<0 dB", None, 0.0), ("0-10 dB", 0.0, 10.0), (">=10 dB", 10.0, None))


TWO_ODDS = [1.0]


def two_stage(pc: np.ndarray, pa: np.ndarray) -> np.ndarray:
    """Count answers (n,) from count probabilities (n, 3) and activity probabilities (n, 5), as
    `wallcli count` answers them (wallcli/infer/twostage.py; --two-odds: the prior odds of two
    people against one)."""
    from wallcli.infer.twostage import combine

    return combine(pc, pa, TWO_ODDS[0]).argmax(1)


def band_of(people: int, snr) -> str:
    if people == 0:
        return "empty"
    if snr is None or snr < 0:
        return "<0 dB"
    return "0-10 dB" if snr < 10 else ">=10 dB"


def mcnemar(gain: int, loss: int) -> float:
    n = gain + loss
    if n == 0:
        return 1.0
    k = min(gain, loss)
    return min(1.0, 2 * sum(math.comb(n, i) for i in range(k + 1)) / 2**n)


def report(name: str, truth, bands, detect, answers: dict) -> None:
    print(f"\n{name}: {len(truth)} clips, {int(detect.sum())} detectable")
    print(f"{'':12s} " + " ".join(f"{b:>9s}" for b, _, _ in BANDS) + "   detectable")
    for label, ans in answers.items():
        ok = ans == truth
        cells = [f"{int(ok[bands == b].sum())}/{int((bands == b).sum())}" for b, _, _ in BANDS]
        print(f"{label:12s} " + " ".join(f"{c:>9s}" for c in cells) + f"   {int(ok[detect].sum())}/{int(detect.sum())}")
    (la, a), (lb, b) = list(answers.items())[:2]
    gain = int(((b == truth) & (a != truth) & detect).sum())
    loss = int(((b != truth) & (a == truth) & detect).sum())
    print(f"{lb} against {la}, detectable clips: +{gain} -{loss} (McNemar p = {mcnemar(gain, loss):.3f})")


def from_answers(path: str) -> None:
    d = json.loads(Path(path).read_text())
    rows = [r for r in d["rows"] if "error" not in r]
    truth = np.array([r["people"] for r in rows])
    pc = np.array([r["count"] for r in rows])
    pa = np.array([r["activity_p"] for r in rows])
    snr = [r["snr_db"] if r["snr_db"] is not None else r["count_signal_db"] for r in rows]
    bands = np.array([band_of(r["people"], s) for r, s in zip(rows, snr)])
    det = np.array([r["detectable"] if r["detectable"] is not None else (r["people"] == 0 or s >= 0)
                    for r, s in zip(rows, snr)], bool)
    report(f"{path} (snr: {'labels' if rows and rows[0]['snr_db'] is not None or any(r['snr_db'] for r in rows) else 'measured'})",
           truth, bands, det, {"count net": pc.argmax(1), "two-stage": two_stage(pc, pa)})


def from_sim(folder: str, count_model=None, activity_model=None) -> None:
    """Simulated windows: each scene's windows averaged, as the commands do for a clip; the
    band is the least visible mover's SNR in the recorded plot (the simulator's own measure)."""
    from wallcli.datagen.dataset import SHARD_FORMAT
    from wallcli.infer.model import load_model
    from wallcli.io.arrays import load_npz

    shards = [load_npz(f, kind=SHARD_FORMAT) for f in sorted(Path(folder).glob("shard-*.npz"))]
    offsets = {"horizontal": "h_offset", "vertical": "v_offset"}
    probs = {}
    for task, path in (("count", count_model), ("activity", activity_model)):
        m = load_model(task, path)
        probs[task] = np.concatenate([m.predict({n: m.normalize(a[n].astype(np.float32), a[offsets[n]].astype(np.float32))
                                                 for n in m.input_names}) for a, _ in shards])
    label = np.concatenate([a["label"] for a, _ in shards])
    weakest = np.concatenate([a["snr_db_weakest"] for a, _ in shards])
    scene = np.concatenate([[f"{s['seed']}:{s['index']}" for s in meta["scenes"]] for _, meta in shards])
    keys = sorted(set(scene))
    idx = [np.flatnonzero(scene == k) for k in keys]
    pc = np.array([probs["count"][j].mean(0) for j in idx])
    pa = np.array([probs["activity"][j].mean(0) for j in idx])
    truth = np.array([label[j[0]] for j in idx])
    snr = [float(np.nanmean(weakest[j])) if truth[n] else None for n, j in enumerate(idx)]
    bands = np.array([band_of(t, s) for t, s in zip(truth, snr)])
    det = np.array([t == 0 or s >= 0 for t, s in zip(truth, snr)])
    report(f"{folder} (scenes; the simulator's plot SNR)", truth, bands, det,
           {"count net": pc.argmax(1), "two-stage": two_stage(pc, pa)})


def main(argv=None) -> int:
    ap = argparse.ArgumentParser()
    ap.add_argument("answers", nargs="*")
    ap.add_argument("--sim", action="append", default=[])
    ap.add_argument("--two-odds", type=float, default=1.0)
    a = ap.parse_args(argv)
    TWO_ODDS[0] = a.two_odds
    for p in a.answers:
        from_answers(p)
    for s in a.sim:
        from_sim(s)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
