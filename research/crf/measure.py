"""Answer accuracy against H.264 CRF and SNR band, for the same scenes (issue 27, point 3).

Each scene is rendered once by ``wallcli simulate`` at CRF 0 (x264 lossless, 4:2:0: exactly the
frames the camera model hands the encoder) and re-encoded from those decoded YUV frames with PyAV
to CRF 18, 23 and 28, with the options ``wallcli simulate`` gives x264 (preset medium, one thread,
the repeatable instruction set, BT.601 limited range). The x264 input is then the same YUV frames
that ``simulate --crf N`` would feed it, so the re-encode *is* the clip ``simulate --crf N`` writes
(``--verify`` checks that on a short clip: decoded frames identical), at a fraction of the cost of
rendering again.

Every clip goes through :func:`wallcli.batch.analyse.analyse` (one decode; the answers are those of
``wallcli count/activity --json``, shipped models) and its SNR is measured as ``wallcli evaluate``
measures it (green block SNR at the block nearest one plot bin). A scene's band is its SNR **on
the lossless clip** (empty rooms by their truth), so that a scene keeps its band at every CRF and
the table shows what the codec does to it.

One JSON line per (scene, CRF) is appended to ``OUT/results.jsonl`` as it finishes; running the
same command again resumes. ``--table`` prints the tables from that file (Markdown) and writes
``OUT/table.md`` and ``OUT/summary.json``.

    nohup nice -n 15 python research/crf/measure.py --scenes 24 --out runs/crf > runs/crf.log 2>&1 &
    python research/crf/measure.py --out runs/crf --table
    python research/crf/measure.py --verify
"""
from __future__ import annotations

import argparse
import json
import math
import os
import subprocess
import sys
import tempfile
import time
from fractions import Fraction
from pathlib import Path

CRFS = (0, 18, 23, 28)
# (people, activity) cycled over the scenes: empty rooms, every activity alone, two people
SPECS = ((0, "none"), (1, "walking"), (1, "crouching"), (1, "waving"), (1, "jumping"), (1, "none"),
         (2, "walking,walking"), (1, "walking"), (0, "none"), (2, "walking,waving"), (1, "jumping"), (1, "waving"))
BANDS = (("empty", None, None), ("<0 dB", None, 0.0), ("0-10 dB", 0.0, 10.0), (">=10 dB", 10.0, None))


def simulate(out: Path, seed: int, people: int, activity: str, size: str, seconds: float, crf: int = 0,
             distance: str = "1,5") -> dict:
    """Render one clip with the CLI itself (the path users take); returns its ground truth."""
    cmd = [sys.executable, "-m", "wallcli", "simulate", "-o", str(out), "--size", size, "--crf", str(crf),
           "--people", str(people), "--activity", activity, "--seed", str(seed), "--duration", str(seconds),
           "--distance", distance, "--force"]
    subprocess.run(cmd, check=True, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE)
    return json.loads(out.with_suffix(".json").read_text())


def reencode(src: Path, dst: Path, crf: int, fps: float) -> None:
    """Decode ``src`` (4:2:0) and encode its YUV frames with x264 at ``crf``, as VideoWriter does."""
    import av

    from wallcli.io.writer import _x264_repeatable

    with av.open(str(src)) as inp, av.open(str(dst), mode="w") as out:
        s_in = inp.streams.video[0]
        st = out.add_stream("libx264", rate=Fraction(fps).limit_denominator(1001))
        st.options = {"crf": str(crf), "preset": "medium", **_x264_repeatable()}
        st.codec_context.thread_count = 1
        st.width, st.height = s_in.codec_context.width, s_in.codec_context.height
        st.pix_fmt = "yuv420p"
        st.codec_context.colorspace = 6
        st.codec_context.color_range = 1
        for frame in inp.decode(s_in):
            if frame.format.name != "yuv420p":
                raise RuntimeError(f"expected yuv420p frames, got {frame.format.name}")
            # a fresh frame of the same YUV planes: a decoded frame carries its I/P/B type, time base
            # and side data, which FFmpeg's libx264 wrapper reads (encoding the decoded frames as
            # they are gave other output than ``simulate --crf N``; fresh frames give the same)
            frame = av.VideoFrame.from_ndarray(frame.to_ndarray(), format="yuv420p")
            frame.color_range, frame.colorspace = 1, 6
            for p in st.encode(frame):
                out.mux(p)
        for p in st.encode():
            out.mux(p)


