"""Session 17 (issue 27 point 1): a larger sample for the view check, cached on disk.

`make` writes, for each of N rounds, one wall clip per world and domain (room: base, shifted,
wide, steady; flatland: base and wide in turn) and from each wall's frames the faults of
wallcli/sim/views.py: a sprite (contrast 40-60 %), a faint sprite (15-40 %), a cut to the
previous round's wall of the same world and domain, two pans and two shakes at amplitudes taken
in turn from PANS and SHAKES. Clips are encoded as `wallcli simulate` writes them (H.264, crf 18,
320x240, 30 fps) and listed in manifest.jsonl. `check` runs the view check on every cached clip
(as the commands do: wallcli's reader, every frame to ViewCheck) and prints the tables with 95 %
Clopper-Pearson intervals; `--transfer DIR` does the same for a folder of wall videos.

    python research/view/sweep.py make --rounds 25 --out /tmp/view17
    python research/view/sweep.py check --out /tmp/view17 --json /tmp/view17/after.json
    python research/view/sweep.py check --transfer ../shared/transfer --json /tmp/view17/transfer.json
"""
from __future__ import annotations

import argparse
import json
import sys
import time
from pathlib import Path

import numpy as np

SECONDS, FPS = 4.0, 30.0
N = int(SECONDS * FPS)
SLOTS = (("room", "base"), ("room", "shifted"), ("room", "wide"), ("room", "steady"), ("flatland", None),
         # session 19: sharp shadows: people 0.3-1.5 m from the wall (any room domain in turn), and the
         # bundled examples' camera (160x120, crf 12, lamps or windows, people 1-2 m away)
         ("room", "near"), ("room", "example"))
NEAR_DOMAINS = ("base", "wide", "steady", "shifted")
PANS = (2.0, 3.0, 4.0, 6.0, 10.0)  # px in total over 1-3 s
SHAKES = (0.5, 1.0, 1.5, 2.0, 3.0)  # px rms per axis


def wall_frames(seed: int, world: str, domain: str) -> list:
    rng = np.random.default_rng(seed)
    people = int(rng.integers(0, 3))
    if world == "flatland":
        from dataclasses import replace

        from wallcli.sim.world_flat import sample_flat_scene

        s = sample_flat_scene(seed, None, max(people, 1) if people else 0, duration=SECONDS, domain=domain, fps=FPS,
                              nuisance_p=0.5)
        s.camera = replace(s.camera, width=320, height=240, codec="libx264", crf=18)
        return list(s.frames())
    from wallcli.sim.scene import SceneConfig, sample_scene

    if domain == "example":  # as examples/make_examples.sh makes them
        cfg = SceneConfig(people=max(people, 1), duration=SECONDS, fps=FPS, width=160, height=120, domain="base",
                          codec="libx264", crf=12, distance=(1.0, 2.0), nuisance_p=0.5,
                          camera_overrides={"gain": 0.1, "read_noise": 1.5, "sensor_pixels": 200000.0})
        return list(sample_scene(seed, cfg).frames())
    near = domain.startswith("near")
    cfg = SceneConfig(people=max(people, 1) if near else people, duration=SECONDS, fps=FPS, width=320, height=240,
                      domain=domain.split("-")[1] if near else domain, codec="libx264", crf=18, nuisance_p=0.5,
                      **({"distance": (0.3, 1.5)} if near else {}))
    return list(sample_scene(seed, cfg).frames())


def make(a) -> None:
    from wallcli.sim import views

    out = a.out
    out.mkdir(parents=True, exist_ok=True)
    man = (out / "manifest.jsonl").open("a")
    prev = {}
    t0 = time.time()
    for k in range(a.start, a.start + a.rounds):
        for j, (world, dom) in enumerate(SLOTS):
            dom = dom or ("base", "wide")[k % 2]
            if dom == "near":
                dom = "near-" + NEAR_DOMAINS[k % len(NEAR_DOMAINS)]
            seed = a.seed + 10 * k + j
            frames = wall_frames(seed, world, dom)
            # the cut goes to the previous round's wall of the slot (a fresh one in the first round)
            other = prev.get(j) or wall_frames(seed + 99991, world, dom)
            prev[j] = frames
            jobs = [("wall", None, lambda rng: frames),
                    ("sprite", "40-60", lambda rng: views.sprite(frames, rng, n=N, fps=FPS, contrast=(0.4, 0.6))),
                    ("faint", "15-40", lambda rng: views.sprite(frames, rng, n=N, fps=FPS, contrast=(0.15, 0.4))),
                    ("cut", None, lambda rng: views.cut(frames, other, rng, n=N))]
            for i in range(2):
                p, s = PANS[(k + j + 2 * i) % len(PANS)], SHAKES[(k + j + 2 * i + 1) % len(SHAKES)]
                jobs.append(("pan", p, lambda rng, p=p: views.pan(frames, rng, n=N, fps=FPS, amplitude=p)))
                jobs.append(("shake", s, lambda rng, s=s: views.shake(frames, rng, n=N, fps=FPS, rms=s)))
            for m, (kind, param, fn) in enumerate(jobs):
                if a.kinds and kind not in a.kinds.split(","):
                    continue  # its index m (and so its rng) stays what a full run gives it
                name = f"{kind}_{param}_{world}_{dom}_{seed}_{m}.mp4".replace("None_", "")
                rng = np.random.default_rng([seed, m])
                views.encode(fn(rng), out / name, fps=FPS)
                man.write(json.dumps({"file": name, "kind": kind, "param": param, "world": world, "domain": dom,
                                      "seed": seed}) + "\n")
                man.flush()
        print(f"round {k + 1 - a.start}/{a.rounds}, {time.time() - t0:.0f} s", file=sys.stderr, flush=True)


