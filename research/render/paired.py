"""Pair two `wallcli evaluate --json` outputs clip by clip: right by band, exact interval, McNemar.

    python research/render/paired.py base.json candidate.json

Both must be evaluations of the same folder (same labels.csv). Prints, for the candidate against
the base, the detectable clips right by band with an exact 95 % interval, the clips the candidate
gains and loses, and the exact two-sided McNemar p over the discordant pairs.
"""
from __future__ import annotations

import json
import sys
from math import comb

from wallcli.evaluate.score import exact_ci

BANDS = (("empty", None, None), ("under 0 dB", None, 0.0), ("0-10 dB", 0.0, 10.0), ("10 dB and over", 10.0, None))


def band_of(row) -> str:
    snr = row.get("snr_db")
    if row.get("truth") in (0, "none") or snr is None:
        return "empty"
    return "under 0 dB" if snr < 0 else ("0-10 dB" if snr < 10 else "10 dB and over")


def mcnemar_p(gain: int, loss: int) -> float:
    n = gain + loss
    if n == 0:
        return 1.0
    k = min(gain, loss)
    return min(1.0, 2 * sum(comb(n, i) for i in range(k + 1)) / 2 ** n)


def right(row) -> bool:
    return row.get("error") is None and row["label"] == row["truth"]


def table(rows) -> dict:
    out = {}
    for name, *_ in BANDS:
        sel = [r for r in rows if band_of(r) == name]
        out[name] = (sum(map(right, sel)), len(sel))
    det = [r for r in rows if r.get("detectable", True)]
    k = sum(map(right, det))
    out["detectable"] = (k, len(det), exact_ci(k, len(det)) if det else None)
    return out


def main(base_path: str, cand_path: str) -> None:
    base, cand = (json.load(open(p)) for p in (base_path, cand_path))
    b = {r["file"]: r for r in base["rows"]}
    c = {r["file"]: r for r in cand["rows"]}
    common = sorted(set(b) & set(c))
    for name, ev in (("base", b), ("candidate", c)):
        t = table([ev[f] for f in common])
        k, n, ci = t["detectable"]
        bands = ", ".join(f"{bn} {t[bn][0]}/{t[bn][1]}" for bn, *_ in BANDS)
        ci_s = f" ({ci[0]:.2f}-{ci[1]:.2f})" if ci else ""
        print(f"{name:9s} detectable {k}/{n}{ci_s}; {bands}")
    det = [f for f in common if b[f].get("detectable", True)]
    gain = sum(1 for f in det if right(c[f]) and not right(b[f]))
    loss = sum(1 for f in det if right(b[f]) and not right(c[f]))
    print(f"candidate against base on detectable clips: +{gain} -{loss}, McNemar p = {mcnemar_p(gain, loss):.3g}")


if __name__ == "__main__":
    if len(sys.argv) != 3:
        sys.exit(__doc__)
    main(*sys.argv[1:])
