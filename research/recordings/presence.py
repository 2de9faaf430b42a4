"""Count: nobody against one person re-split by the 19 features (wallcli.infer.split on count), out of fold."""
import sys, json
sys.path.insert(0, "research/recordings")
import numpy as np
from common import *
from wallcli.infer.split import Split, fit
from wallcli.signal.features import window_features
recs=recordings(); folds=np.array([fold_of(r.name,K) for r in recs])
base=json.load(open(ROOT/"runs"/"baseline_probs.json"))
F=np.array([window_features(r.horizontal[r.eval_index(64)], r.vertical[r.eval_index(64)], r.h_offset[r.eval_index(64)], r.v_offset[r.eval_index(64)]).mean(0) for r in recs])
sel=np.array([(r.people==0 or (r.people==1 and bool(r.detectable))) for r in recs])
y=np.array([1.0 if r.people>0 else 0.0 for r in recs])
for l2 in (1.0, 10.0):
    newr,oldr=[],[]
    for f in range(K):
        b=fit(F[sel&(folds!=f)], y[sel&(folds!=f)], l2=l2); b["pair"]=[0,1]; sp=Split(b,[0,1,2])
        for j in np.flatnonzero(folds==f):
            p=np.array(base[recs[j].name]["count"]); q=sp.apply(p,F[j])[0]
            newr.append((j,int(q.argmax())==recs[j].people)); oldr.append((j,int(p.argmax())==recs[j].people))
    newr=dict(newr); oldr=dict(oldr); js=sorted(newr); det=[j for j in js if recs[j].detectable]
    print(l2, table([recs[j] for j in js],[newr[j] for j in js],"count"), "+%d -%d p=%.3f"%mcnemar([oldr[j] for j in det],[newr[j] for j in det]))
