"""Quick transfer probe on precomputed plots (data/tp/*.npz): per-clip answers of an ONNX model."""
import sys, csv, numpy as np
from wallcli.infer.model import Model
from wallcli.infer.classify import classify_plot
from wallcli.io.arrays import load_npz
from wallcli.signal.stplot import FORMAT, from_arrays
task, path = sys.argv[1], sys.argv[2]
m = Model.load(path, task=task)
rows = list(csv.DictReader(open("/work/shared/transfer/labels.csv")))
ok = n = 0
conf = {}
for r in rows:
    truth = int(r["people"]) if task == "count" else r["activity"]
    if task == "activity" and int(r["people"]) > 1: continue
    p = from_arrays(*load_npz(f"data/tp/{r['file'][:-4]}.npz", kind=FORMAT))
    res = classify_plot(m, p, stride=64, source=r["file"])
    n += 1; ok += res["label"] == truth
    conf[(truth, res["label"])] = conf.get((truth, res["label"]), 0) + 1
    if "-v" in sys.argv: print(r["file"], truth, res["label"], np.round(res["probabilities"], 2), r["signal"], r["lighting"], r["crf"])
print(f"{task}: {ok}/{n} = {ok/n:.3f}")
print(sorted(conf.items(), key=lambda kv: -kv[1]))
