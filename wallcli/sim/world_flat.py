"""Flatland as a recording: the 1-D receiver image per frame, seen by the same camera model.

Each frame's receiver irradiance (flatland.irradiance) becomes one image row, repeated down the
frame (the wall albedo texture and camera noise still vary in 2-D). A 2-D occluder stands for a
whole person in every row, which overstates a 3-D person's effect by the fraction of the vertical
field a person does not cover, so the moving part is scaled by ``vertical_fraction`` (0.1-0.5).
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Iterator

import numpy as np

from wallcli.sim import moving_truth
from wallcli.sim.camera import Camera, CameraParams, sample_camera
from wallcli.sim.flatland import Flatland, irradiance, occluder_tracks, sample_world


@dataclass
class FlatScene:
    seed: int
    world: Flatland
    camera: CameraParams
    tracks: np.ndarray  # (T, n_occ, 2, 2)
    times: np.ndarray
    vertical_fraction: float
    domain: str
    rng: np.random.Generator

    def receiver_images(self) -> Iterator[np.ndarray]:
        """(n_recv, 3) receiver radiance-like images (albedo x irradiance), no camera."""
        for segs in self.tracks:
            yield self.world.albedo * irradiance(self.world, segs)

    def frames(self) -> Iterator[np.ndarray]:
        empty = np.zeros((0, 2, 2))
        E0 = self.world.albedo * irradiance(self.world, empty)
        grid0 = np.repeat(E0[None], 2, axis=0)
        cam = Camera(self.camera, grid0, np.ones(3), len(self.times), self.rng)
        for i, img in enumerate(self.receiver_images()):
            dE = self.vertical_fraction * (img - E0)
            yield cam.render(np.repeat(dE[None], 2, axis=0), i, static_E=grid0)

    def truth(self) -> dict:
        n = self.tracks.shape[1]
        centres = self.tracks.mean(axis=2)  # (T, n_occ, 2)
        return {
            "people": n, "activity": "walking" if n else "none", "activities": ["walking"] * n,
            **moving_truth(["walking"] * n),
            "fps": self.camera.fps, "frames": len(self.times), "seed": self.seed, "world": "flatland",
            "width": self.camera.width, "height": self.camera.height, "domain": self.domain,
            "camera": self.camera.to_dict(),
            "flatland": {"width_m": round(self.world.width, 3), "depth_m": round(self.world.depth, 3),
                         "emitter_cells": len(self.world.emitter_radiance), "vertical_fraction": round(self.vertical_fraction, 3)},
            "persons": [{"activity": "walking", "positions": np.round(centres[:, k], 3).tolist()} for k in range(n)],
            "coordinates": "metres; receiver is y=0, positions are occluder centres [x, y] per frame",
        }


def sample_flat_scene(seed: int, index: int | None, people: int, *, duration: float = 12.0, domain: str = "base",
                      fps: float | None = None, nuisance_p: float = 0.35) -> FlatScene:
    ss = np.random.SeedSequence([int(seed), int(index)] if index is not None else int(seed))
    rng = np.random.default_rng(ss)
    cam = sample_camera(rng, domain, nuisance_p=nuisance_p)
    if fps:
        cam.fps = float(fps)
    world = sample_world(rng, people, n_recv=64, domain=domain)
    times = np.arange(max(2, int(round(duration * cam.fps)))) / cam.fps
    tracks = occluder_tracks(rng, world, people, times)
    return FlatScene(int(seed), world, cam, tracks, times, float(rng.uniform(0.1, 0.5)), domain, rng)
