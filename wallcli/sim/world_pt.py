"""The 'pt' world as a recording: a scene's frames path traced (pathtrace.PathTracer), seen by
the same camera model as the analytic world.

A scene describes (room, people, poses, camera); a world renders it. This module takes a
``Scene`` as it is given and never imports scene.py, and pathtrace.py knows only rooms, people
and poses, so neither of them imports the other (they once did, each way).
"""
from __future__ import annotations

from typing import Iterator

import numpy as np

from wallcli.sim.camera import Camera
from wallcli.sim.pathtrace import PathTracer


def frames(scene) -> Iterator[np.ndarray]:
    """uint8 RGB frames (H, W, 3) of ``scene`` (a scene.Scene) by path tracing: the empty room
    once (same sampler seed as every frame, so the static room cancels exactly in the
    differences), then each frame's change from it. ``scene.clean_profiles``, when a list, collects
    the noise-free profiles as Scene.frames() does for the analytic world."""
    tracer = PathTracer(scene.room, scene.points, scene.people, scene.poses, spp=scene.config.spp,
                        seed=scene.seed % 2**31)
    E0 = tracer.irradiance(None)
    wall_albedo = np.clip(scene.room.albedo[2].mean(axis=(0, 1)), 0.05, 0.95)
    cam = Camera(scene.camera, E0, wall_albedo, len(scene.times), scene.rng)
    E0_safe = np.maximum(E0, 1e-12)
    for i in range(len(scene.times)):
        dE = tracer.irradiance(i) - E0 if scene.people else np.zeros_like(E0)
        if scene.clean_profiles is not None:
            rel = dE / E0_safe
            entry = (rel.mean(axis=0), rel.mean(axis=1))
            if len(scene.people) > 1:
                # each person alone: one more render per person (as the analytic world does)
                entry = (*entry, [((tracer.irradiance(i, who=[j]) - E0) / E0_safe).mean(axis=0)
                                  for j in range(len(scene.people))])
            scene.clean_profiles.append(entry)
        yield cam.render(dE, i, static_E=E0)
