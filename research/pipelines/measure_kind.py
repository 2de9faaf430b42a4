"""Do count and activity survive a camera pipeline's temporal noise reduction or white-balance
hunting? (issue 36 part 2; README_tnr_awb.md)

Three steps, so that the altered clips are made once (with this branch's wallcli.sim.isp) and
then analysed by any wallcli on PYTHONPATH (main's for 'before', this branch's for 'after'):

    make:  the strong one-person transfer clips (people == 1, snr_db >= --min-db), decoded to
           float RGB, written again (FFV1 4:4:4) clean and with each kind applied in float
           (the clean copy goes through the same decode and rounding as the altered ones);
    run:   count and activity on every clip made, as `wallcli scan` runs them (one decode,
           the single commands' answers), one JSON line per clip;
    table: per kind, out of N: view usable kept, count label kept, activity label kept,
           |signal_db change| <= 3 dB (count's and activity's), against the clean copy.

    python research/pipelines/measure_kind.py make --out /tmp/pipe --kind tnr --kind awb
    python research/pipelines/measure_kind.py run --out /tmp/pipe --tag after
    python research/pipelines/measure_kind.py table --out /tmp/pipe --tag after
"""
from __future__ import annotations

import argparse
import csv
import json
import sys
from pathlib import Path

import numpy as np

TRANSFER = Path("/work/shared/transfer")
TNR_LEVELS = (0.3, 0.45, 0.6, 0.7, 0.8)  # recursive blending a, in turn over the clips
AWB_LEVELS = (0.005, 0.01, 0.02, 0.03)  # relative amplitude of the per-colour gains, in turn


def strong_clips(min_db: float) -> list[dict]:
    with open(TRANSFER / "labels.csv", newline="") as f:
        rows = list(csv.DictReader(f))
    return [r for r in rows if r["people"] == "1" and r["snr_db"] and float(r["snr_db"]) >= min_db]


def _alter(src: Path, dst: Path, kind: str, strength: float, seed: int) -> None:
    from wallcli.io.video import open_video
    from wallcli.io.writer import VideoWriter
    from wallcli.sim.isp import RecursiveFilter, awb_gains

    with open_video(src) as reader:
        fps, n = float(reader.info.fps), None
        frames = [f.planes.to_rgb(f.planes.y.astype(np.float64),
                                  *(p.astype(np.float64) for p in _chroma(f.planes))) for f in reader.frames()]
    h, w = frames[0].shape[:2]
    n = len(frames)
    tnr = RecursiveFilter(strength) if kind == "tnr" else None
    gains = awb_gains(n, fps, strength, np.random.default_rng([seed, 0xA3B])) if kind == "awb" else None
    with VideoWriter(dst, fps, w, h, codec="ffv1", repeatable=True) as vw:
        for i, x in enumerate(frames):
            x = np.asarray(x, np.float32)
            if gains is not None:
                x = x * gains[i].astype(np.float32)
            if tnr is not None:
                x = tnr(x)
            vw.write(np.clip(np.rint(x), 0, 255).astype(np.uint8))


def _chroma(planes):
    """u, v at the luma's size (a 4:2:0 chroma sample covers its 2x2 luma pixels)."""
    if planes.u is None:
        return ()
    fy, fx = 1 << planes.sub_y, 1 << planes.sub_x
    up = lambda c: np.repeat(np.repeat(c, fy, axis=0), fx, axis=1)[:planes.height, :planes.width]  # noqa: E731
    return up(planes.u), up(planes.v)


def make(args) -> None:
    out = Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    clips = strong_clips(args.min_db)
    levels = {"tnr": TNR_LEVELS, "awb": AWB_LEVELS}
    index = []
    for i, r in enumerate(clips):
        stem = Path(r["file"]).stem
        src = TRANSFER / r["file"]
        for kind in ["clean", *args.kind]:
            strength = 0.0 if kind == "clean" else levels[kind][i % len(levels[kind])]
            dst = out / f"{stem}_{kind}.mkv"
            if not dst.exists():
                tmp = dst.with_name("tmp_" + dst.name)
                _alter(src, tmp, kind, strength, i)
                tmp.rename(dst)
            index.append({"clip": stem, "kind": kind, "strength": strength, "file": dst.name,
                          "activity": r["activity"], "snr_db": float(r["snr_db"]), "crf": int(r["crf"])})
        print(f"{i + 1}/{len(clips)} {stem}", file=sys.stderr, flush=True)
    (out / "index.json").write_text(json.dumps(index, indent=1))


