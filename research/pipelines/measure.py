"""Do count and activity keep a clean clip's answers when a camera pipeline's artefact is added?

Takes the strong one-person clips of the independent renderer's transfer set (labels.csv:
people = 1, snr_db >= --min-snr), decodes each clip's YUV 4:2:0 planes, adds the kind to the
decoded frames and writes them again (H.264 at CRF 0, lossless for these planes: everything the
kind leaves alone is the original's code values), then runs ``wallcli count X --json`` and
``wallcli activity X --json`` on the clean clip and on the altered one. A case (a clip and a task)
is kept when the altered clip's view is usable (as the clean one's), its label is the clean one's,
and its ``signal_db`` is within 3 dB of the clean one's.

Kinds:
  overlay    a CCTV clock (HH:MM:SS, white, flat, top left) changing every second, and a camera
             name at the bottom right (wallcli.sim.overlay.text_mask)
  interlace  frame k = the even rows (top field) of frame k and the odd rows of frame k + 1: the
             renderer has no half-frame instants, so the fields are a whole frame apart, the
             strongest combing its rate allows (simulate --interlace weaves half a frame apart)

    nice -n 10 python research/pipelines/measure.py --kind overlay --out /tmp/pipe --tag after
    PYTHONPATH=/work/main python research/pipelines/measure.py --kind overlay --out /tmp/pipe --tag before --code /work/main
    python research/pipelines/measure.py --kind overlay --out /tmp/pipe --tag after --table
"""
from __future__ import annotations

import argparse
import csv
import json
import os
import subprocess
import sys
import tempfile
from concurrent.futures import ThreadPoolExecutor
from pathlib import Path

import numpy as np

TRANSFER = Path("/work/shared/transfer")
TASKS = ("count", "activity")
NAME = "CAM 01"


def clips(min_snr: float) -> list[dict]:
    rows = list(csv.DictReader(open(TRANSFER / "labels.csv")))
    return [r for r in rows if r["people"] == "1" and r["snr_db"] and float(r["snr_db"]) >= min_snr]


