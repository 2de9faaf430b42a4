"""A quicker check of the exposure and drift corrections than ``measure.py``, and its diagnosis.

For each seed, the clip of ``measure.py`` (same simulation, same injected nuisances) is kept in
CACHE (simulated once, injected once), and its clean, exposure and drift versions are analysed as
``wallcli scan`` does with the corrections on (the code on ``PYTHONPATH``, so an older commit's
tree can be measured on the same cached clips). One JSON per seed in OUT; with ``--rec`` also
every ``corrections.fit`` call's input levels (OUT/SEED.pkl), so the fit can be rerun offline on
the profiles (``--offline``: the residue each fit leaves against the clean clip's, relative to
the clean profile's own variation, the worst over a clip's fits).

    nice -n 10 python research/corrections/quick.py --out /tmp/q-new --cache /tmp/q-clips --seeds 7100 7120 --rec
    git archive OLD | tar -x -C /tmp/old    # an older commit's code on the same cached clips:
    PYTHONPATH=/tmp/old python research/corrections/quick.py --out /tmp/q-old --cache /tmp/q-clips --seeds 7100 7120
    python research/corrections/quick.py --table /tmp/q-old /tmp/q-new
    python research/corrections/quick.py --offline /tmp/q-new --kind exposure
"""
from __future__ import annotations

import argparse
import json
import pickle
import subprocess
import sys
import time
from pathlib import Path

import numpy as np

KINDS = ("none", "exposure", "drift")