def resume(out: Path, tag: str):
    """(the index, both shipped models, the results file of ``tag``, the files it already holds):
    a run picks up where an earlier one stopped."""
    from wallcli.infer.twostage import load_classifier

    index = json.loads((out / "index.json").read_text())
    models = {t: load_classifier(t) for t in ("count", "activity")}
    path = out / f"results_{tag}.jsonl"
    done = set()
    if path.exists():
        done = {json.loads(line)["file"] for line in path.read_text().splitlines() if line.strip()}
    return index, models, path, done


def run(args) -> None:
    from wallcli.batch.analyse import analyse

    out = Path(args.out)
    index, models, path, done = resume(out, args.tag)
    with open(path, "a") as f:
        for k, e in enumerate(index):
            if e["file"] in done or (args.kind and e["kind"] not in ("clean", *args.kind)):
                continue
            res = analyse(str(out / e["file"]), ("count", "activity"), models)
            rec = {"file": e["file"], "view": res["view"]["usable"], "corrections": res["corrections"]}
            for t in ("count", "activity"):
                rec[t] = {k2: res[t][k2] for k2 in ("label", "confident", "reason", "signal_db")}
            f.write(json.dumps(rec) + "\n")
            f.flush()
            print(f"{k + 1}/{len(index)} {e['file']} {rec['count']['label']} {rec['activity']['label']} "
                  f"{rec['count']['signal_db']}", file=sys.stderr, flush=True)


def table(args) -> None:
    out = Path(args.out)
    index = {e["file"]: e for e in json.loads((out / "index.json").read_text())}
    res = {}
    for tag in args.tag.split(","):
        for line in (out / f"results_{tag}.jsonl").read_text().splitlines():
            r = json.loads(line)
            res[(tag, r["file"])] = r
    tags = args.tag.split(",")
    kinds = sorted({e["kind"] for e in index.values()} - {"clean"})
    print("| kind | code | N | view usable kept | count label kept | activity label kept | "
          "count signal_db within 3 dB | activity signal_db within 3 dB | all four | median signal_db change (count) |"
          " found | decided on a figure over 3 dB off (count, activity) |")
    print("|" + "---|" * 12)
    for kind in kinds:
        for tag in tags:
            rows = []
            for f, e in index.items():
                if e["kind"] != kind:
                    continue
                clean = res.get((tag, f.replace(f"_{kind}.mkv", "_clean.mkv")))
                alt = res.get((tag, f))
                if clean and alt:
                    rows.append((e, clean, alt))
            if not rows:
                continue
            n = len(rows)
            view = sum(a["view"] or not c["view"] for _, c, a in rows)
            lab = {t: sum(a[t]["label"] == c[t]["label"] for _, c, a in rows) for t in ("count", "activity")}
            d = {t: [a[t]["signal_db"] - c[t]["signal_db"] for _, c, a in rows] for t in ("count", "activity")}
            db = {t: sum(abs(x) <= 3 for x in d[t]) for t in d}
            every = sum((a["view"] or not c["view"]) and all(a[t]["label"] == c[t]["label"] and
                        abs(a[t]["signal_db"] - c[t]["signal_db"]) <= 3 for t in ("count", "activity"))
                        for _, c, a in rows)
            found = sum(any(x["kind"] in _KINDS[kind] for x in a["corrections"]) for _, c, a in rows)
            off = {t: sum(a[t]["confident"] and abs(a[t]["signal_db"] - c[t]["signal_db"]) > 3 for _, c, a in rows)
                   for t in ("count", "activity")}
            print(f"| {kind} | {tag} | {n} | {view} | {lab['count']} | {lab['activity']} | {db['count']} | "
                  f"{db['activity']} | {every} | {np.median(d['count']):+.1f} | {found} | {off['count']}, {off['activity']} |")
    if args.detail:
        for kind in kinds:
            for tag in tags:
                for f, e in index.items():
                    a, c = res.get((tag, f)), res.get((tag, f.replace(f"_{kind}.mkv", "_clean.mkv")))
                    if e["kind"] == kind and a and c:
                        print(tag, f, e["strength"], c["count"]["label"], a["count"]["label"], c["activity"]["label"],
                              a["activity"]["label"], c["count"]["signal_db"], a["count"]["signal_db"],
                              [x["kind"] for x in a["corrections"]])


_KINDS = {"tnr": ("temporal_nr",), "awb": ("white_balance",)}


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("step", choices=("make", "run", "table"))
    ap.add_argument("--out", required=True)
    ap.add_argument("--kind", action="append", choices=("tnr", "awb"), default=[])
    ap.add_argument("--min-db", type=float, default=5.0)
    ap.add_argument("--tag", default="after")
    ap.add_argument("--detail", action="store_true")
    args = ap.parse_args()
    {"make": make, "run": run, "table": table}[args.step](args)


if __name__ == "__main__":
    main()
