"""Waving against jumping: what in the plots tells them apart on the recordings (out of fold)."""
import sys, json
import numpy as np

sys.path.insert(0, __import__('os').path.dirname(__file__))
from common import *
from oof_head import fit

recs = recordings()
E = dict(np.load(ROOT / "runs" / "emb.npz"))
folds = np.array([fold_of(r.name, K) for r in recs])


def extra(r):
    out = []
    for ix in [r.eval_index(64)]:
        v = r.vertical[ix].mean(-1); h = r.horizontal[ix].mean(-1)
        v = v - v.mean(2, keepdims=True); h = h - h.mean(2, keepdims=True)
        pv = (v ** 2).mean(2)  # (n, bins) energy along height
        top = pv[:, :32].sum(1) / (pv.sum(1) + 1e-20)
        hv = np.log((h ** 2).mean((1, 2)) / ((v ** 2).mean((1, 2)) + 1e-20))
        # dominant frequency of the vertical plot's first temporal component
        fr, pk = [], []
        for w in v:
            u, s, vt = np.linalg.svd(w, full_matrices=False)
            sp = np.abs(np.fft.rfft(vt[0])) ** 2; sp[0] = 0
            fr.append(sp.argmax() * 30 / w.shape[1]); pk.append(sp.max() / sp.sum())
        # spatial extent: share of bins above half the max energy
        ext = (pv > 0.5 * pv.max(1, keepdims=True)).mean(1)
        out.append(np.stack([top, hv, fr, pk, ext], 1).mean(0))
    return out[0]

def oof_second(X, y, sel, folds, balance=False):
    """P(second of the pair) for every clip, each fold's from a logistic fitted on the other folds' ``sel`` rows."""
    q = np.zeros(len(X))
    for f in range(K):
        tr = sel & (folds != f)
        mu, sd = X[tr].mean(0), X[tr].std(0) + 1e-9
        m = fit((X[tr] - mu) / sd, y[tr], 2, 1e-2, balance=balance)
        te = folds == f
        q[te] = m((X[te] - mu) / sd)[:, 1]
    return q


X = np.array([np.concatenate([extra(r), E["feat"][E["clip"] == j].mean(0)]) for j, r in enumerate(recs)])
sel = np.array([r.activity in ("waving", "jumping") and r.detectable and r.persons <= 1 for r in recs])
y = np.array([1 if r.activity == "jumping" else 0 for r in recs])
for name, cols in (("extra", slice(0, 5)), ("feat14", slice(5, 19)), ("all", slice(0, 19))):
    right = []
    for f in range(K):
        tr, te = sel & (folds != f), sel & (folds == f)
        mu, sd = X[tr][:, cols].mean(0), X[tr][:, cols].std(0) + 1e-9
        m = fit((X[tr][:, cols] - mu) / sd, y[tr], 2, 1e-2, balance=False)
        right += list(m((X[te][:, cols] - mu) / sd).argmax(1) == y[te])
    print(name, f"{sum(right)}/{len(right)}")
for lab in ("waving", "jumping"):
    s = sel & np.array([r.activity == lab for r in recs])
    print(lab, np.round(np.median(X[s][:, :5], 0), 3))

# the shipped activity net, with waving/jumping re-split by the discriminator (out of fold)
base = json.load(open(ROOT / "runs" / "baseline_probs.json"))
act = [r for r in recs]
for name, cols in (("feat14", slice(5, 19)), ("all", slice(0, 19))):
    newright, oldright = [], []
    q = oof_second(X[:, cols], y, sel, folds)
    for j, r in enumerate(recs):
        if not scored(r, "activity"):
            continue
        p = np.array(base[r.name]["activity"])
        old = ACT_CLASSES[int(p.argmax())]
        if old in ("waving", "jumping"):
            mm = p[3] + p[4]; p[3], p[4] = mm * (1 - q[j]), mm * q[j]
        newright.append(ACT_CLASSES[int(p.argmax())] == r.activity); oldright.append(old == r.activity)
    sub = [r for r in recs if scored(r, "activity")]
    det = [i for i, r in enumerate(sub) if r.detectable]
    print(name, table(sub, newright, "activity"), "+%d -%d p=%.3f" % mcnemar([oldright[i] for i in det], [newright[i] for i in det]))
