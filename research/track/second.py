"""Can the tracker see a second person? Three measurements behind README.md's "A second streak".

1. ``examples/two-walking.mp4`` against its truth: when each walker's shade from the room's one lamp
   (a point at the truth's lamp position, cast on the wall y = 0) is in the view.
2. On the recordings with truth: of each class, how many clips hold a second path's run (apart from
   the first path by 0.2 of the width, over THRESHOLD, in 16 s pieces as the chunks) of a given
   length and share of the first path's darkness, at the shipped speed limit and at 3 view widths a
   second. If a second streak told two people from one, some row would hold many more two-person
   clips than one-person ones.
3. Variants of the shipped tracker (the whole wall's change taken as the row's mean, as shipped,
   its median or its 25 %-trimmed mean; RELATIVE 0.35, 0.25, 0.2): the walkers' figures, clips with
   two tracks at once by class, and the examples' ``simultaneous`` seconds.

    python research/track/second.py
"""
from __future__ import annotations

import json
import sys
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))
from data import clips  # noqa: E402
from evaluate import walker_figures  # noqa: E402
import wallcli.signal.track as tr  # noqa: E402
from wallcli.api import stplot  # noqa: E402
from wallcli.train.recordings import FPS  # noqa: E402

ROOT = Path(__file__).resolve().parents[2]
EXAMPLES = ["walking", "crouching", "waving", "jumping", "empty", "standing", "two-walking", "two-mixed"]
SHIPPED_DARKNESS = tr.darkness


def lamp_shades(name: str = "two-walking") -> None:
    d = json.loads((ROOT / "examples" / f"{name}.json").read_text())
    x0, x1 = d["wall_region_m"][:2]
    lamp = np.array(d["room"]["lamp_positions"][0])
    t = np.arange(d["frames"]) / d["fps"]
    seen = []
    for k, p in enumerate(d["persons"]):
        pos = np.array(p["positions"])
        u = (lamp[0] + (pos[:, 0] - lamp[0]) * lamp[1] / (lamp[1] - pos[:, 1]) - x0) / (x1 - x0)
        seen.append((u >= 0) & (u <= 1))
        print(f"{name} walker {k}: lamp shade in view at " + ", ".join(
            f"{t[a]:.2f}-{t[b - 1]:.2f} s" for a, b in tr._runs(seen[-1])))
    both = seen[0] & seen[1]
    print(f"both in view {both.sum() / d['fps']:.1f} s: " + ", ".join(f"{t[a]:.2f}-{t[b - 1]:.2f} s" for a, b in tr._runs(both)))


def second_runs(h: np.ndarray, fps: float, speed: float, durations) -> dict:
    """The largest share of the first path's darkness (its 90th percentile) held by a run of the
    second path of at least each duration."""
    dark = tr.darkness(h, fps)
    T, B = dark.shape
    score = np.clip(dark, -tr.THRESHOLD, None)
    hold, guard = int(round(0.25 * fps)), max(1, int(round(tr.GUARD * B)))
    best = {d: 0.0 for d in durations}
    for k in range(2):
        path = tr.viterbi(score, speed * B / fps)
        held = np.convolve(dark[np.arange(T), path], np.ones(hold) / hold, mode="same")
        if k == 0:
            p90, first, held0 = np.percentile(held, 90), path.copy(), held
            for t in range(T):
                g = max(guard, int(np.ceil(2.0 * tr._width(dark[t], int(path[t])))))
                score[t, max(0, path[t] - g):path[t] + g + 1] = -1e6
            continue
        apart = (np.abs(path - first) >= 0.2 * B) & (held0 >= tr.THRESHOLD)
        for a, b in tr._runs((held >= tr.THRESHOLD) & apart):
            for d in durations:
                if (b - a) / fps >= d:
                    best[d] = max(best[d], float(np.median(held[a:b])) / max(p90, 1e-9))
    return best


