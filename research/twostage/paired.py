"""Paired comparison of two `wallcli evaluate --json` outputs on the same clips: clips right by band
and on the detectable ones, gains and losses, exact McNemar p.

    python research/twostage/paired.py BASE.json CANDIDATE.json [...]
"""
import json
import math
import sys


def mcnemar(g, l):
    n = g + l
    return 1.0 if n == 0 else min(1.0, 2 * sum(math.comb(n, i) for i in range(min(g, l) + 1)) / 2**n)


def bands(d):
    return " ".join(f"{b['band']} {b['correct']}/{b['clips']}" for b in d["by_band"]) + f" | detectable {d['correct']}/{d['scored']} decided {d['decided']} ({d.get('correct_decided')})"


base = json.load(open(sys.argv[1]))
print(f"{sys.argv[1]}: {bands(base)}")
ra = {r["file"]: r for r in base["rows"]}
for p in sys.argv[2:]:
    d = json.load(open(p))
    g = sum(1 for r in d["rows"] if r["detectable"] and r["correct"] and not ra[r["file"]]["correct"])
    l = sum(1 for r in d["rows"] if r["detectable"] and not r["correct"] and ra[r["file"]]["correct"])
    print(f"{p}: {bands(d)} | +{g} -{l} McNemar p = {mcnemar(g, l):.3f}")
