"""The other recorder kinds on measure45's eight clips: interlace (measure.py's weave, H.264 CRF 0),
white-balance hunting of 1 % (measure_kind.py's, FFV1, against its clean FFV1 copy) and a DVR's
padding (every sixth frame replaced by the one before it, H.264 CRF 0). Count and activity each
(`wallcli count/activity X --json` in-process, the code on PYTHONPATH); a case is kept when the view
is usable as the clean copy's, the label is the clean copy's, and `signal_db` is within 3 dB of it.

    python research/pipelines/measure_more.py make --out /tmp/k25
    PYTHONPATH=/tmp/base python research/pipelines/measure_more.py run --out /tmp/k25 --tag before
    python research/pipelines/measure_more.py run --out /tmp/k25 --tag after
    python research/pipelines/measure_more.py table --out /tmp/k25 --tag before,after
"""
from __future__ import annotations

import argparse
import contextlib
import io
import json
import sys
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))

import measure45  # noqa: E402

KINDS = {"interlace": ".mp4", "awb": "_clean.mkv", "dups": ".mp4"}  # kind: its clean copy's suffix


def _dups(src: Path, dst: Path, every: int = 6) -> None:
    import av

    with av.open(str(src)) as inp, av.open(str(dst), "w") as out:
        vs = inp.streams.video[0]
        st = out.add_stream("libx264", rate=vs.average_rate)
        st.width, st.height, st.pix_fmt = vs.codec_context.width, vs.codec_context.height, "yuv420p"
        st.options = {"crf": "0", "preset": "medium"}
        prev = None
        for i, f in enumerate(inp.decode(vs)):
            a = f.to_ndarray(format="yuv420p")
            if i % every == every - 1 and prev is not None:
                a = prev  # a DVR's padding: the frame before, again
            prev = a
            for p in st.encode(av.VideoFrame.from_ndarray(a, format="yuv420p")):
                out.mux(p)
        for p in st.encode():
            out.mux(p)


def make(out: Path) -> None:
    import measure
    import measure_kind

    out.mkdir(parents=True, exist_ok=True)
    for i, r in enumerate(measure45.chosen()):
        src = measure45.TRANSFER / r["file"]
        stem = src.stem
        measure.alter(src, out / f"{stem}_interlace.mp4", "interlace")
        for kind, strength in (("clean", 0.0), ("awb", 0.01)):
            if not (out / f"{stem}_{kind}.mkv").exists():
                measure_kind._alter(src, out / f"{stem}_{kind}.mkv", kind if kind != "clean" else "none", strength, i)
        if not (out / f"{stem}_dups.mp4").exists():
            _dups(src, out / f"{stem}_dups.mp4")
        print(stem, file=sys.stderr, flush=True)


def _files(out: Path) -> list[Path]:
    stems = [measure45.TRANSFER / r["file"] for r in measure45.chosen()]
    made = [out / f"{s.stem}_{k}{'.mkv' if k in ('awb', 'clean') else '.mp4'}" for s in stems
            for k in ("interlace", "awb", "clean", "dups")]
    return stems + made


def run(out: Path, tag: str) -> None:
    from wallcli.cli.app import main as cli

    with open(out / f"more_{tag}.jsonl", "w") as fh:
        for clip in _files(out):
            rec = {"clip": clip.name}
            for task in ("count", "activity"):
                buf = io.StringIO()
                with contextlib.redirect_stdout(buf), contextlib.redirect_stderr(io.StringIO()):
                    try:
                        cli([task, str(clip), "--json"])
                    except SystemExit:
                        pass
                r = json.loads(buf.getvalue())
                rec[task] = {"label": r["label"], "db": r["signal_db"], "usable": r["view"]["usable"]}
            fh.write(json.dumps(rec) + "\n")


def table(out: Path, tags: str) -> None:
    for tag in tags.split(","):
        res = {json.loads(line)["clip"]: json.loads(line) for line in open(out / f"more_{tag}.jsonl")}
        kept = total = 0
        for kind, clean in KINDS.items():
            for task in ("count", "activity"):
                k = n = 0
                misses = []
                for name, rec in res.items():
                    if not name.rsplit(".", 1)[0].endswith("_" + kind):
                        continue
                    stem = name.rsplit("_", 1)[0]
                    a, b = rec[task], res[stem + clean][task]
                    ok = a["usable"] == b["usable"] and a["label"] == b["label"] and abs(a["db"] - b["db"]) <= 3
                    n, k = n + 1, k + ok
                    if not ok:
                        misses.append(f"{stem}: {b['label']} -> {a['label']}, {a['db'] - b['db']:+.2f} dB")
                print(f"| {tag} | {kind} | {task} | {k}/{n} | {'; '.join(misses)} |")
                kept, total = kept + k, total + n
        print(f"{tag}: {kept}/{total} kept")


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("step", choices=("make", "run", "table"))
    ap.add_argument("--out", required=True)
    ap.add_argument("--tag", default="after")
    args = ap.parse_args()
    out = Path(args.out)
    {"make": lambda: make(out), "run": lambda: run(out, args.tag), "table": lambda: table(out, args.tag)}[args.step]()


if __name__ == "__main__":
    main()
