"""Does the 'bracket' domain's analytic world bracket the path tracer? (issue 35, point 4)

    python research/ptcache/bracket_check.py [--scenes 8] [--spp 256]

For the same scenes (room, person, motion: one seed), the wall's noise-free relative change is
rendered path traced (Mitsuba, boxes) and analytically (spheres) with the bracket domain's two
gains at their corners (body radiance 0.3x and 1.5x, room shadows 0.5x and 3x) and at 1x. Per
scene and world, three summary features of the column profile rel(t, x) = dE/E averaged over
rows and colours:

- power: the mean over columns of rel's variance over time (relative units squared, in dB);
- whole-wall share: the variance of the column mean over time, over the power;
- high-frequency share: the share of the power (column mean removed) above 1 Hz.

Prints each scene's path-traced value and the analytic range over the four corners, and whether
the former falls inside. Path-traced figures carry Monte-Carlo noise (research/ptcache/README.md),
which inflates power and high-frequency share.
"""
from __future__ import annotations

import argparse
import itertools

import numpy as np

from wallcli.sim.scene import SceneConfig, sample_scene

ACTS = ["walking", "crouching", "waving", "jumping"]


def profile(scene) -> np.ndarray:
    scene.clean_profiles = []
    for _ in scene.frames():
        pass
    return np.stack([c.mean(axis=-1) for c, *_ in scene.clean_profiles])  # (T, gx)


def features(rel: np.ndarray, fps: float) -> tuple[float, float, float]:
    rel = rel - rel.mean(axis=0)
    power = float(np.mean(rel.var(axis=0)))
    wall = float(rel.mean(axis=1).var()) / max(power, 1e-30)
    local = rel - rel.mean(axis=1, keepdims=True)
    spec = np.abs(np.fft.rfft(local, axis=0)) ** 2
    f = np.fft.rfftfreq(len(rel), 1 / fps)
    hf = float(spec[f > 1.0].sum() / max(spec[1:].sum(), 1e-30))
    return 10 * np.log10(max(power, 1e-30)), wall, hf


def main(argv=None) -> int:
    ap = argparse.ArgumentParser()
    ap.add_argument("--scenes", type=int, default=8)
    ap.add_argument("--spp", type=int, default=256)
    ap.add_argument("--seed", type=int, default=950)
    a = ap.parse_args(argv)
    inside = np.zeros(3, int)
    names = ("power dB", "whole-wall share", "share above 1 Hz")
    for k in range(a.scenes):
        act = ACTS[k % 4]
        base = dict(people=1, activities=[act], duration=6.0, fps=15.0, grid=(16, 24), domain="bracket",
                    distance=(1.0, 3.0) if act != "walking" else (1.0, 5.0), roam=2.0)
        pt = sample_scene(a.seed, SceneConfig(world="pt", spp=a.spp, **base), index=k)
        f_pt = features(profile(pt), 15.0)
        corners = []
        for bg, sg in itertools.product((0.3, 1.5), (0.5, 3.0)):
            sc = sample_scene(a.seed, SceneConfig(world="room", **base), index=k)
            sc.body_gain, sc.shadow_gain = bg, sg
            corners.append(features(profile(sc), 15.0))
        sc = sample_scene(a.seed, SceneConfig(world="room", **base), index=k)
        sc.body_gain = sc.shadow_gain = 1.0
        one = features(profile(sc), 15.0)
        lo, hi = np.min(corners, axis=0), np.max(corners, axis=0)
        ok = (np.array(f_pt) >= lo) & (np.array(f_pt) <= hi)
        inside += ok
        print(f"scene {k} {act:9s} " + " | ".join(
            f"{n}: pt {p:.3g}, analytic {l:.3g}..{h:.3g} (1x {o:.3g}){'' if g else ' OUTSIDE'}"
            for n, p, l, h, o, g in zip(names, f_pt, lo, hi, one, ok)), flush=True)
    print(f"\npath-traced feature inside the bracket's analytic range: " +
          ", ".join(f"{n} {i} of {a.scenes}" for n, i in zip(names, inside)))
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