def measure(path: Path, models: dict) -> dict:
    from wallcli.batch.analyse import analyse
    from wallcli.evaluate.clip import GREEN, plot_block

    t0 = time.perf_counter()
    a = analyse(str(path), ("count", "activity", "snr"), models)
    snr = a["snr"]
    bins = models["count"].bins
    block = plot_block(snr["roi"], bins, [s["block"] for s in snr["scales"]])
    snr_db = next(float(s["snr_db"][GREEN]) for s in snr["scales"] if s["block"] == block)
    keep = ("label", "confident", "reason", "signal_db", "probabilities")
    return {"frames": a["frames"], "view_usable": a["view"]["usable"], "view_issues": a["view"]["issues"],
            "snr_db": round(snr_db, 2), "snr_block": block, "pixel_snr_db": snr["snr_db"][GREEN],
            "count": {k: a["count"].get(k) for k in keep}, "activity": {k: a["activity"].get(k) for k in keep},
            "analyse_s": round(time.perf_counter() - t0, 1)}


def run(a) -> None:
    from wallcli.infer.model import load_model

    a.out.mkdir(parents=True, exist_ok=True)
    res = a.out / "results.jsonl"
    done = set()
    if res.exists():
        for line in res.read_text().splitlines():
            if line.strip():
                r = json.loads(line)
                done.add((r["seed"], r["crf"], r["size"]))
    models = {t: load_model(t, threads=1) for t in ("count", "activity")}
    work = Path(tempfile.mkdtemp(prefix="crf_", dir=a.work))
    t_all = time.perf_counter()
    specs = [s for s in SPECS if s[0] > 0] if a.people_only else SPECS
    for i in range(a.scenes):
        people, activity = specs[i % len(specs)]
        seed = a.seed + i
        todo = [c for c in CRFS if (seed, c, a.size) not in done]
        if not todo:
            continue
        t0 = time.perf_counter()
        src = work / f"s{seed}_crf0.mp4"
        truth = simulate(src, seed, people, activity, a.size, a.seconds, crf=0, distance=a.distance)
        t_render = time.perf_counter() - t0
        for crf in CRFS:
            if crf not in todo:
                continue
            t1 = time.perf_counter()
            clip = src if crf == 0 else work / f"s{seed}_crf{crf}.mp4"
            if crf:
                reencode(src, clip, crf, truth["fps"])
            t_enc = time.perf_counter() - t1
            m = measure(clip, models)
            row = {"seed": seed, "size": a.size, "seconds": a.seconds, "distance": a.distance, "crf": crf, "people": truth["people"],
                   "truth_activity": truth["activity"], "activities": truth.get("activities"), "bytes": clip.stat().st_size,
                   "render_s": round(t_render, 1) if crf == 0 else None, "encode_s": round(t_enc, 1), **m}
            with res.open("a") as fh:
                fh.write(json.dumps(row) + "\n")
            print(f"seed {seed} crf {crf:2d}: people {row['people']} {row['truth_activity']:9s} snr {m['snr_db']:6.1f} dB"
                  f" count {m['count']['label']} ({m['count']['signal_db']} dB) activity {m['activity']['label']}"
                  f"  [{row['bytes'] / 1e6:.1f} MB, render {t_render:.0f} s, encode {t_enc:.0f} s,"
                  f" analyse {m['analyse_s']:.0f} s]", flush=True)
            if crf:
                clip.unlink()
        src.unlink()
        src.with_suffix(".json").unlink()
        print(f"scene {i + 1}/{a.scenes} done, {time.perf_counter() - t_all:.0f} s so far", flush=True)
    work.rmdir()


# ------------------------------------------------------------------------------------------ tables
def band_of(people: int, snr_db: float) -> str:
    if people == 0:
        return "empty"
    return next(n for n, lo, hi in BANDS[1:] if (lo is None or snr_db >= lo) and (hi is None or snr_db < hi))


def wilson(k: int, n: int):
    # evaluate's intervals are exact (Clopper-Pearson) since #54.2; the name stays for the tables' code
    from wallcli.evaluate.score import exact_ci

    return exact_ci(k, n) if n else (0.0, 1.0)


def cell(k: int, n: int) -> str:
    if not n:
        return "–"
    lo, hi = wilson(k, n)
    return f"{k}/{n} [{lo:.2f}, {hi:.2f}]"


