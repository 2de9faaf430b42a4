"""The tracker (wallcli/signal/track.py) against the rendered recordings' motion-capture truth.

For every recording with truth: the tracks of its horizontal plot (rebuilt from the cached inference
windows, research/track/data.py), and for single walkers the issue's two figures on the longest
track: Pearson r of its x with the true x at the same times, and its median absolute error (view
widths). Two-person evidence (``simultaneous``) is printed by class and band. The tracker has no
parameter fitted on the recordings except GEOMETRY_SIGMA, so its figures are out of fold as they
stand, except MAX_SPEED (research/track/tune.py) and GEOMETRY_SIGMA, whose fold-by-fold estimate (each
from the other folds) and out-of-fold coverage this prints.

    python research/track/evaluate.py [--json runs/track_eval.json]
"""
from __future__ import annotations

import argparse
import json
import sys
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))
from data import clips  # noqa: E402
from wallcli.signal.track import simultaneous, track_rows  # noqa: E402
from wallcli.train.recordings import FPS  # noqa: E402


def walker_figures(c, tracks):
    if not tracks:
        return None
    tr = max(tracks, key=lambda t: t.duration)
    t = np.asarray(tr.t)
    xt = np.interp(t, np.arange(c.x.shape[1]) / FPS, c.x[0])
    xe = np.asarray(tr.x)
    r = float(np.corrcoef(xe, xt)[0, 1]) if len(t) > 2 and np.std(xe) > 0 and np.std(xt) > 0 else 0.0
    sg = np.asarray(tr.sigma)
    return {"r": r, "err": float(np.median(np.abs(xe - xt))), "seconds": float(tr.duration), "n_tracks": len(tracks),
            "within_sigma": float(np.mean(np.abs(xe - xt) <= sg)), "abs_err": np.abs(xe - xt).tolist()}


def main() -> None:
    ap = argparse.ArgumentParser()
    ap.add_argument("--json", type=Path)
    a = ap.parse_args()
    rows = []
    for c in clips():
        T = c.h.shape[0]
        tracks = track_rows(c.h, np.arange(T) / FPS, FPS)
        row = {"file": c.name, "fold": c.fold, "people": c.people, "activities": c.activities, "band": c.band,
               "snr_db": c.snr_db, "detectable": c.detectable, "tracks": len(tracks),
               "simultaneous": simultaneous(tracks)}
        if c.people == 1 and c.activity == "walking":
            row["walker"] = walker_figures(c, tracks)
        rows.append(row)
    W = [r for r in rows if "walker" in r and r["detectable"]]
    rs = np.array([r["walker"]["r"] if r["walker"] else 0.0 for r in W])
    es = np.array([r["walker"]["err"] if r["walker"] else 1.0 for r in W])
    print(f"single walkers, detectable: {len(W)}; r >= 0.8 on {int((rs >= 0.8).sum())} "
          f"({(rs >= 0.8).mean():.0%}); median error <= 0.25 on {int((es <= 0.25).sum())} ({(es <= 0.25).mean():.0%}); "
          f"|r| >= 0.8 on {int((np.abs(rs) >= 0.8).sum())}")
    follows = [r for r in W if r["walker"] and r["walker"]["r"] >= 0.8]
    if follows:
        errs = np.concatenate([r["walker"]["abs_err"] for r in follows])
        cover = np.mean([r["walker"]["within_sigma"] for r in follows])
        print(f"walkers whose track follows them (r >= 0.8): 1.4826 x median |error| = {1.4826 * np.median(errs):.3f} "
              f"of the width; samples within their sigma: {cover:.0%} (68 % for a calibrated Gaussian)")
    # GEOMETRY_SIGMA: the 68th percentile of |error| over the other folds' walkers, and how often it covers
    with_w = [r for r in W if r["walker"]]
    got, n, fold_s = 0, 0, []
    for k in range(5):
        s = float(np.percentile(np.concatenate([r["walker"]["abs_err"] for r in with_w if r["fold"] != k]), 68))
        e = np.concatenate([r["walker"]["abs_err"] for r in with_w if r["fold"] == k])
        got, n = got + int(np.sum(e <= s)), n + len(e)
        fold_s.append(round(s, 3))
    print(f"geometry sigma by fold (68th percentile of |error|, other folds): {fold_s}; "
          f"out of fold it covers {got / n:.0%} of {n} samples")
    for r in W:
        w = r["walker"] or {}
        print(f"  {r['file']:22s} {r['band']:5s} r={w.get('r', float('nan')):+.2f} err={w.get('err', float('nan')):.2f} "
              f"tracks={r['tracks']}")
    for p in (0, 1, 2):
        for b in ("empty", "<0", "0-10", ">=10"):
            sel = [r for r in rows if r["people"] == p and r["band"] == b]
            if sel:
                s2 = [r["simultaneous"]["seconds"] for r in sel]
                print(f"people={p} band={b:5s} n={len(sel):3d} two tracks at once > 0 s: {sum(s > 0 for s in s2)}, "
                      f">= 2 s: {sum(s >= 2 for s in s2)}; "
                      f"median {np.median(s2):.1f} s; tracks median {np.median([r['tracks'] for r in sel]):.0f}")
    if a.json:
        a.json.write_text(json.dumps(rows, indent=1))


if __name__ == "__main__":
    main()
