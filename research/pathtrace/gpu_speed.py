"""Frames per second of `--world pt` on whatever variant wallcli picks (cuda_ad_rgb on a GPU
machine): one 'wide' walker scene, 300 frames, 24 x 32 wall points, 256 and 1024 spp.

    python research/pathtrace/gpu_speed.py
"""
import time, sys
from wallcli.sim.pathtrace import variant
print("variant", variant(), flush=True)
from wallcli.sim.scene import SceneConfig, sample_scene
for spp, grid in ((256, (24, 32)), (1024, (24, 32))):
    sc = sample_scene(7, SceneConfig(people=1, activities=["walking"], domain="wide", duration=10, fps=30, grid=grid, world="pt", spp=spp, width=96, height=72))
    t = time.time(); n = 0
    for f in sc.frames():
        n += 1
        if n == 2: t1 = time.time()
    dt = time.time() - t1
    print(f"grid {grid} spp {spp}: {n} frames, {(n-2)/dt:.1f} frames/s after the first two ({t1-t:.1f} s)", flush=True)
