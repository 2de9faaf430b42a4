"""Make DIR_part: the first K complete shards of a dataset still being written, as the dataset
`wallcli simulate --dataset K*per_shard ...` with the same seed would write them."""
import json, os, sys
from pathlib import Path
src, dst = Path(sys.argv[1]), Path(sys.argv[2])
man = json.loads((src / "dataset.json").read_text())
per = man["recipe"]["shard_scenes"] * man["recipe"]["windows_per_scene"]
k = 0
while (src / f"shard-{k:05d}.npz").exists() and k < len(man["shards"]):
    k += 1
k = min(k, len(man["shards"])) if man.get("complete") else max(k - 1, 0)  # the newest may be mid-write
dst.mkdir(parents=True, exist_ok=True)
for f in dst.glob("shard-*.npz"):
    f.unlink()
for i in range(k):
    os.symlink((src / f"shard-{i:05d}.npz").resolve(), dst / f"shard-{i:05d}.npz")
man["shards"] = man["shards"][:k]
man["recipe"]["windows"] = sum(s["n"] for s in man["shards"])
man["complete"] = True
(dst / "dataset.json").write_text(json.dumps(man, indent=1))
print(k, "shards,", man["recipe"]["windows"], "windows")