def _yuv(frame) -> list[np.ndarray]:
    a = frame.to_ndarray(format="yuv420p")
    h = frame.height
    y = a[:h]
    rest = a[h:].reshape(2, h // 2, frame.width // 2)
    return [y.copy(), rest[0].copy(), rest[1].copy()]


def alter(src: Path, dst: Path, kind: str) -> None:
    """Write ``src`` again with ``kind`` added (see the module's docstring)."""
    import av

    from wallcli.sim.overlay import text_mask, weave

    if dst.exists():
        return
    tmp = dst.with_suffix(".tmp.mp4")
    with av.open(str(src)) as inp:
        vs = inp.streams.video[0]
        frames = [(_yuv(f), float(f.time)) for f in inp.decode(vs)]
        rate = vs.average_rate
    w, h = frames[0][0][0].shape[1], frames[0][0][0].shape[0]
    with av.open(str(tmp), "w") as out:
        st = out.add_stream("libx264", rate=rate)
        st.width, st.height, st.pix_fmt = w, h, "yuv420p"
        st.options = {"crf": "0", "preset": "medium"}
        st.codec_context.thread_count = 1
        for k, (p, t) in enumerate(frames):
            if kind == "overlay":
                m = text_mask(h, w, t - frames[0][1], name=NAME)
                p[0][m] = 235
                mc = m.reshape(h // 2, 2, w // 2, 2).any(axis=(1, 3))
                p[1][mc] = 128
                p[2][mc] = 128
            elif kind == "interlace":
                if k + 1 >= len(frames):
                    break
                p = [weave(x, n) for x, n in zip(p, frames[k + 1][0])]
            frame = av.VideoFrame.from_ndarray(np.concatenate([p[0], p[1].reshape(h // 4, w), p[2].reshape(h // 4, w)]),
                                               format="yuv420p")
            for pk in st.encode(frame):
                out.mux(pk)
        for pk in st.encode():
            out.mux(pk)
    os.replace(tmp, dst)


def run(path: Path, task: str, dst: Path, code: str | None) -> dict:
    if dst.exists():
        return json.loads(dst.read_text())
    env = dict(os.environ)
    if code:
        env["PYTHONPATH"] = code
    # run from elsewhere: ``python -m`` puts the working directory first on the path, before PYTHONPATH
    p = subprocess.run([sys.executable, "-m", "wallcli", task, str(Path(path).resolve()), "--json"],
                       capture_output=True, text=True, env=env, cwd=tempfile.gettempdir())
    try:
        r = json.loads(p.stdout)
    except json.JSONDecodeError:
        r = {"error": (p.stderr.strip().splitlines() or ["?"])[-1]}
    keep = {k: r.get(k) for k in ("label", "signal_db", "confident", "reason", "corrections", "error")}
    keep["view"] = {k: (r.get("view") or {}).get(k) for k in ("usable", "reason", "masked", "notes")}
    dst.parent.mkdir(parents=True, exist_ok=True)
    dst.write_text(json.dumps(keep))
    return keep


def judge(clean: dict, alt: dict) -> dict:
    usable = bool(alt["view"].get("usable")) or not clean["view"].get("usable")
    label = alt.get("label") is not None and alt.get("label") == clean.get("label")
    a, b = clean.get("signal_db"), alt.get("signal_db")
    db = a is not None and b is not None and abs(a - b) <= 3.0
    return {"usable": usable, "label": label, "db": db, "kept": usable and label and db,
            "delta": None if a is None or b is None else round(b - a, 2)}


def found(result: dict, kind: str) -> bool:
    """Whether ``result`` lists the kind: an overlay in view.masked, interlace under corrections."""
    if kind == "overlay":
        return bool(result["view"].get("masked"))
    return any(c.get("kind") == kind for c in result.get("corrections") or [])


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--kind", required=True, choices=("overlay", "interlace"))
    ap.add_argument("--out", type=Path, required=True)
    ap.add_argument("--tag", default="after", help="where the answers go (before: main's code, after: this branch)")
    ap.add_argument("--code", default=None, help="PYTHONPATH for the wallcli that answers (default: this one)")
    ap.add_argument("--min-snr", type=float, default=5.0)
    ap.add_argument("--jobs", type=int, default=2)
    ap.add_argument("--table", action="store_true", help="print the table from what is there")
    ap.add_argument("-v", action="store_true", help="also list the cases not kept")
    a = ap.parse_args()
    chosen = clips(a.min_snr)
    alt_dir = a.out / "clips" / a.kind
    alt_dir.mkdir(parents=True, exist_ok=True)
    if not a.table:
        for r in chosen:
            alter(TRANSFER / r["file"], alt_dir / r["file"], a.kind)
        jobs = [(TRANSFER / r["file"], t, a.out / a.tag / "clean" / f"{r['file']}.{t}.json") for r in chosen for t in TASKS]
        jobs += [(alt_dir / r["file"], t, a.out / a.tag / a.kind / f"{r['file']}.{t}.json") for r in chosen for t in TASKS]
        with ThreadPoolExecutor(a.jobs) as pool:
            list(pool.map(lambda j: run(*j, a.code), jobs))
    rows = []
    for r in chosen:
        for t in TASKS:
            c = a.out / a.tag / "clean" / f"{r['file']}.{t}.json"
            x = a.out / a.tag / a.kind / f"{r['file']}.{t}.json"
            if c.exists() and x.exists():
                clean, alt = json.loads(c.read_text()), json.loads(x.read_text())
                rows.append({"file": r["file"], "task": t, "snr_db": float(r["snr_db"]), **judge(clean, alt),
                             "found": found(alt, a.kind), "false": found(clean, a.kind),
                             "view": alt["view"], "corr": [k.get("kind") for k in alt.get("corrections") or []]})
    for t in TASKS + ("both",):
        s = [x for x in rows if t in ("both", x["task"])]
        n = len(s)
        if not n:
            continue
        d = [abs(x["delta"]) for x in s if x["delta"] is not None]
        print(f"| {a.kind} | {a.tag} | {t} | {sum(x['usable'] for x in s)}/{n} | {sum(x['label'] for x in s)}/{n} | "
              f"{sum(x['db'] for x in s)}/{n} | {sum(x['kept'] for x in s)}/{n} | "
              f"{np.median(d) if d else float('nan'):.2f} | {sum(x['found'] for x in s)}/{n} | "
              f"{sum(x['false'] for x in s)}/{n} |")
    if a.v:
        for x in rows:
            if not x["kept"]:
                print(json.dumps(x))


if __name__ == "__main__":
    main()
