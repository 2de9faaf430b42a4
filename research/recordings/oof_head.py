"""Approach A: the shipped nets' trunks frozen, a new head fitted on the recordings, out of fold."""
import sys, json
import numpy as np
import torch
sys.path.insert(0, __import__('os').path.dirname(__file__))
from common import *

torch.manual_seed(0)
recs = recordings()
E = dict(np.load(ROOT / "runs" / "emb.npz"))
E["lpc"] = np.log(np.clip(E["pc"], 1e-6, 1)); E["lpa"] = np.log(np.clip(E["pa"], 1e-6, 1))
base = json.load(open(ROOT / "runs" / "baseline_probs.json"))
folds = np.array([fold_of(r.name, K) for r in recs])


def fit(X, y, k, wd, hidden=0, epochs=300, balance=True):
    X = torch.from_numpy(X).float(); y = torch.from_numpy(y).long()
    net = torch.nn.Linear(X.shape[1], k) if not hidden else torch.nn.Sequential(
        torch.nn.Linear(X.shape[1], hidden), torch.nn.LeakyReLU(0.1), torch.nn.Dropout(0.3), torch.nn.Linear(hidden, k))
    opt = torch.optim.Adam(net.parameters(), lr=1e-2, weight_decay=wd)
    w = torch.bincount(y, minlength=k).float(); w = (w.sum() / (k * w.clamp_min(1))) if balance else torch.ones(k)
    for _ in range(epochs):
        opt.zero_grad(); loss = torch.nn.functional.cross_entropy(net(X), y, weight=w); loss.backward(); opt.step()
    net.eval()
    return lambda Z: torch.softmax(net(torch.from_numpy(Z).float()), 1).detach().numpy()


def run(task, feats, wd, hidden=0, tag="", balance=True):
    cls = COUNT_CLASSES if task == "count" else ACT_CLASSES
    keep = np.array([scored(r, task) for r in recs])
    Xw = np.concatenate([E[f] for f in feats], 1)
    clipw = E["clip"]
    yc = np.array([cls.index(truth(r, task)) if scored(r, task) else -1 for r in recs])
    probs = {}
    for f in range(K):
        tr = np.flatnonzero(np.isin(clipw, np.flatnonzero((folds != f) & keep)))
        mu, sd = Xw[tr].mean(0), Xw[tr].std(0) + 1e-6
        model = fit((Xw[tr] - mu) / sd, yc[clipw[tr]], len(cls), wd, hidden, balance=balance)
        for j in np.flatnonzero((folds == f) & keep):
            r = recs[j]
            ix = np.flatnonzero(clipw == j)[r.eval_index(64)]
            probs[j] = model((Xw[ix] - mu) / sd).mean(0)
    sel = [j for j in range(len(recs)) if keep[j]]
    right = {j: cls[int(np.argmax(probs[j]))] == truth(recs[j], task) for j in sel}
    bright = {j: cls[int(np.argmax(base[recs[j].name][task]))] == truth(recs[j], task) for j in sel}
    sub = [recs[j] for j in sel]
    det = [i for i, j in enumerate(sel) if recs[j].detectable]
    g, l, p = mcnemar([bright[sel[i]] for i in det], [right[sel[i]] for i in det])
    print(f"{task} {tag} {'+'.join(feats)} wd={wd} h={hidden} bal={balance}: {table(sub, [right[j] for j in sel], task)}  +{g}-{l} p={p:.3f}", flush=True)
    return probs


if __name__ == "__main__" and len(sys.argv) == 1:
  for task in ("count", "activity"):
   for feats in (["fc", "fh", "fv"], ["fh", "fv"], ["fc"]):
        for wd in (1e-3, 1e-2):
            run(task, feats, wd)
   run(task, ["fc", "fh", "fv"], 1e-3, hidden=32)
