"""Seeds of simulated one-person 'wide' scenes lit one way (no lamps), to set beside transfer clips:

    python research/transfer/pick_lighting.py window_back 3 walking   # -> 3 6 9
    wallcli simulate -o data/cmp/w3.mp4 --people 1 --activity walking --domain wide --seed 3 --duration 10 --size 96x72 --crf 0
    wallcli stplot data/cmp/w3.mp4 -o data/cmp/w3.npz
"""
from wallcli.sim.scene import SceneConfig, sample_scene
import sys
want = sys.argv[1]; n = int(sys.argv[2]); act = sys.argv[3]
out = []
for seed in range(1, 400):
    sc = sample_scene(seed, SceneConfig(people=1, activities=[act], domain="wide", distance=(1.0, 5.0), roam=2.0))
    kinds = {s for s, *_ in sc.room.windows}
    lamps = len(sc.room.lamp_radius)
    ok = {"window_back": kinds == {2} and not lamps, "window_side": kinds <= {0, 1} and kinds and not lamps,
          "ceiling": kinds == {4} and not lamps}[want]
    if ok:
        out.append(seed)
    if len(out) == n:
        break
print(" ".join(map(str, out)))
