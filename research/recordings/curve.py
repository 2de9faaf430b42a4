"""A learning curve on the recordings: out-of-fold detectable accuracy against training rooms.

For every held-out fold (clip number mod 5, as everywhere here) the candidate is fitted on 25, 50,
75 or 100 % of that fold's training rooms (the other 4 folds' clips) and answers the held-out fold,
which never changes. The subsets are nested: one random order of all clips per draw
(numpy default_rng(seed).permutation of the sorted clip names, seeds 0..19, written to
curve_draws.json next to this script); a fold's q-subset is the first round(q * n) of its training
clips in that order, so the 25 % subset lies inside the 50 % one and so on. At 100 % every draw is
the same fit.

Candidates (all numpy / scipy, cheap on 2 cores; no torch):
  count     shipped   count 0.4.1 in two stages with activity 0.3.1 (never trained on the recordings:
                      the same answers at every fraction)
            G shallow aggregate.py: mean + max of the presence and how-many logits of the clip's
                      stride-16 windows, multinomial logistic regression, C = 1, all training rows
                      (the setting the nested choice picked)
            G dist+phys  aggregate.py's richest set (44 numbers), C = 0.1, all rows (to see whether
                      capacity pays once there are more rooms)
            A logp    logistic regression on both nets' per-window log-probabilities (8 numbers,
                      standardised), trained on every stride-16 window of the training clips labelled
                      by its clip, C = 1 (C * sum log-loss + |W|^2 / 2); the clip's answer is the mean
                      of its stride-64 windows' probabilities, as inference does
  activity  net       activity 0.3.1's net alone (no recordings)
            F split   the shipped recipe of activity 0.4.0: the net, with waving/jumping re-split by the
                      Newton logistic regression (L2 = 1) on the 19 physical features
                      (wallcli.infer.split.fit), fitted on the training rooms' detectable
                      waving/jumping clips (split_oof.py)
            A logp    as for count, 5 classes, on the clips with at most one person

Folds (--folds): 'fixed' (default) is the rule used everywhere here, the clip's number mod 5
(wallcli.train.recordings.fold_of); each of its folds is exactly one kind of light (fold 0 window_back,
1 window_side, 2 ceiling, 3 ceiling_window, 4 two_lamps; research/track/README.md), so its figures
measure transfer to an unseen kind of light. 'balanced' is (number // 5) % 5, declared after that
confound was found and before any curve on it: every light in every fold (9-10 clips of each).
Everything else (draws, seeds, fractions, candidates, settings) is the same under both rules.

Figures: detectable clips right (count 185, activity 157 on 229 clips) with exact 95 %
Clopper-Pearson intervals; per fraction the mean over draws, the range of the draws, and the
interval of the rounded mean (the sampling error of one held-out set of this size). Run: python research/recordings/curve.py [--draws 5] [--folds balanced] (the windows'
outputs come from runs/aggregate_windows.npz, made by aggregate.py if missing). Writes
runs/curve.json and research/recordings/curve.png (balanced: runs/curve_balanced.json and
research/recordings/curve_balanced.png).
"""
from __future__ import annotations

import argparse
import json
import os
import re
import sys
import zlib
from pathlib import Path

import numpy as np
from scipy.stats import beta

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from common import ACT_CLASSES, CACHE, K, ROOT, mcnemar, recordings  # noqa: E402
from aggregate import OUT as WINDOWS, clip_features, fit_mlr, window_outputs  # noqa: E402
from wallcli.infer.split import Split, fit as split_fit  # noqa: E402
from wallcli.train.recordings import fold_of  # noqa: E402

HERE = Path(__file__).resolve().parent
FRACTIONS = (0.25, 0.5, 0.75, 1.0)
BANDS = ("empty", "<0", "0-10", ">=10")