def check_file(path: Path) -> dict:
    from wallcli.io.video import open_video
    from wallcli.view.check import ViewCheck

    vc = ViewCheck()
    with open_video(path) as reader:
        for frame in reader.frames():
            vc(frame)
    return vc.summary()


def interval(k: int, n: int) -> tuple[float, float]:
    """95 % Clopper-Pearson interval of k successes in n."""
    from scipy.stats import beta

    lo = 0.0 if k == 0 else float(beta.ppf(0.025, k, n - k + 1))
    hi = 1.0 if k == n else float(beta.ppf(0.975, k + 1, n - k))
    return lo, hi


def table(rows: list, keys) -> None:
    print(f"{'clips':24} {'n':>4} {'flagged':>7} {'rate':>6}  95 % interval   issues")
    for key in keys:
        sel = [r for r in rows if (r["kind"], r.get("param")) == key or (key[1] == "*" and r["kind"] == key[0])]
        if not sel:
            continue
        bad = [r for r in sel if not r["usable"]]
        issues: dict = {}
        for r in bad:
            for i in r["issues"]:
                issues[i] = issues.get(i, 0) + 1
        lo, hi = interval(len(bad), len(sel))
        label = f"{key[0]} {key[1] if key[1] is not None else ''}"
        print(f"{label:24} {len(sel):4d} {len(bad):7d} {len(bad) / len(sel):6.1%}  {lo:5.1%}-{hi:5.1%}  {issues}")


def check(a) -> None:
    # verdicts are kept in --json (one clip a line) and not recomputed: a run can be resumed
    done = {}
    if a.json and a.json.exists():
        done = {r["file"]: r for r in map(json.loads, a.json.read_text().splitlines())}
    out = a.json.open("a") if a.json else None
    if a.transfer:
        todo = [{"file": p.name, "kind": "transfer", "param": None, "path": p} for p in sorted(Path(a.transfer).glob("*.mp4"))]
    else:
        todo = [{**r, "path": a.out / r["file"]} for r in map(json.loads, (a.out / "manifest.jsonl").read_text().splitlines())
                if not a.kinds or r["kind"] in a.kinds.split(",")]
    rows = []
    for r in todo:
        path = r.pop("path")
        if r["file"] not in done:
            done[r["file"]] = {**r, **check_file(path)}
            if out:
                out.write(json.dumps(done[r["file"]]) + "\n")
                out.flush()
        rows.append(done[r["file"]])
    kinds = sorted({(r["kind"], r.get("param")) for r in rows}, key=lambda x: (x[0], str(x[1])))
    table(rows, kinds + [(k, "*") for k in ("pan", "shake")])
    walls = [r for r in rows if r["kind"] in ("wall", "transfer") and not r["usable"]]
    for r in walls:
        print("false alarm:", r["file"], r["issues"], r["reason"])


def main() -> None:
    ap = argparse.ArgumentParser()
    sub = ap.add_subparsers(dest="cmd", required=True)
    m = sub.add_parser("make")
    m.add_argument("--rounds", type=int, default=25)
    m.add_argument("--start", type=int, default=0)
    m.add_argument("--seed", type=int, default=17000)
    m.add_argument("--out", type=Path, default=Path("/tmp/view17"))
    m.add_argument("--kinds", help="make only these kinds of clip, comma-separated (the wall is always rendered)")
    c = sub.add_parser("check")
    c.add_argument("--out", type=Path, default=Path("/tmp/view17"))
    c.add_argument("--transfer", type=Path)
    c.add_argument("--kinds", help="only these kinds of clip, comma-separated (wall,sprite,faint,cut,pan,shake)")
    c.add_argument("--json", type=Path, help="verdicts, one clip a line (resumed if present)")
    a = ap.parse_args()
    make(a) if a.cmd == "make" else check(a)


if __name__ == "__main__":
    main()
