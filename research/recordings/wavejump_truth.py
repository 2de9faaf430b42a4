"""Waving against jumping, from the motion-capture truth to the vertical plot (issue #53, item 3).

1. What each draws (truth/NAME.json, t061 on): per frame the moving person's bounding box; per clip
   the range (max - min over the clip) of the box's bottom (feet) and top, of its height and width,
   of the person's place, and the dominant frequency (and its spectral peak share) of the box's
   height over time.
2. Whether the vertical plot reads it: four features declared before any fit, from what the truth
   shows (a waver's feet stay, the top of the box moves; a jumper's whole box moves), each a clip's
   mean over its stride-64 windows, as the split's 19:
     v_top3_share    the vertical plot's energy share in its upper third (upper part against whole)
     v_ud_coherence  |correlation| over time of the upper half's and lower half's mean signals (the
                     whole body moving together)
     v_top_peak      log of the upper half's spectral peak share over the whole plot's (is the rhythm
                     in the upper part or everywhere)
     v_shift_share   the share of the plot's energy along the gradient of its mean profile (what a
                     vertical shift of the light pattern draws)
   Their rank AUC (jumping against waving, detectable single-person clips), and their rank
   correlation with the truth's range of the feet and with its rhythm, where truth exists.
3. Whether they help the split out of fold: the F recipe (split_oof.py: Newton, L2 = 1, fitted per
   fold on the other folds' detectable waving/jumping clips) on the 19 features plus each of the four
   and plus all four: 5 settings, paired against activity 0.4.0's recipe (the 19) and against the
   net alone.

Run: python research/recordings/wavejump_truth.py
"""
import json
import sys

import numpy as np
from scipy.stats import spearmanr

sys.path.insert(0, __import__('os').path.dirname(__file__))
from common import *  # noqa: E402,F403
from common import ROOT, TRANSFER, K, ACT_CLASSES, mcnemar, recordings, table  # noqa: E402
from wallcli.infer.split import Split, fit  # noqa: E402
from wallcli.signal.features import NAMES, _centred, window_features  # noqa: E402
from wallcli.train.recordings import fold_of  # noqa: E402

NEW = ["v_top3_share", "v_ud_coherence", "v_top_peak", "v_shift_share"]


def truth_stats(name):
    p = TRANSFER / "truth" / (name.rsplit(".", 1)[0] + ".json")
    if not p.is_file():
        return None
    d = json.loads(p.read_text())
    act = d["activity"]
    pid = [q["id"] for q in d["people"] if q["activity"] == act][0]
    bmin, bmax, pos = [], [], []
    for fr in d["per_frame"]:
        q = [q for q in fr["people"] if q["id"] == pid][0]
        bmin.append(q["bbox_min"]); bmax.append(q["bbox_max"]); pos.append(q["position"])
    bmin, bmax, pos = np.array(bmin), np.array(bmax), np.array(pos)
    h = bmax[:, 1] - bmin[:, 1]
    x = h - h.mean()
    sp = np.abs(np.fft.rfft(x)) ** 2
    sp[0] = 0
    return {"feet_range": float(np.ptp(bmin[:, 1])), "top_range": float(np.ptp(bmax[:, 1])),
            "height_range": float(np.ptp(h)), "width_range": float(np.ptp(bmax[:, 0] - bmin[:, 0])),
            "place_range": float(np.ptp(pos[:, 0]) + np.ptp(pos[:, 2])),
            "height_hz": float(sp.argmax() * d["fps"] / len(x)), "height_peak": float(sp.max() / (sp.sum() + 1e-20)),
            "height_m": float(d["people"][pid]["height_m"]) if pid < len(d["people"]) else float("nan")}