def fold_balanced(name: str, k: int) -> int:
    """The lighting-balanced rule, (number // 5) % 5 (a name without digits: fold_of's CRC-32)."""
    assert k == 5, "the balanced rule is declared for 5 folds"
    digits = re.findall(r"\d+", Path(Path(name).name).stem)
    if digits:
        return (int(digits[0]) // 5) % 5
    return zlib.crc32(Path(name).name.encode("utf-8")) % k


FOLD_RULES = {"fixed": fold_of, "balanced": fold_balanced}


def clopper_pearson(k: int, n: int, a: float = 0.05) -> tuple[float, float]:
    lo = 0.0 if k == 0 else float(beta.ppf(a / 2, k, n - k + 1))
    hi = 1.0 if k == n else float(beta.ppf(1 - a / 2, k + 1, n - k))
    return lo, hi


def subsets(names, folds, order, q):
    """{fold: boolean mask of its training clips kept at fraction q} for one draw's order."""
    rank = {nm: i for i, nm in enumerate(order)}
    out = {}
    for f in range(K):
        tr = np.flatnonzero(folds != f)
        tr = tr[np.argsort([rank[names[j]] for j in tr], kind="stable")]
        m = np.zeros(len(names), bool)
        m[tr[:int(round(q * len(tr)))]] = True
        out[f] = m
    return out


class Data:
    def __init__(self, W, recs, fold_rule=fold_of):
        self.names = list(W["names"])
        assert self.names == [r.name for r in recs], "the window file and the recordings disagree"
        n = len(self.names)
        self.folds = np.array([fold_rule(nm, K) for nm in self.names])
        self.people = W["people"].astype(int)
        self.det = W["detectable"].astype(bool)
        self.bands = np.array(["empty" if p == 0 else "<0" if not (s >= 0) else "0-10" if s < 10 else ">=10"
                               for p, s in zip(self.people, W["snr"])])
        self.single = np.array([r.persons <= 1 for r in recs])
        self.act = np.array([ACT_CLASSES.index(r.activity) if r.persons <= 1 else -1 for r in recs])
        clip, at64 = W["clip"], W["at64"].astype(bool)
        self.clip, self.at64 = clip, at64
        self.shipped_count = W["shipped"]
        self.net_act = np.stack([W["pa"][(clip == j) & at64].mean(0) for j in range(n)])
        self.phys = np.stack([W["feat"][(clip == j) & at64].mean(0) for j in range(n)])
        self.G = clip_features(W)
        self.lp = np.concatenate([np.log(np.clip(W["pc"], 1e-6, 1)), np.log(np.clip(W["pa"], 1e-6, 1))], 1)


def g_answers(D, fs, C, train):
    pred = np.zeros(len(D.names), int)
    for f in range(K):
        model = fit_mlr(D.G[fs][train[f]], D.people[train[f]], C)
        te = D.folds == f
        pred[te] = model(D.G[fs][te]).argmax(1)
    return pred


def a_answers(D, task, train, C=1.0):
    y = D.people if task == "count" else D.act
    k = 3 if task == "count" else len(ACT_CLASSES)
    ok = np.ones(len(y), bool) if task == "count" else D.single
    pred = np.full(len(y), -1)
    for f in range(K):
        trw = np.isin(D.clip, np.flatnonzero(train[f] & ok))
        mu, sd = D.lp[trw].mean(0), D.lp[trw].std(0) + 1e-6
        model = fit_mlr((D.lp[trw] - mu) / sd, y[D.clip[trw]], C, k)
        for j in np.flatnonzero((D.folds == f) & ok):
            w = (D.clip == j) & D.at64
            L = model((D.lp[w] - mu) / sd)
            P = np.exp(L - L.max(1, keepdims=True))
            pred[j] = (P / P.sum(1, keepdims=True)).mean(0).argmax()
    return pred


def f_answers(D, train, l2=1.0):
    pair = [ACT_CLASSES.index("waving"), ACT_CLASSES.index("jumping")]
    sel = np.isin(D.act, pair) & D.det & D.single
    yb = (D.act == pair[1]).astype(float)
    pred = np.full(len(D.names), -1)
    for f in range(K):
        tr = sel & train[f]
        blk = split_fit(D.phys[tr], yb[tr], l2=l2)
        blk["pair"] = ["waving", "jumping"]
        sp = Split(blk, ACT_CLASSES)
        for j in np.flatnonzero((D.folds == f) & D.single):
            pred[j] = int(sp.apply(D.net_act[j], D.phys[j])[0].argmax())
    return pred


def score(D, task, pred):
    y = D.people if task == "count" else D.act
    scored = D.det & (True if task == "count" else D.single)
    right = (pred == y)
    return int(right[scored].sum()), int(scored.sum()), right


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--draws", type=int, default=20)
    ap.add_argument("--folds", choices=sorted(FOLD_RULES), default="fixed",
                    help="fixed: number mod 5 (one light per fold); balanced: (number // 5) % 5")
    a = ap.parse_args()
    sfx = "" if a.folds == "fixed" else "_" + a.folds
    W = {k: v for k, v in np.load(WINDOWS).items()} if WINDOWS.is_file() else window_outputs(CACHE)
    recs = recordings()
    D = Data(W, recs, FOLD_RULES[a.folds])
    names_sorted = sorted(D.names)
    draws = {str(s): [str(x) for x in np.random.default_rng(s).permutation(names_sorted)] for s in range(a.draws)}
    (HERE / "curve_draws.json").write_text("{\n" + ",\n".join(f'"{s}": {json.dumps(v)}' for s, v in draws.items()) + "\n}\n")
    ntrain = {f: int((D.folds != f).sum()) for f in range(K)}
    print("folds", a.folds, "clips", len(D.names), "training rooms per fold", ntrain)

    ship_c = D.shipped_count.argmax(1)
    ship_a = D.net_act.argmax(1)
    base = {"count": score(D, "count", ship_c)[2], "activity": score(D, "activity", ship_a)[2]}
    cands = {
        ("count", "shipped (no recordings)"): lambda tr: ship_c,
        ("count", "G shallow, C = 1"): lambda tr: g_answers(D, "shallow", 1.0, tr),
        ("count", "G dist+phys, C = 0.1"): lambda tr: g_answers(D, "dist+phys", 0.1, tr),
        ("count", "A log-probabilities"): lambda tr: a_answers(D, "count", tr),
        ("activity", "net alone (no recordings)"): lambda tr: ship_a,
        ("activity", "F split (shipped recipe)"): lambda tr: f_answers(D, tr),
        ("activity", "A log-probabilities"): lambda tr: a_answers(D, "activity", tr),
    }
    res = {}
    for (task, name), fn in cands.items():
        for q in FRACTIONS:
            ks, extra = [], []
            for s in (draws if q < 1 else ["0"]):
                tr = subsets(D.names, D.folds, draws[s], q)
                pred = fn(tr)
                k, n, right = score(D, task, pred)
                scored = D.det & (True if task == "count" else D.single)
                g, l, p = mcnemar(base[task][scored], right[scored])
                bands = [int((right & scored & (D.bands == b)).sum()) for b in BANDS]
                every = True if task == "count" else D.single  # the README's band columns: all scored clips
                bands_all = [int((right & every & (D.bands == b)).sum()) for b in BANDS]
                ks.append(k)
                extra.append({"draw": s, "k": k, "n": n, "gain": g, "loss": l, "p": p, "bands": bands,
                              "bands_all": bands_all})
            rooms = float(np.mean([int(round(q * ntrain[f])) for f in range(K)]))
            med = int(round(float(np.mean(ks))))
            lo, hi = clopper_pearson(med, n)
            res.setdefault(task, {}).setdefault(name, []).append(
                {"fraction": q, "rooms": rooms, "mean_k": float(np.mean(ks)), "min_k": min(ks), "max_k": max(ks),
                 "n": n, "rounded_mean_k": med, "cp95": [lo, hi], "draws": extra})
            print(f"{task:8s} {name:28s} {q:4.2f} rooms {rooms:5.1f}: {np.mean(ks):6.1f} of {n} "
                  f"({min(ks)}-{max(ks)}), {med / n:.3f} [{lo:.3f}, {hi:.3f}]  "
                  + "; ".join("+%d -%d p=%.2g" % (e["gain"], e["loss"], e["p"]) for e in extra[:1]), flush=True)
    json.dump(res, open(ROOT / "runs" / f"curve{sfx}.json", "w"), indent=1)

    # markdown table
    for task in res:
        print(f"\n| {task} | " + " | ".join(f"{int(q * 100)} % (~{res[task][next(iter(res[task]))][i]['rooms']:.0f} rooms)"
                                          for i, q in enumerate(FRACTIONS)) + " |")
        print("|---|" + "---|" * len(FRACTIONS))
        for name, pts in res[task].items():
            cells = []
            for p in pts:
                rng = f", draws {p['min_k']}-{p['max_k']}" if p["max_k"] != p["min_k"] else ""
                cells.append(f"{p['mean_k']:.1f}{rng} ({100 * p['mean_k'] / p['n']:.1f} %; "
                             f"{100 * p['cp95'][0]:.0f}-{100 * p['cp95'][1]:.0f} %)")
            print(f"| {name} | " + " | ".join(cells) + " |")

    # slope: a + b ln(rooms) through the draws' points (25-100 %), and rooms for 0.85 if it rises
    print("\nlog-linear fit of accuracy on ln(rooms) (every draw's point):")
    fits = {}
    for task in res:
        for name, pts in res[task].items():
            xs, ys = [], []
            for p in pts:
                for e in p["draws"]:
                    xs.append(np.log(p["rooms"])); ys.append(e["k"] / e["n"])
            b, a0 = np.polyfit(xs, ys, 1)
            need = float(np.exp((0.85 - a0) / b)) if b > 1e-6 else float("inf")
            print(f"  {task} {name}: {100 * b * np.log(2):+.2f} points per doubling of rooms; "
                  f"0.85 at ~{need:.3g} rooms")
            fits[f"{task} | {name}"] = {"slope_per_doubling": float(b * np.log(2)), "rooms_for_085": need}
    # the split's ceiling: every clip the net answers waving or jumping, of a waving or jumping person, right
    pair = [ACT_CLASSES.index("waving"), ACT_CLASSES.index("jumping")]
    sc = D.det & D.single
    ceil = (ship_a == D.act) | (np.isin(ship_a, pair) & np.isin(D.act, pair))
    print(f"F's ceiling (a perfect waving/jumping split): {int(ceil[sc].sum())} of {int(sc.sum())}")
    fits["activity | F ceiling"] = {"k": int(ceil[sc].sum()), "n": int(sc.sum())}
    # the shipping rule at 100 %: exact McNemar against the answers that ship, no band down by 2 or more
    print("\nat 100 % against the shipped answers (McNemar on detectable clips; bands over every scored clip,\n"
          "empty / <0 / 0-10 / >=10 as the README's tables; rule: p <= 0.1, no band down by 2 or more):")
    rule = {}
    for task, ref in (("count", "shipped (no recordings)"), ("activity", "net alone (no recordings)")):
        rb = res[task][ref][-1]["draws"][0]["bands_all"]
        for name, pts in res[task].items():
            e, p = pts[-1]["draws"][0], pts[-1]
            down = [b for b, x, y in zip(BANDS, rb, e["bands_all"]) if x - y >= 2]
            ok = e["p"] <= 0.1 and e["gain"] > e["loss"] and not down
            print(f"  {task} {name}: {e['k']} of {e['n']} ({100 * e['k'] / e['n']:.1f} %; "
                  f"{100 * p['cp95'][0]:.0f}-{100 * p['cp95'][1]:.0f} %), bands {e['bands_all']} (shipped {rb}), "
                  f"+{e['gain']} -{e['loss']}, p = {e['p']:.3g}; bands down by >= 2: {down or 'none'}; "
                  f"{'MEETS the rule' if ok else 'does not meet the rule'}")
            rule[f"{task} | {name}"] = {"k": e["k"], "n": e["n"], "bands": e["bands_all"], "shipped_bands": rb,
                                        "gain": e["gain"], "loss": e["loss"], "p": e["p"], "bands_down": down,
                                        "meets_rule": bool(ok)}
    json.dump({"folds": a.folds, "curve": res, "fits": fits, "rule_at_100": rule, "draws": a.draws},
              open(ROOT / "runs" / f"curve{sfx}.json", "w"), indent=1)

    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    import matplotlib.ticker
    fig, axes = plt.subplots(1, 2, figsize=(10, 4), sharey=True)
    for ax, task in zip(axes, ("count", "activity")):
        for i, (name, pts) in enumerate(res[task].items()):
            x = np.array([p["rooms"] for p in pts]) * (1 + 0.012 * (i - 1.5))
            m = np.array([p["mean_k"] / p["n"] for p in pts])
            lo = np.array([p["cp95"][0] for p in pts]); hi = np.array([p["cp95"][1] for p in pts])
            ax.errorbar(x, m, yerr=[m - lo, hi - m], marker="o", capsize=3, label=name)
            for p, xx in zip(pts, x):
                ax.plot([xx] * len(p["draws"]), [e["k"] / e["n"] for e in p["draws"]], ".", color="grey", ms=3)
        ax.axhline(0.85, ls=":", color="k", lw=0.8)
        ax.set_xscale("log")
        ax.set_xticks([46, 92, 137, 183]); ax.set_xticklabels(["46", "92", "137", "183"])
        ax.xaxis.set_minor_formatter(matplotlib.ticker.NullFormatter())
        if task == "activity":
            c = fits["activity | F ceiling"]
            ax.axhline(c["k"] / c["n"], ls="--", color="C1", lw=0.8)
            ax.text(50, c["k"] / c["n"] + 0.005, "F's ceiling (a perfect waving/jumping split)", fontsize=7, color="C1")
        ax.set_xlabel("training rooms per fold")
        ax.set_title(f"{task}: detectable clips right, out of fold"
                     + ("" if a.folds == "fixed" else f" ({a.folds} folds)"), fontsize=9 if sfx else None)
        ax.legend(fontsize=7, loc="lower right")
    axes[0].set_ylabel("accuracy (95 % Clopper-Pearson)")
    fig.tight_layout()
    fig.savefig(HERE / f"curve{sfx}.png", dpi=110)
    print("wrote", HERE / f"curve{sfx}.png")


if __name__ == "__main__":
    main()