def _median(v):
    v = sorted(v)
    n = len(v)
    return None if not n else (v[n // 2] if n % 2 else 0.5 * (v[n // 2 - 1] + v[n // 2]))


def tables(out: Path) -> str:
    rows = [json.loads(x) for x in (out / "results.jsonl").read_text().splitlines() if x.strip()]
    # the scene's band: its lossless clip's measured SNR
    lossless = {(r["seed"], r["size"]): r for r in rows if r["crf"] == 0}
    scenes = {k: r for k, r in lossless.items() if all((k[0], c, k[1]) in {(x["seed"], x["crf"], x["size"]) for x in rows}
                                                     for c in CRFS)}
    rows = [r for r in rows if (r["seed"], r["size"]) in scenes]
    for r in rows:
        r["band"] = band_of(r["people"], lossless[(r["seed"], r["size"])]["snr_db"])
        r["count_ok"] = _right(r, "count")
    sizes = sorted({r["size"] for r in rows})
    L = [f"Scenes: {len(scenes)} ({', '.join(sizes)}, "
         f"{', '.join(sorted({str(r['seconds']) + ' s' for r in rows}))}); each at CRF {', '.join(map(str, CRFS))} "
         "(0 = lossless). Band: the scene's measured SNR on its lossless clip (evaluate's SNR), empty rooms by "
         "truth. Cells: right/clips [Wilson 95 %].", ""]
    summary: dict = {"scenes": len(scenes), "sizes": sizes, "crfs": list(CRFS), "count": {}, "activity": {}}
    for task in ("count", "activity"):
        sel = [r for r in rows if task == "count" or r["people"] <= 1]
        L += [f"**{task}**" + (" (clips with at most one person; an empty room's truth is 'none')" if task == "activity"
                               else ""), "",
              "| CRF | " + " | ".join(n for n, *_ in BANDS) + " | all | decided right/decided | view refused |",
              "|---|" + "---|" * (len(BANDS) + 3)]
        for crf in CRFS:
            rc = [r for r in sel if r["crf"] == crf]
            cells, per = [], {}
            for name, *_ in BANDS:
                b = [r for r in rc if r["band"] == name]
                k = sum(_right(r, task) for r in b)
                cells.append(cell(k, len(b)))
                per[name] = {"clips": len(b), "right": k, "ci95": wilson(k, len(b)),
                             "decided": sum(bool(r[task]["confident"]) for r in b),
                             "decided_right": sum(bool(r[task]["confident"]) and _right(r, task) for r in b)}
            k = sum(_right(r, task) for r in rc)
            dec = [r for r in rc if r[task]["confident"]]
            kd = sum(_right(r, task) for r in dec)
            L.append(f"| {crf if crf else 'lossless'} | " + " | ".join(cells) + f" | {cell(k, len(rc))} | {kd}/{len(dec)} |"
                     f" {sum(not r['view_usable'] for r in rc)} |")
            summary[task][str(crf)] = {"bands": per, "clips": len(rc), "right": k, "decided": len(dec), "decided_right": kd,
                                       "view_refused": sum(not r["view_usable"] for r in rc)}
        L.append("")
    # what the codec does to the signal: signal_db (count) and measured SNR, per band, against lossless
    L += ["**signal against CRF** (median over the band's scenes; count's `signal_db`, and evaluate's measured SNR; "
          "dB)", "",
          "| band | " + " | ".join(f"CRF {c if c else 'lossless'}" for c in CRFS) + " |", "|---|" + "---|" * len(CRFS)]
    summary["signal"] = {}
    for name, *_ in BANDS:
        cols = []
        for crf in CRFS:
            b = [r for r in rows if r["band"] == name and r["crf"] == crf]
            s, m = _median([r["count"]["signal_db"] for r in b]), _median([r["snr_db"] for r in b])
            cols.append("–" if s is None else f"{s:.1f} / {m:.1f}")
            summary["signal"].setdefault(name, {})[str(crf)] = {"signal_db": s, "snr_db": m, "clips": len(b)}
        L.append(f"| {name} | " + " | ".join(cols) + " |")
    L.append("")
    # per-scene: lossless SNR, and which CRFs keep count's lossless answer right
    L += ["**per scene** (count: label at each CRF, ✗ wrong; `signal_db` at lossless and 28)", "",
          "| seed | people | activity | distance m | SNR lossless | " + " | ".join(f"CRF {c if c else 'lossless'}" for c in CRFS)
          + " | signal lossless → 28 |", "|---|---|---|---|---|" + "---|" * (len(CRFS) + 1)]
    for key in sorted(scenes, key=lambda k: (lossless[k]["snr_db"] if lossless[k]["people"] else -1e9, k)):
        per = {r["crf"]: r for r in rows if (r["seed"], r["size"]) == key}
        z = lossless[key]
        marks = [f"{per[c]['count']['label']}{'' if per[c]['count_ok'] else ' ✗'}" for c in CRFS]
        L.append(f"| {key[0]} | {z['people']} | {z['truth_activity']} | {z.get('distance', '1,5') if z['people'] else '–'}"
                 f" | {z['snr_db']:.1f} | " + " | ".join(marks)
                 + f" | {per[0]['count']['signal_db']:.1f} → {per[28]['count']['signal_db']:.1f} |")
    L.append("")
    summary["limit"] = limit(rows, scenes, lossless)
    L += [summary["limit"]["sentence"], ""]
    return "\n".join(L), summary


def _right(r: dict, task: str) -> bool:
    if task == "count":
        return r["count"]["label"] == r["people"]
    return r["activity"]["label"] == r["truth_activity"]


def limit(rows, scenes, lossless) -> dict:
    """The statements for the README, from the rows. Per lossy CRF, over the scenes with people that
    count gets right lossless: how many it still gets right ('kept') and how many it gets wrong
    ('lost'), the highest lossless SNR among the lost and the lowest among the kept; and how many
    scenes with people it answers '0 people' (the signal erased)."""
    out, sentences = {}, []
    for crf in CRFS[1:]:
        lost, kept, zero, withp, zsnr, seen = [], [], 0, 0, [], []
        for key in scenes:
            z = lossless[key]
            if not z["people"]:
                continue
            r = next(x for x in rows if (x["seed"], x["size"]) == key and x["crf"] == crf)
            withp += 1
            zero += r["count"]["label"] == 0
            (zsnr if r["count"]["label"] == 0 else seen).append(z["snr_db"])
            if z["count"]["label"] != z["people"]:
                continue
            (kept if r["count"]["label"] == r["people"] else lost).append(z["snr_db"])
        o = out[str(crf)] = {"lost_max_snr": max(lost) if lost else None, "kept_min_snr": min(kept) if kept else None,
                             "lost": len(lost), "kept": len(kept), "with_people": withp, "answered_zero": zero}
        if not o["lost"]:
            txt = f"at CRF {crf} count kept every answer it got right lossless ({o['kept']} scenes with people)"
        else:
            x = o["lost_max_snr"]
            above = [k for k in kept if k > x]
            o["kept_above"] = len(above)
            txt = (f"at CRF {crf} count lost {o['lost']} of the {o['lost'] + o['kept']} scenes with people it got right "
                   f"lossless, all at a lossless SNR of {x:.1f} dB or under (it kept {o['kept'] - len(above)} there), "
                   + (f"and kept all {len(above)} above it" if above else "and no scene above it was measured"))
        o["erased_max_snr"] = max(zsnr) if zsnr else None
        o["seen_above"] = sum(v > o["erased_max_snr"] for v in seen) if zsnr else len(seen)
        txt += f"; it answered '0 people' (the person erased) on {zero} of all {withp} scenes with people"
        if zsnr:
            txt += (f", none of lossless SNR over {o['erased_max_snr']:.1f} dB ({o['seen_above']} scenes above it, each "
                    f"answered 1 or 2 people; under it {len(zsnr)} of {len(zsnr) + len(seen) - o['seen_above']} erased)")
        sentences.append("- " + txt[0].upper() + txt[1:] + ".")
    return {"per_crf": out, "sentence": "\n".join(sentences)}


def verify(a) -> None:
    """simulate --crf N directly == simulate --crf 0 re-encoded at N, on a short clip (decoded frames)."""
    import numpy as np

    from wallcli.io.video import open_video

    def frames(p):
        with open_video(p) as r:
            return np.stack([f.planes.rgb() for f in r.frames()])

    with tempfile.TemporaryDirectory(dir=a.work) as tmp:
        tmp = Path(tmp)
        t = simulate(tmp / "l.mp4", 7, 1, "walking", a.size, 1.0, crf=0)
        for crf in CRFS[1:]:
            simulate(tmp / f"d{crf}.mp4", 7, 1, "walking", a.size, 1.0, crf=crf)
            reencode(tmp / "l.mp4", tmp / f"r{crf}.mp4", crf, t["fps"])
            same = np.array_equal(frames(tmp / f"d{crf}.mp4"), frames(tmp / f"r{crf}.mp4"))
            print(f"CRF {crf}: simulate directly vs re-encoded lossless: decoded frames "
                  f"{'identical' if same else 'DIFFERENT'}", flush=True)


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--out", type=Path, default=Path("runs/crf"))
    ap.add_argument("--scenes", type=int, default=12)
    ap.add_argument("--seed", type=int, default=2700)
    ap.add_argument("--size", default="1280x720")
    ap.add_argument("--seconds", type=float, default=10.0, help="clip length (>= 10 s gives each model one window)")
    ap.add_argument("--distance", default="1,5", help="MIN,MAX distance of people from the wall (m), as simulate's")
    ap.add_argument("--people-only", action="store_true", help="no empty rooms (e.g. for a batch of near scenes)")
    ap.add_argument("--work", default=None, help="folder for the temporary clips (default: the system's)")
    ap.add_argument("--table", action="store_true", help="print the tables from OUT/results.jsonl")
    ap.add_argument("--verify", action="store_true", help="check that re-encoding equals simulate --crf N")
    a = ap.parse_args()
    os.environ.setdefault("OMP_NUM_THREADS", "1")
    if a.verify:
        return verify(a)
    if a.table:
        text, summary = tables(a.out)
        (a.out / "table.md").write_text(text + "\n")
        (a.out / "summary.json").write_text(json.dumps(summary, indent=1) + "\n")
        print(text)
        return
    run(a)


if __name__ == "__main__":
    main()
