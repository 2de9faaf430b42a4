"""Issue 35, point 3: do the path-traced scenes look like the transfer set's? One clip per cached
clean scene (one camera draw, through the same camera and codec as training windows), and the
table of wallcli's measured snr_db per activity, ours against the transfer set's.

    python research/ptcache/envelope.py clips --seed 2000 --stop 129 -o /tmp/ptclips   # videos + labels.csv
    wallcli evaluate /tmp/ptclips --task count --json > runs/env_pt.json
    wallcli evaluate ../shared/transfer --task count --json > runs/final_count.json
    python research/ptcache/envelope.py table runs/env_pt.json runs/final_count.json ../shared/transfer/labels.csv

The table gives per activity (and for two-person clips) the quartiles of the evaluate rows'
snr_db (wallcli's own estimator, the same on both sides), the share of two-person clips and the
lighting mix where the labels have it.
"""
from __future__ import annotations

import argparse
import csv
import json
from pathlib import Path

import numpy as np


def clips(a) -> int:
    from wallcli.datagen import ptcache
    from wallcli.io.writer import VideoWriter
    from wallcli.sim.camera import Camera, sample_camera, video_pix_fmt

    rec = ptcache.recipe(seed=a.seed, grid=(16, 24), spp=a.spp)
    out = Path(a.out)
    out.mkdir(parents=True, exist_ok=True)
    rows = []
    for i in range(a.start, a.stop):
        got = ptcache.load_scene(ptcache.scene_file(rec, i))
        if got is None:
            continue
        arrays, meta = got
        rng = np.random.default_rng(np.random.SeedSequence([a.seed, i, 11, 10_000 + a.draw]))
        cam = sample_camera(rng, "wide")
        cam.fps = float(meta["fps"])
        E0, dE = arrays["E0"], arrays["dE"]
        camera = Camera(cam, E0, arrays["wall_albedo"], len(dE), rng)
        acts = [x for x in meta["activities"] if x != "none"]
        name = f"pt{i:04d}_p{meta['label']}_{meta['activity']}" + (".mkv" if cam.codec == "ffv1" else ".mp4")
        with VideoWriter(out / name, cam.fps, cam.width, cam.height, codec=cam.codec, crf=cam.crf,
                         pix_fmt=video_pix_fmt(cam), preset="veryfast", repeatable=True) as w:
            for t in range(len(dE)):
                w.write(camera.render(dE[t], t, static_E=E0))
        rows.append({"file": name, "people": meta["label"], "activity": meta["activity"] if meta["label"] <= 1 else "mixed",
                     "activities": "+".join(acts), "lighting": meta["room"].get("lighting", "") if isinstance(meta["room"], dict) else "",
                     "fps": cam.fps, "size": f"{cam.width}x{cam.height}", "crf": cam.crf})
        print(name, flush=True)
    with open(out / "labels.csv", "w", newline="") as fh:
        w = csv.DictWriter(fh, fieldnames=list(rows[0]))
        w.writeheader()
        w.writerows(rows)
    return 0


def _groups(rows, labels):
    g = {}
    for r in rows:
        lab = labels.get(r["file"], {})
        n = int(lab.get("people", r.get("truth", 0)) or 0)
        key = "empty" if n == 0 else ("two people" if n >= 2 else lab.get("activity", "?"))
        if r.get("snr_db") is not None:
            g.setdefault(key, []).append(float(r["snr_db"]))
    return g


def table(a) -> int:
    ours = json.loads(Path(a.ours).read_text())
    theirs = json.loads(Path(a.theirs).read_text())
    lab_t = {r["file"]: r for r in csv.DictReader(open(a.labels))}
    lab_o = {r["file"]: r for r in csv.DictReader(open(Path(ours["dir"]) / "labels.csv"))} if a.ours_labels is None \
        else {r["file"]: r for r in csv.DictReader(open(a.ours_labels))}
    go, gt = _groups(ours["rows"], lab_o), _groups(theirs["rows"], lab_t)
    print("| clips | path-traced (ours): n | snr_db q25 / median / q75 | transfer: n | q25 / median / q75 | medians differ by |")
    print("|---|---|---|---|---|---|")
    for k in ("empty", "walking", "crouching", "waving", "jumping", "none", "two people"):
        o, t = np.array(go.get(k, [])), np.array(gt.get(k, []))
        q = lambda v: " / ".join(f"{x:.1f}" for x in np.percentile(v, [25, 50, 75])) if len(v) else "-"
        d = f"{np.median(o) - np.median(t):+.1f} dB" if len(o) and len(t) else "-"
        print(f"| {k} | {len(o)} | {q(o)} | {len(t)} | {q(t)} | {d} |")
    return 0


def main(argv=None) -> int:
    ap = argparse.ArgumentParser()
    sub = ap.add_subparsers(dest="cmd", required=True)
    c = sub.add_parser("clips")
    c.add_argument("--seed", type=int, default=2000)
    c.add_argument("--spp", type=int, default=4096)
    c.add_argument("--start", type=int, default=0)
    c.add_argument("--stop", type=int, default=129)
    c.add_argument("--draw", type=int, default=0)
    c.add_argument("-o", "--out", required=True)
    t = sub.add_parser("table")
    t.add_argument("ours")
    t.add_argument("theirs")
    t.add_argument("labels")
    t.add_argument("--ours-labels")
    a = ap.parse_args(argv)
    return clips(a) if a.cmd == "clips" else table(a)


if __name__ == "__main__":
    raise SystemExit(main())