def _clip(cache: Path, seed: int, kind: str) -> Path:
    from research.corrections import measure as M
    from wallcli.sim.inject import inject

    src = cache / f"s{seed}.mkv"
    if not src.exists():
        people = seed % 3
        act = M.ACTIVITIES[(seed // 3) % len(M.ACTIVITIES)]
        cmd = [sys.executable, "-m", "wallcli", "simulate", "-o", str(src), "--people", str(people), "--seed", str(seed),
               "--size", "128x96", "--duration", "10.5", "--fps", "30", "--force"]
        if people:
            cmd += ["--activity", act]
        subprocess.run(cmd, check=True, capture_output=True)
    p = cache / f"s{seed}-{kind}.mkv"
    if not p.exists():
        inject(src, p, kind, strength=0.0 if kind == "none" else M.NUISANCES[kind], seed=seed)
    return p


def run(out: Path, cache: Path, seeds, rec: bool) -> None:
    from wallcli.batch.analyse import analyse
    from wallcli.camera import corrections as C
    from wallcli.evaluate.clip import GREEN, plot_block
    from wallcli.infer.model import load_model

    calls = []
    fit = C.fit

    def recording(levels, rate, **kw):
        calls.append({"levels": np.asarray(levels, np.float32), "rate": rate, "t0": kw.get("t0", 0.0),
                      "part": None if kw.get("part") is None else np.asarray(kw["part"]),
                      "lines": list(kw.get("lines", ()))})
        return fit(levels, rate, **kw)

    C.fit = recording
    out.mkdir(parents=True, exist_ok=True)
    cache.mkdir(parents=True, exist_ok=True)
    models = {t: load_model(t, None) for t in ("count", "activity")}
    for seed in seeds:
        if (out / f"{seed}.json").exists():
            continue
        t0 = time.time()
        line, recs = {"seed": seed, "people": seed % 3}, {}
        for kind in KINDS:
            calls.clear()
            res = analyse(str(_clip(cache, seed, kind)), ("count", "activity", "snr"), models, corrections=C.Options())
            scales = {s["block"]: s for s in res["snr"]["scales"]}
            block = plot_block(res["snr"]["roi"], models["count"].bins, list(scales))
            line[kind] = {"count": res["count"]["label"], "activity": res["activity"]["label"],
                          "snr_db": scales[block]["snr_db"][GREEN], "corr_count": res["count"]["corrections"],
                          "corr_snr": res["snr"]["corrections"]}
            recs[kind] = list(calls)
        if rec:
            with open(out / f"{seed}.pkl", "wb") as f:
                pickle.dump(recs, f)
        line["seconds"] = round(time.time() - t0, 1)
        (out / f"{seed}.json").write_text(json.dumps(line))
        print(seed, line["seconds"], flush=True)


def table(out: Path) -> list[str]:
    rows = {int(p.stem): json.loads(p.read_text()) for p in out.glob("*.json")}
    seeds = sorted(rows)
    lines = []
    for kind in ("exposure", "drift"):
        ref = {s: rows[s]["none"] for s in seeds}
        both = [s for s in seeds if (rows[s][kind]["count"], rows[s][kind]["activity"]) == (ref[s]["count"], ref[s]["activity"])]
        sig = [s for s in seeds if ref[s]["snr_db"] >= -10]
        ratio = {s: 10 ** ((rows[s][kind]["snr_db"] - ref[s]["snr_db"]) / 10) for s in sig}
        within = [s for s in sig if abs(ratio[s] - 1) <= 0.1]
        faint = [s for s in seeds if s not in sig]
        quiet = [s for s in faint if rows[s][kind]["snr_db"] < -10]
        lines.append(f"| {out.name} | {seeds[0]}-{seeds[-1]} | {kind} | {len(both)}/{len(seeds)} | {len(within)}/{len(sig)} | "
                     f"{len(quiet)}/{len(faint)} | {', '.join(map(str, (s for s in seeds if s not in both))) or '-'} | "
                     f"{', '.join(f'{s} ({ratio[s]:.2f})' for s in sig if s not in within) or '-'} |")
    fp = [s for s in seeds if rows[s]["none"]["corr_count"] or rows[s]["none"]["corr_snr"]]
    lines.append(f"| {out.name} | {seeds[0]}-{seeds[-1]} | clean: anything found | {len(fp)}/{len(seeds)} | | | "
                 f"{', '.join(map(str, fp)) or '-'} | |")
    return lines


def offline(out: Path, kind: str) -> list[str]:
    from wallcli.camera import corrections as C

    def rel(x):
        return x / x.mean(0) - 1

    lines = []
    for p in sorted(out.glob("*.pkl")):
        recs = pickle.load(open(p, "rb"))
        worst = []
        for rc, rk in zip(recs["none"], recs[kind]):
            kw = dict(lines=rk["lines"], t0=rk["t0"], part=rk["part"])
            lc, lk = rc["levels"].astype(np.float64), rk["levels"].astype(np.float64)
            fc, fk = C.fit(lc, rk["rate"], **kw), C.fit(lk, rk["rate"], **kw)
            base = rel(lc / (1 + (fc.gain if fc else 0)))
            got = rel(lk / (1 + (fk.gain if fk else 0)))
            worst.append(float(np.sqrt(np.mean((got - base) ** 2)) / np.sqrt(np.mean(rel(lc) ** 2))))
        lines.append(f"{p.stem} {max(worst):.3f}")
    return lines


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--out", type=Path)
    ap.add_argument("--cache", type=Path)
    ap.add_argument("--seeds", type=int, nargs=2, metavar=("FIRST", "END"))
    ap.add_argument("--rec", action="store_true", help="keep every fit's input levels (OUT/SEED.pkl)")
    ap.add_argument("--table", type=Path, nargs="+")
    ap.add_argument("--offline", type=Path)
    ap.add_argument("--kind", default="exposure")
    a = ap.parse_args()
    if a.table:
        print("| run | seeds | version | both kept | SNR within 10 % | no signal stays under -10 dB | answers lost | SNR off (ratio) |")
        print("|---|---|---|---|---|---|---|---|")
        for d in a.table:
            print("\n".join(table(d)))
    elif a.offline:
        print("\n".join(offline(a.offline, a.kind)))
    else:
        run(a.out, a.cache, range(*a.seeds), a.rec)


if __name__ == "__main__":
    main()
