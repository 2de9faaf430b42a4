"""The path tracer's variant probe: render a small scene in a child process (pathtrace._probe
runs ``python -m wallcli.sim.pt_selftest``). It lives apart because it needs both a scene and the
tracer, and pathtrace.py must not import scene.py (scene.py reaches the tracer through world_pt)."""
from __future__ import annotations

import numpy as np

from wallcli.sim.pathtrace import PathTracer
from wallcli.sim.scene import SceneConfig, sample_scene


def main() -> None:
    """Render a 4 x 4 wall with one person in a small room, twice; print 'ok'."""
    sc = sample_scene(0, SceneConfig(people=1, activities=["walking"], duration=0.1, fps=20, grid=(4, 4)))
    tr = PathTracer(sc.room, sc.points, sc.people, sc.poses, spp=2)
    E = tr.irradiance(0)
    assert np.isfinite(E).all() and E.shape == (4, 4, 3)
    tr.irradiance(1)
    print("ok")


if __name__ == "__main__":
    main()