def new_features(v, v_off):
    """(n, 4) of n windows of the vertical plot (n, bins, T, 3) and its levels (n, bins, 3)."""
    x = _centred(v)
    n, bins, T = x.shape
    pv = (x ** 2).mean(2)
    tot = pv.sum(1) + 1e-20
    top3 = pv[:, :bins // 3].sum(1) / tot
    up, lo = x[:, :bins // 2].mean(1), x[:, bins // 2:].mean(1)
    coh = np.abs([np.corrcoef(a, b)[0, 1] if a.std() > 0 and b.std() > 0 else 0.0 for a, b in zip(up, lo)])

    def peak(sig):
        s = np.abs(np.fft.rfft(sig - sig.mean(1, keepdims=True), axis=1)) ** 2
        s[:, 0] = 0
        return s.max(1) / (s.sum(1) + 1e-20)

    toppk = np.log(peak(up) + 1e-9) - np.log(peak(x.mean(1)) + 1e-9)
    g = np.gradient(np.asarray(v_off, np.float64).mean(-1), axis=1)  # (n, bins)
    g = g / (np.linalg.norm(g, axis=1, keepdims=True) + 1e-20)
    proj = np.einsum("nb,nbt->nt", g, x)
    shift = (proj ** 2).sum(1) / ((x ** 2).sum((1, 2)) + 1e-20)
    return np.stack([top3, coh, toppk, shift], 1)


def auc(s, pos):
    a, b = s[pos], s[~pos]
    return float(((a[:, None] > b[None]).sum() + 0.5 * (a[:, None] == b[None]).sum()) / (len(a) * len(b)))


def main():
    recs = recordings()
    folds = np.array([fold_of(r.name, K) for r in recs])
    base = json.load(open(ROOT / "runs" / "baseline_probs.json"))
    F19, F4 = [], []
    for r in recs:
        ix = r.eval_index(64)
        F19.append(window_features(r.horizontal[ix], r.vertical[ix], r.h_offset[ix], r.v_offset[ix]).mean(0))
        F4.append(new_features(r.vertical[ix], r.v_offset[ix]).mean(0))
    F19, F4 = np.array(F19), np.array(F4)
    pair = ["waving", "jumping"]
    sel = np.array([r.activity in pair and bool(r.detectable) and r.persons <= 1 for r in recs])
    single = np.array([r.activity in pair and r.persons <= 1 for r in recs])
    y = np.array([1.0 if r.activity == "jumping" else 0.0 for r in recs])
    jump = y == 1

    # 1. the truth
    T = {j: truth_stats(r.name) for j, r in enumerate(recs) if single[j]}
    T = {j: t for j, t in T.items() if t is not None}
    keys = ["feet_range", "top_range", "height_range", "width_range", "place_range", "height_hz", "height_peak"]
    print(f"1. truth (single-person waving/jumping clips with truth: {sum(1 for j in T if not jump[j])} waving, "
          f"{sum(1 for j in T if jump[j])} jumping); median [10 %, 90 %]:")
    for k in keys:
        cells = []
        for lab, m in (("waving", False), ("jumping", True)):
            v = np.array([T[j][k] for j in T if jump[j] == m])
            cells.append(f"{lab} {np.median(v):.3f} [{np.quantile(v, 0.1):.3f}, {np.quantile(v, 0.9):.3f}]")
        v = np.array([T[j][k] for j in T]); pj = np.array([jump[j] for j in T])
        print(f"  {k:13s} " + "; ".join(cells) + f"; AUC jumping > waving {auc(v, pj):.2f}")

    # 2. what the plot reads
    print("\n2. the vertical plot's features: AUC jumping > waving (detectable single-person clips, "
          f"{int((sel & ~jump).sum())} waving, {int((sel & jump).sum())} jumping); Spearman with the truth's "
          "feet range / height rhythm (Hz) over the clips with truth (all SNR)")
    tj = np.array(sorted(T))
    feet = np.array([T[j]["feet_range"] for j in tj]); hz = np.array([T[j]["height_hz"] for j in tj])
    tdet = np.array([bool(recs[j].detectable) for j in tj])
    cols = {nm: F19[:, NAMES.index(nm)] for nm in ("v_top_share", "v_extent", "v_pattern_hz", "v_pattern_peak",
                                                   "v_peak_hz", "v_rank1", "log_h_over_v")}
    cols.update({nm: F4[:, i] for i, nm in enumerate(NEW)})
    for nm, c in cols.items():
        rf = spearmanr(c[tj], feet).correlation
        rh = spearmanr(c[tj], hz).correlation
        rfd = spearmanr(c[tj][tdet], feet[tdet]).correlation
        print(f"  {nm:15s} AUC {auc(c[sel], jump[sel]):.2f}; with feet range {rf:+.2f} (detectable {rfd:+.2f}); "
              f"with rhythm {rh:+.2f}")

    # 3. the split out of fold
    def answers(X):
        out = {}
        for f in range(K):
            blk = fit(X[sel & (folds != f)], y[sel & (folds != f)], l2=1.0)
            for j in np.flatnonzero(folds == f):
                r = recs[j]
                if not scored(r, "activity"):
                    continue
                z = ((X[j] - np.array(blk["mean"])) / np.array(blk["scale"])) @ np.array(blk["coef"]) + blk["intercept"]
                q = 1 / (1 + np.exp(-np.clip(z, -50, 50)))
                p = np.array(base[r.name]["activity"], float)
                if p.argmax() in (3, 4):
                    s = p[3] + p[4]
                    p[3], p[4] = s * (1 - q), s * q
                out[j] = ACT_CLASSES[int(p.argmax())] == r.activity
        return out

    js = sorted(j for j, r in enumerate(recs) if scored(r, "activity"))
    det = [j for j in js if recs[j].detectable]
    net = {j: ACT_CLASSES[int(np.argmax(base[recs[j].name]["activity"]))] == recs[j].activity for j in js}
    ref = answers(F19)
    # check: the same answers as the package's Split on the 19 (split_oof.py)
    chk = {}
    for f in range(K):
        blk = fit(F19[sel & (folds != f)], y[sel & (folds != f)], l2=1.0); blk["pair"] = pair
        sp = Split(blk, ACT_CLASSES)
        for j in np.flatnonzero(folds == f):
            if scored(recs[j], "activity"):
                chk[j] = ACT_CLASSES[int(sp.apply(np.array(base[recs[j].name]["activity"]), F19[j])[0].argmax())] == recs[j].activity
    assert chk == ref, "the re-implemented split differs from wallcli.infer.split"
    pairdet = [j for j in det if sel[j]]
    print("\n3. the split out of fold (activity, detectable of", len(det), "; waving/jumping detectable", len(pairdet), ")")
    print("| features | waving right | jumping right | detectable | against 0.4.0's recipe (19) | against the net alone |")
    print("|---|---|---|---|---|---|")
    settings = [("19 (activity 0.4.0's recipe)", F19)] + [(f"19 + {nm}", np.concatenate([F19, F4[:, [i]]], 1))
                                                          for i, nm in enumerate(NEW)] + \
               [("19 + all four", np.concatenate([F19, F4], 1))]
    res = {}
    for name, X in settings:
        a = ref if name.startswith("19 (") else answers(X)
        k = sum(a[j] for j in det)
        wv = sum(a[j] for j in pairdet if not jump[j]); jp = sum(a[j] for j in pairdet if jump[j])
        g1, l1, p1 = mcnemar([ref[j] for j in det], [a[j] for j in det])
        g2, l2, p2 = mcnemar([net[j] for j in det], [a[j] for j in det])
        print(f"| {name} | {wv} of {sum(1 for j in pairdet if not jump[j])} | {jp} of {sum(1 for j in pairdet if jump[j])} "
              f"| {k} ({100 * k / len(det):.1f} %) | +{g1} -{l1}, p = {p1:.2g} | +{g2} -{l2}, p = {p2:.2g} |")
        print("   ", table([recs[j] for j in js], [a[j] for j in js], "activity"))
        res[name] = {"detectable": int(k), "vs_recipe": [g1, l1, p1], "vs_net": [g2, l2, p2]}
    json.dump(res, open(ROOT / "runs" / "wavejump_truth.json", "w"), indent=1)


if __name__ == "__main__":
    main()
