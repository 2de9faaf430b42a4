"""Compressed HD exports (issue 36 part 2): does a 720p clip at CRF 23 keep the lossless clip's
answers and signal_db (within 3 dB), and is an empty room's codec residue not read as a signal?

The same seed is simulated twice (the same frames; H.264 at CRF 0 and at CRF 23), both analysed
as `wallcli scan` runs count and activity (one decode, the single commands' answers).

    python research/pipelines/measure_crf.py --out /tmp/crf --walkers 3 --empty 3
"""
from __future__ import annotations

import argparse
import json
import sys
from pathlib import Path


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--out", required=True)
    ap.add_argument("--walkers", type=int, default=3)
    ap.add_argument("--empty", type=int, default=3)
    ap.add_argument("--size", default="1280x720")
    ap.add_argument("--seed0", type=int, default=3600)
    args = ap.parse_args()
    from wallcli.batch.analyse import analyse
    from wallcli.cli.app import main as cli
    from wallcli.infer.twostage import load_classifier

    out = Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    models = {t: load_classifier(t) for t in ("count", "activity")}
    rows = []
    plan = [(1, "walking", args.seed0 + i) for i in range(args.walkers)] + \
           [(0, "none", args.seed0 + 100 + i) for i in range(args.empty)]
    for people, act, seed in plan:
        res = {}
        for crf in (0, 23):
            clip = out / f"s{seed}_p{people}_crf{crf}.mp4"
            if not clip.exists():
                try:
                    cli(["simulate", "-o", str(clip), "--people", str(people), "--activity", act, "--seed", str(seed),
                         "--size", args.size, "--duration", "9", "--crf", str(crf), "--distance", "1,2.5"])
                except SystemExit:
                    pass
            r = analyse(str(clip), ("count", "activity"), models)
            res[crf] = {t: {k: r[t][k] for k in ("label", "confident", "signal_db")} for t in ("count", "activity")}
            res[crf]["view"] = r["view"]["usable"]
            res[crf]["corrections"] = [c["kind"] for c in r["corrections"]]
        rows.append({"seed": seed, "people": people, **{f"crf{k}": v for k, v in res.items()}})
        print(json.dumps(rows[-1]), file=sys.stderr, flush=True)
    (out / "results.json").write_text(json.dumps(rows, indent=1))
    print("| seed | people | view (0 / 23) | count (0 / 23) | activity (0 / 23) | count signal_db (0 / 23) | "
          "activity signal_db (0 / 23) | corrections at 23 |")
    print("|---|---|---|---|---|---|---|---|")
    for r in rows:
        a, b = r["crf0"], r["crf23"]
        print(f"| {r['seed']} | {r['people']} | {a['view']} / {b['view']} | {a['count']['label']} / {b['count']['label']} | "
              f"{a['activity']['label']} / {b['activity']['label']} | {a['count']['signal_db']} / {b['count']['signal_db']} | "
              f"{a['activity']['signal_db']} / {b['activity']['signal_db']} | {', '.join(b['corrections']) or '-'} |")


if __name__ == "__main__":
    main()
