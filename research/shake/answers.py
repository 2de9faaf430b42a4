"""Session 18: are a still clip's answers kept when the camera shakes, with the shake regressed out?

    .venv/bin/python research/shake/answers.py --seeds 7000 7020 --rms 0.5 --crf 0 --cache /tmp/shk18 > out.jsonl
    .venv/bin/python research/shake/answers.py --table out.jsonl [more.jsonl ...]

For each seed, the scene of ``measure.py`` (base domain, 0-2 people, 10 s, 320x240, a door frame,
a switch plate and a skirting board of 30 % contrast) is rendered still and shaking by ``--rms``
px per axis (exact sub-pixel warps), encoded at ``--crf`` (0: x264's lossless mode), cached, and
read by the product's own path (``classify_video``, every correction on as the commands run it):
the still clip, the shaking clip with ``shake=False`` (``--no-shake``) and the shaking clip as
shipped. One JSON line per seed: each task's (label, signal_db) for the three, the shake found,
and the view check's issues on the shaking clip.
"""
from __future__ import annotations

import argparse
import json
import sys
from pathlib import Path

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE))


def clip(cache: Path, seed: int, rms: float, crf: int) -> Path:
    from measure import _clip

    p = cache / f"s{seed}_{rms}_{crf}.mp4"
    if not p.exists():
        truth = _clip(seed, rms, 0.3, p, crf=crf)
        (cache / f"s{seed}.json").write_text(json.dumps(truth))
    return p


def run(a) -> None:
    from wallcli.camera.corrections import Options
    from wallcli.infer.classify import classify_video
    from wallcli.infer.model import load_model

    a.cache.mkdir(parents=True, exist_ok=True)
    models = {k: load_model(k) for k in ("count", "activity")}
    for s in range(*a.seeds):
        still, shaking = clip(a.cache, s, 0.0, a.crf), clip(a.cache, s, a.rms, a.crf)
        out = {"seed": s, "crf": a.crf, "rms": a.rms, "truth": json.loads((a.cache / f"s{s}.json").read_text())}
        for k, m in models.items():
            ref = classify_video(m, str(still), stride=64)[0]
            off = classify_video(m, str(shaking), stride=64, corrections=Options(shake=False))[0]
            on = classify_video(m, str(shaking), stride=64)[0]
            out[k] = {"still": [ref["label"], ref["signal_db"]], "off": [off["label"], off["signal_db"]],
                      "on": [on["label"], on["signal_db"]],
                      "found": [c for c in on["corrections"] if c["kind"] == "shake"], "view_on": on["view"]["issues"]}
        print(json.dumps(out), flush=True)


def table(files) -> None:
    print("| clips | crf | rms px | count kept, not corrected | corrected | activity kept, not corrected | corrected "
          "| shaking clips the view check refuses |")
    print("|---|---|---|---|---|---|---|---|")
    for f in files:
        rows = [json.loads(x) for x in Path(f).read_text().splitlines() if x.strip()]
        if not rows:
            continue
        kept = {k: [sum(r[k][v][0] == r[k]["still"][0] for r in rows) for v in ("off", "on")]
                for k in ("count", "activity")}
        refused = sum(bool(r["count"]["view_on"]) for r in rows)
        n = len(rows)
        print(f"| {rows[0]['seed']}-{rows[-1]['seed']} | {rows[0]['crf']} | {rows[0]['rms']} | {kept['count'][0]}/{n} | "
              f"{kept['count'][1]}/{n} | {kept['activity'][0]}/{n} | {kept['activity'][1]}/{n} | {refused}/{n} |")


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--seeds", type=int, nargs=2, default=(7000, 7010))
    ap.add_argument("--rms", type=float, default=0.5)
    ap.add_argument("--crf", type=int, default=0)
    ap.add_argument("--cache", type=Path, default=Path("/tmp/shk18"))
    ap.add_argument("--table", nargs="+", help="print the table of these JSON-lines files instead")
    a = ap.parse_args()
    if a.table:
        return table(a.table)
    run(a)


if __name__ == "__main__":
    main()
