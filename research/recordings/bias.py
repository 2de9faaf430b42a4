"""Approach E: the shipped nets kept, class biases (and stride) refitted on the recordings, out of fold."""
import sys, json
import numpy as np
import torch
sys.path.insert(0, __import__('os').path.dirname(__file__))
from common import *
from wallcli.infer.twostage import combine

recs = recordings()
E = dict(np.load(ROOT / "runs" / "emb.npz"))
folds = np.array([fold_of(r.name, K) for r in recs])
base = json.load(open(ROOT / "runs" / "baseline_probs.json"))


def clip_probs(task, stride, odds=0.25):
    out = []
    for j, r in enumerate(recs):
        ix = np.flatnonzero(E["clip"] == j)[r.eval_index(stride)]
        pc, pa = E["pc"][ix].mean(0), E["pa"][ix].mean(0)
        out.append(combine(pc[None], pa[None], odds)[0] if task == "count" else pa)
    return np.array(out)


def fit_bias(L, y, k, wd=1e-2):
    b = torch.zeros(k, requires_grad=True)
    t = torch.ones(1, requires_grad=True)
    opt = torch.optim.LBFGS([b, t], max_iter=200)
    L, y = torch.from_numpy(L).float(), torch.from_numpy(y).long()
    def closure():
        opt.zero_grad(); l = torch.nn.functional.cross_entropy(L * t + b, y) + wd * (b ** 2).sum(); l.backward(); return l
    opt.step(closure)
    return b.detach().numpy(), float(t)


for task in ("count", "activity"):
    cls = COUNT_CLASSES if task == "count" else ACT_CLASSES
    keep = np.array([scored(r, task) for r in recs])
    y = np.array([cls.index(truth(r, task)) if scored(r, task) else 0 for r in recs])
    for stride in (64, 16):
        P = clip_probs(task, stride)
        L = np.log(np.clip(P, 1e-6, 1))
        right0 = [cls[int(np.argmax(P[j]))] == truth(recs[j], task) for j in range(len(recs))]
        pred = np.zeros(len(recs), int)
        for f in range(K):
            tr = (folds != f) & keep
            b, t = fit_bias(L[tr], y[tr], len(cls))
            te = folds == f
            pred[te] = np.argmax(L[te] * t + b, 1)
        right = [cls[pred[j]] == truth(recs[j], task) for j in range(len(recs))]
        sel = [j for j in range(len(recs)) if keep[j]]
        sub = [recs[j] for j in sel]
        det = [j for j in sel if recs[j].detectable]
        g, l, p = mcnemar([base_right for base_right in [cls[int(np.argmax(base[recs[j].name][task]))] == truth(recs[j], task) for j in det]], [right[j] for j in det])
        print(task, "stride", stride, "plain:", table(sub, [right0[j] for j in sel], task))
        print(task, "stride", stride, "bias :", table(sub, [right[j] for j in sel], task), f"+{g}-{l} p={p:.3f}")
