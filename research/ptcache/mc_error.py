"""The Monte-Carlo error of the path-traced column profile against 1024 spp, as a share of the signal,
with one sampler seed for every frame and with 8 seeds cycled (research/ptcache/README.md).

    python research/ptcache/mc_error.py
"""
import numpy as np, sys
sys.path.insert(0,'research/ptcache')
from wallcli.datagen.clips import PLACEMENTS
from wallcli.sim.pathtrace import PathTracer
from wallcli.sim.scene import SceneConfig, sample_scene
F=90
for k, act in [(0,'walking'),(2,'waving'),(6,'waving'),(11,'jumping')]:
    cfg = SceneConfig(people=1, activities=[act], duration=F/30+0.1, fps=30, grid=(16,24), domain="wide", **PLACEMENTS["wide"])
    sc = sample_scene(900, cfg, index=k)
    out={}
    for name, spp, K in [("ref1024",1024,1),("64 single",64,1),("64 cyc8",64,8),("16 cyc8",16,8)]:
        tr = PathTracer(sc.room, sc.points, sc.people, sc.poses, spp=spp, seed=k); tr.mi.set_log_level(tr.mi.LogLevel.Error)
        seeds=[k*100+j for j in range(K)]
        emp=[]
        for s in seeds:
            tr.seed=s; emp.append(tr.irradiance(None))
        E0=np.maximum(np.mean(emp,0),1e-12)
        pr=[]
        for i in range(F):
            tr.seed=seeds[i%K]; pr.append(((tr.irradiance(i)-emp[i%K])/E0).mean(axis=(0,2)))
        pr=np.array(pr); out[name]=pr
    ref=out["ref1024"]
    sig=np.sqrt(np.mean((ref-ref.mean(0))**2))
    line=f"{act:8s} signal {sig:.2e}"
    for n,pr in out.items():
        hf=np.sqrt(np.mean(np.diff(pr,axis=0)**2)/2)  # white-noise estimate from frame differences
        err=np.sqrt(np.mean((pr-ref)**2))
        line+=f" | {n}: err/sig {err/sig:.2f} hf/sig {hf/sig:.2f}"
    print(line, flush=True)
