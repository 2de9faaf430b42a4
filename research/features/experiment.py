"""Train small classifiers on feats.features of simulated windows; measure them on held-out
simulated windows and on the transfer set's clips (measured only, never trained or tuned on).

  python research/features/experiment.py --train data/wide41 --val data/val_wide43 --plots data/tp

Transfer plots: `wallcli stplot CLIP -o data/tp/NAME.npz` for every clip of ../shared/transfer.
"""
from __future__ import annotations

import argparse
import csv
import json
import sys
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))
from feats import features, names  # noqa: E402

from wallcli.io.arrays import load_npz  # noqa: E402
from wallcli.signal.stplot import FORMAT, from_arrays  # noqa: E402
from wallcli.signal.window import resample, window_starts  # noqa: E402

ACTS = ["none", "walking", "crouching", "waving", "jumping"]


def dataset_features(root: Path, cache: Path):
    if cache.is_file():
        z = np.load(cache)
        return {k: z[k] for k in z.files}
    man = json.loads((root / "dataset.json").read_text())
    out = {k: [] for k in ("x", "people", "activity", "snr", "movers")}
    for s in man["shards"]:
        a, _ = load_npz(root / s["file"], kind="wallcli.dataset-shard")
        out["x"].append(features(a["horizontal"], a["vertical"]))
        # count's label: moving people (a count dataset's label; in an activity dataset, someone
        # standing still is 'none' and counts 0); 'movers' <= 1 selects activity's windows
        act = a["activity"] if man["task"] == "count" else a["label"]
        out["people"].append(a["label"] if man["task"] == "count" else (act != 0).astype(np.int64))
        out["activity"].append(act)
        out["movers"].append(a["people"] if man["task"] == "count" else np.zeros_like(act))
        out["snr"].append(a["snr_db"])
    res = {k: np.concatenate(v) for k, v in out.items()}
    np.savez(cache, **res)
    return res


def transfer_features(plots: Path, labels: Path):
    clips = []
    for r in csv.DictReader(open(labels)):
        p = from_arrays(*load_npz(plots / (r["file"][:-4] + ".npz"), kind=FORMAT))
        h, grid = resample(p.horizontal, p.time)
        v, _ = resample(p.vertical, p.time)
        starts = window_starts(len(grid), 256, 64)
        x = features(np.stack([h[:, s:s + 256] for s in starts]), np.stack([v[:, s:s + 256] for s in starts]))
        clips.append((r, x))
    return clips


def train(x, y, classes, *, hidden, epochs=300, seed=0, wd=1e-3):
    import torch

    torch.manual_seed(seed)
    mu, sd = x.mean(0), x.std(0) + 1e-6
    xt = torch.tensor((x - mu) / sd, dtype=torch.float32)
    yt = torch.tensor(y, dtype=torch.long)
    counts = np.bincount(y, minlength=classes).astype(np.float64)
    wts = torch.tensor(counts.sum() / np.maximum(counts, 1) / classes, dtype=torch.float32)
    d = x.shape[1]
    if hidden:
        net = torch.nn.Sequential(torch.nn.Linear(d, hidden), torch.nn.ReLU(), torch.nn.Dropout(0.2),
                                  torch.nn.Linear(hidden, hidden), torch.nn.ReLU(), torch.nn.Linear(hidden, classes))
    else:
        net = torch.nn.Linear(d, classes)
    opt = torch.optim.Adam(net.parameters(), lr=3e-3, weight_decay=wd)
    lossf = torch.nn.CrossEntropyLoss(weight=wts)
    for _ in range(epochs):
        net.train()
        perm = torch.randperm(len(xt))
        for i in range(0, len(xt), 256):
            b = perm[i:i + 256]
            opt.zero_grad()
            lossf(net(xt[b]), yt[b]).backward()
            opt.step()
    net.eval()

    def predict(xx):
        with torch.no_grad():
            return torch.softmax(net(torch.tensor((xx - mu) / sd, dtype=torch.float32)), 1).numpy()
    return predict


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--train", nargs="+", required=True)
    ap.add_argument("--val", required=True)
    ap.add_argument("--plots", default="data/tp")
    ap.add_argument("--labels", default="../shared/transfer/labels.csv")
    ap.add_argument("--min-snr-db", type=float, default=-20.0)
    ap.add_argument("--hidden", type=int, nargs="+", default=[0, 64])
    ap.add_argument("--seeds", type=int, default=3)
    ap.add_argument("--tasks", nargs="+", default=["count", "activity"])
    ap.add_argument("--out", default="runs/features.json")
    a = ap.parse_args()
    tr = [dataset_features(Path(t), Path("runs") / f"feat_{Path(t).name}.npz") for t in a.train]
    tr = {k: np.concatenate([d[k] for d in tr]) for k in tr[0]}
    va = dataset_features(Path(a.val), Path("runs") / f"feat_{Path(a.val).name}.npz")
    clips = transfer_features(Path(a.plots), Path(a.labels))
    print(f"train {len(tr['x'])} windows, val {len(va['x'])}, transfer {len(clips)} clips; {len(names())} features",
          file=sys.stderr)
    report = {}
    for task in a.tasks:
        def xy(d):
            keep = (d["snr"] >= a.min_snr_db) | (d["people"] == 0)
            if task == "activity":
                keep &= d["movers"] <= 1
                return d["x"][keep], d["activity"][keep]
            return d["x"][keep], d["people"][keep]
        xtr, ytr = xy(tr)
        xva, yva = xy(va)
        nc = 3 if task == "count" else 5
        for hidden in a.hidden:
            accs, tacc, per = [], [], []
            for seed in range(a.seeds):
                pred = train(xtr, ytr, nc, hidden=hidden, seed=seed)
                accs.append(float(np.mean(pred(xva).argmax(1) == yva)))
                right, cls = 0, {}
                n = 0
                for r, x in clips:
                    if task == "activity" and int(r["people"]) > 1:
                        continue
                    truth = int(r["people"]) if task == "count" else ACTS.index(r["activity"])
                    ans = int(pred(x).mean(0).argmax())
                    n += 1
                    right += ans == truth
                    cls.setdefault(truth, [0, 0])
                    cls[truth][0] += ans == truth
                    cls[truth][1] += 1
                tacc.append(right / n)
                per.append({str(k): f"{v[0]}/{v[1]}" for k, v in sorted(cls.items())})
            key = f"{task}_h{hidden}"
            report[key] = {"val_window_acc": accs, "transfer_clip_acc": tacc, "transfer_per_class": per,
                           "val_windows": int(len(yva)), "train_windows": int(len(ytr))}
            print(key, "val", np.round(accs, 3), "transfer", np.round(tacc, 3), per[0], file=sys.stderr)
    Path(a.out).write_text(json.dumps(report, indent=1))


if __name__ == "__main__":
    main()
