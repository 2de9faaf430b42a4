"""sigma's geometric part by the shade's strength (wallcli/signal/track.py GEOMETRY_BY_STRENGTH),
and how often sigma covers the true place: out of fold on the rendered recordings' single walkers
(each fold's table from the other four), and on the bundled examples' walkers (their sidecars).

The table is the 68th percentile of the longest track's |x - true x| in each third of the samples
by strength (the sample's darkness in noise units), at the third's median strength.

    python research/track/sigma.py
"""
from __future__ import annotations

import json
import sys
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))
from data import clips  # noqa: E402
from wallcli.signal import track as tr  # noqa: E402
from wallcli.train.recordings import FPS  # noqa: E402

EXAMPLES = Path(__file__).resolve().parents[2] / "examples"


def table(samples: list[dict], parts: int = 3) -> tuple[tuple[float, float], ...]:
    st = np.concatenate([s["strength"] for s in samples])
    err = np.concatenate([s["err"] for s in samples])
    log = np.log10(np.maximum(st, 1.0))
    edges = np.percentile(log, np.linspace(0, 100, parts + 1))
    out, top = [], 0.0
    for a, b in zip(edges[:-1], edges[1:]):
        m = (log >= a) & (log <= b)
        top = max(top, float(np.percentile(err[m], 68)))  # never narrower for a stronger shade
        out.append((round(float(10 ** np.median(log[m])), 1), round(top, 3)))
    return tuple(out)


def covered(samples: list[dict], tab) -> tuple[int, int]:
    s, g = (np.array(v) for v in zip(*tab))
    n = got = 0
    for x in samples:
        geo = np.interp(np.log10(np.maximum(x["strength"], 1.0)), np.log10(s), g)
        got += int(np.sum(x["err"] <= np.sqrt(x["shade"] ** 2 + geo ** 2)))
        n += len(x["err"])
    return got, n


def recording_samples() -> list[dict]:
    out = []
    for c in clips():
        if not (c.people == 1 and c.activity == "walking" and c.detectable):
            continue
        tracks = tr.track_rows(c.h, np.arange(c.h.shape[0]) / FPS, FPS)
        if not tracks:
            continue
        k = max(tracks, key=lambda t: t.duration)
        t = np.asarray(k.t)
        xt = np.interp(t, np.arange(c.x.shape[1]) / FPS, c.x[0])
        out.append({"name": c.name, "fold": c.fold, "err": np.abs(np.asarray(k.x) - xt),
                    "strength": np.asarray(k.strength), "shade": np.asarray(k.shade), "sigma": np.asarray(k.sigma)})
    return out


def example_samples() -> list[dict]:
    """Every track of the examples with walkers, against the nearer walker's true place."""
    from wallcli.infer.track import track_video

    out = []
    for side in sorted(EXAMPLES.glob("*.json")):
        truth = json.loads(side.read_text())
        walkers = [p for p in truth.get("persons", []) if p.get("activity") == "walking"]
        if not walkers or not (EXAMPLES / truth["video"]).is_file():
            continue
        x0, x1 = truth["wall_region_m"][:2]
        res, _ = track_video(str(EXAMPLES / truth["video"]))
        for k in res["tracks"]:
            t = np.array([s["t"] for s in k["samples"]])
            x = np.array([s["x"] for s in k["samples"]])
            err = np.min([np.abs(x - np.interp(t, np.arange(len(p["positions"])) / truth["fps"],
                                               (np.array(p["positions"])[:, 0] - x0) / (x1 - x0))) for p in walkers], axis=0)
            out.append({"name": side.stem, "err": err, "sigma": np.array([s["sigma"] for s in k["samples"]]),
                        "shade": np.array([s["sigma_shade"] for s in k["samples"]]),
                        "strength": np.full(len(t), k["strength"])})
    return out


def main() -> None:
    rec = recording_samples()
    print(f"table on all {len(rec)} walkers with a track: {table(rec)} (shipped: {tr.GEOMETRY_BY_STRENGTH})")
    got = n = 0
    for k in range(5):
        g, m = covered([s for s in rec if s["fold"] == k], table([s for s in rec if s["fold"] != k]))
        got, n = got + g, n + m
    print(f"recordings, out of fold: sigma covers {got} of {n} samples ({got / n:.0%}; 68 % is calibrated)")
    shipped = sum(int(np.sum(s["err"] <= s["sigma"])) for s in rec)
    print(f"recordings, the shipped table: {shipped} of {n} ({shipped / n:.0%})")
    ex = example_samples()
    g = sum(int(np.sum(s["err"] <= s["sigma"])) for s in ex)
    m = sum(len(s["err"]) for s in ex)
    print(f"examples' walkers ({', '.join(sorted({s['name'] for s in ex}))}): sigma covers {g} of {m} samples "
          f"({g / max(m, 1):.0%}); median sigma {np.median(np.concatenate([s['sigma'] for s in ex])):.2f}, "
          f"68th percentile of |error| {np.percentile(np.concatenate([s['err'] for s in ex]), 68):.2f}")


if __name__ == "__main__":
    main()