def separability(cs, ex) -> None:
    durations, shares = (0.3, 0.5, 1.0), (0.1, 0.2, 0.35)
    print("second-path runs: clips with one, by class (people 0 / 1 / 2), and the examples with one")
    for speed in (tr.MAX_SPEED, 3.0):
        per = {}
        for c in cs:
            T = c.h.shape[0]
            pieces = [second_runs(c.h[a:a + 480], FPS, speed, durations) for a in range(0, max(1, T - 120), 360)]
            per.setdefault(c.people, []).append({d: max(p[d] for p in pieces) for d in durations})
        e = {n: second_runs(h, 30.0, speed, durations) for n, h in ex.items()}
        for d in durations:
            for s in shares:
                n = [sum(v[d] >= s for v in per[p]) for p in (0, 1, 2)]
                print(f"  speed {speed:.1f}/s, run >= {d} s, share >= {s}: {n[0]}/{len(per[0])} {n[1]}/{len(per[1])} "
                      f"{n[2]}/{len(per[2])}; examples: {' '.join(k for k in e if e[k][d] >= s) or '-'}")


def darkness_with(row: str):
    """The shipped darkness, with the whole wall's change taken as each row's mean (as shipped),
    median or 25 %-trimmed mean after each place's median over the chunk is taken off."""
    def darkness(rows, fps):
        lum = np.asarray(rows, np.float64)
        lum = lum.mean(axis=-1) if lum.ndim == 3 else lum
        if row == "mean":  # the shipped order: the row's mean first, then each place's median
            lum = lum - lum.mean(axis=1, keepdims=True)
        d = lum - np.median(lum, axis=0, keepdims=True)
        if row == "median":
            d = d - np.median(d, axis=1, keepdims=True)
        elif row == "trimmed":
            k = int(round(0.25 * d.shape[1]))
            d = d - np.sort(d, axis=1)[:, k:d.shape[1] - k].mean(axis=1, keepdims=True)
        # the rest as the shipped function: smoothed, in units of the noise that changes bin by bin
        d = tr._smooth(d, tr.SMOOTH_SECONDS * fps, 0)
        sb = tr.SMOOTH_BINS * d.shape[1] / 64.0
        ds = tr._smooth(d, sb, 1)
        g = tr._gain(sb)
        noise = 1.4826 * np.median(np.abs(d - ds)) * np.sqrt(g / max(1.0 - g, 1e-6))
        spread = 1.4826 * np.median(np.abs(ds - np.median(ds)))
        return -ds / max(noise if noise > 1e-3 * spread else spread, 1e-12)
    return darkness


def variants(cs, ex) -> None:
    print("variants: walkers r >= 0.8 / error <= 0.25 of 28; clips with two tracks at once > 0 s (>= 2 s) "
          "by people 0 / 1 / 2; examples' simultaneous seconds")
    shipped = tr.RELATIVE
    for row in ("mean", "median", "trimmed"):
        for rel in (0.35, 0.25, 0.2):
            tr.darkness, tr.RELATIVE = darkness_with(row), rel
            sims, rs, es = {0: [], 1: [], 2: []}, 0, 0
            for c in cs:
                T = c.h.shape[0]
                tk = tr.track_rows(c.h, np.arange(T) / FPS, FPS)
                sims[c.people].append(tr.simultaneous(tk)["seconds"])
                if c.people == 1 and c.activity == "walking" and c.detectable:
                    f = walker_figures(c, tk)
                    rs, es = rs + bool(f and f["r"] >= 0.8), es + bool(f and f["err"] <= 0.25)
            e = {n: tr.simultaneous(tr.track_rows(h, np.arange(len(h)) / 30.0, 30.0))["seconds"] for n, h in ex.items()}
            cls = " / ".join(f"{sum(s > 0 for s in v)} ({sum(s >= 2 for s in v)}) of {len(v)}" for v in sims.values())
            print(f"  {row:8s} RELATIVE {rel}: walkers {rs} / {es}; {cls}; "
                  + " ".join(f"{n} {v:.1f}" for n, v in e.items() if v > 0 or n == "two-walking"))
    tr.darkness, tr.RELATIVE = SHIPPED_DARKNESS, shipped


def main() -> None:
    lamp_shades()
    ex = {}
    for n in EXAMPLES:
        a = stplot(str(ROOT / "examples" / f"{n}.mp4"))
        ex[n] = np.moveaxis(a["horizontal"], 0, 1) + a["h_mean"][None]
    cs = clips()
    h = cs[0].h
    assert np.allclose(darkness_with("mean")(h, FPS), SHIPPED_DARKNESS(h, FPS)), "the copy differs from the shipped darkness"
    separability(cs, ex)
    variants(cs, ex)


if __name__ == "__main__":
    main()
