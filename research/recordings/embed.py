"""Per-window embeddings of the shipped nets' trunks (frozen), for every harvested window."""
import sys
import numpy as np
import torch
sys.path.insert(0, __import__('os').path.dirname(__file__))
from common import *
from wallcli.infer.model import load_model
from wallcli.train.init import init_from_onnx
from wallcli.train.nets import build

torch.set_num_threads(2)
recs = recordings()
cm, am = load_model("count"), load_model("activity")
H = np.concatenate([cm.normalize(r.horizontal, r.h_offset) for r in recs]).astype(np.float32)
V = np.concatenate([am.normalize(r.vertical, r.v_offset) for r in recs]).astype(np.float32)
Ha = np.concatenate([am.normalize(r.horizontal, r.h_offset) for r in recs]).astype(np.float32)
cn, an = build("count"), build("activity")
init_from_onnx(cn, cm.path, [torch.from_numpy(H[:64])])
init_from_onnx(an, am.path, [torch.from_numpy(Ha[:64]), torch.from_numpy(V[:64])])
cn.eval(); an.eval()
fc, fh, fv, pc, pa = [], [], [], [], []
with torch.no_grad():
    for i in range(0, len(H), 64):
        h, ha, v = (torch.from_numpy(x[i:i+64]) for x in (H, Ha, V))
        a = cn.trunk(h); fc.append(a.numpy()); pc.append(torch.softmax(cn.head(a), 1).numpy())
        b, c = an.trunk_h(ha), an.trunk_v(v); fh.append(b.numpy()); fv.append(c.numpy())
        pa.append(torch.softmax(an.head(torch.cat([b, c], 1)), 1).numpy())
clip = np.concatenate([[j] * len(r.starts) for j, r in enumerate(recs)])
starts = np.concatenate([r.starts for r in recs])
np.savez(ROOT / "runs" / "emb.npz", fc=np.concatenate(fc), fh=np.concatenate(fh), fv=np.concatenate(fv),
         pc=np.concatenate(pc), pa=np.concatenate(pa), clip=clip, starts=starts)
print("ok", len(clip))
