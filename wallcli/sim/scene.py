"""A whole simulated recording: room + people + motion + camera, sampled from one seed.

``sample_scene(seed, config)`` draws every random choice up front from one
``numpy.random.Generator`` (per-scene seeds are derived from (seed, index) by the dataset
mode), so the same seed and config give the same frames. ``Scene.frames()`` renders lazily.
"""

from __future__ import annotations

from dataclasses import dataclass, field, replace
from typing import Iterator

import numpy as np

from wallcli.sim import WIDE_DOMAINS, bodies, motion, moving_truth
from wallcli.sim.camera import Camera, CameraParams, sample_camera
from wallcli.sim.bodylight import body_delta, body_radiance, overlapping_pairs
from wallcli.sim.room import Room, index_interp, sample_room, static_irradiance
from wallcli.sim.shadows import shadow_delta

ACTIVITIES = motion.ACTIVITIES


@dataclass
class SceneConfig:
    """User knobs; None means 'randomise'."""

    people: int | None = None
    activities: list[str] | None = None  # per person; one name applies to everybody
    duration: float = 12.0
    fps: float | None = None
    width: int | None = None
    height: int | None = None
    grid: tuple[int, int] = (64, 64)  # wall points (rows, cols) where irradiance is rendered
    domain: str = "base"
    distance: tuple[float, float] = (1.0, 5.0)
    speed: tuple[float, float] = (0.5, 1.8)
    roam: float = 2.5  # walkers stay within this many metres (along the wall) of the observed patch's centre
    codec: str | None = None  # ffv1 | libx264
    crf: int | None = None
    noise_scale: float = 1.0
    nuisance_p: float = 0.35
    camera_overrides: dict = field(default_factory=dict)
    # light transport: 'room' = the analytic renderer (room.py, people of spheres); 'pt' = Mitsuba 3
    # path tracing of the same scene with people of boxes (pathtrace.py; needs the pt extra)
    world: str = "room"
    spp: int = 256  # pt: samples per wall point and frame
    # room world: bodies also shadow the room's other surfaces (shadows.py), a whole-wall dimming the
    # path tracer shows; False renders the direct term only, as the simulator did before
    shadows: bool = True


@dataclass
class Scene:
    seed: int
    config: SceneConfig
    room: Room
    camera: CameraParams
    region: tuple[float, float, float, float]  # observed wall: x0, x1, z0, z1 (m)
    points: np.ndarray  # (gy, gx, 3) wall points
    people: list[bodies.Person]
    activities: list[str]
    poses: list[dict]
    times: np.ndarray
    rng: np.random.Generator
    # Set to [] before frames() to collect, per frame, the noise-free relative irradiance change
    # averaged over wall rows and columns: ((gx, 3), (gy, 3)), plus, with several people, a list
    # of each person's own (gx, 3) change. Dataset mode uses it to measure how visible the people
    # are in each window.
    clean_profiles: list | None = None
    # 'bracket' domain: the bodies' radiance and their room shadows scaled (sim/__init__.py)
    body_gain: float = 1.0
    shadow_gain: float = 1.0

    @property
    def label_activity(self) -> str:
        """The clip's activity class: 'none' without movers, else the first mover's activity."""
        moving = [a for a in self.activities if a != "none"]
        return moving[0] if moving else "none"

    def sphere_tracks(self):
        """Per person (T, 20, 3) centres, (20,) radii, (20, 3) albedo."""
        return [(bodies.sphere_centers(p, pose), p.radii(), p.albedo()) for p, pose in zip(self.people, self.poses)]

    def static_irradiance(self, max_points: int = 16) -> np.ndarray:
        """Empty-room irradiance on the wall grid: exact on a sub-grid of at most max_points per
        side, interpolated linearly in between (it is smooth: it integrates the whole room)."""
        gy, gx = self.points.shape[:2]
        iy = np.unique(np.linspace(0, gy - 1, min(gy, max_points)).round().astype(int))
        ix = np.unique(np.linspace(0, gx - 1, min(gx, max_points)).round().astype(int))
        sub = self.points[np.ix_(iy, ix)]
        E = static_irradiance(self.room, sub.reshape(-1, 3)).reshape(sub.shape)
        if len(iy) == gy and len(ix) == gx:
            return E
        return np.einsum("ya,abc,xb->yxc", index_interp(gy, iy), E, index_interp(gx, ix))

    def frames(self) -> Iterator[np.ndarray]:
        """uint8 RGB frames (H, W, 3)."""
        if self.config.world == "pt":
            from wallcli.sim import world_pt  # the path-traced world renders this scene

            yield from world_pt.frames(self)
            return
        E0 = self.static_irradiance()
        wall_albedo = np.clip(self.room.albedo[2].mean(axis=(0, 1)), 0.05, 0.95)
        cam = Camera(self.camera, E0, wall_albedo, len(self.times), self.rng)
        tracks = self.sphere_tracks()
        gy, gx = self.points.shape[:2]
        probes = self.points[np.ix_([0, gy // 2, gy - 1], [0, gx // 2, gx - 1])].reshape(-1, 3)
        view = np.array([(self.region[0] + self.region[1]) / 2, 0.0, (self.region[2] + self.region[3]) / 2])
        x0, x1, z0, z1 = self.region
        bbox = (x0 - 0.2, x1 + 0.2, z0 - 0.2, z1 + 0.2)
        for i in range(len(self.times)):
            if tracks:
                C = np.concatenate([c[i] for c, _, _ in tracks])
                R = np.concatenate([r for _, r, _ in tracks])
                A = np.concatenate([a for _, _, a in tracks])
                dE = self._delta(C, R, A, probes, view, bbox)
            else:
                dE = np.zeros_like(E0)
            if self.clean_profiles is not None:
                E0_safe = np.maximum(E0, 1e-12)
                rel = dE / E0_safe
                entry = (rel.mean(axis=0), rel.mean(axis=1))
                if len(tracks) > 1:
                    # each person alone as well (one more physics pass): a window where one of two
                    # people is invisible must not pass for a window where both are seen
                    alone = []
                    for c, r, a in tracks:
                        dEi = self._delta(c[i], r, a, probes, view, bbox)
                        alone.append((dEi / E0_safe).mean(axis=0))
                    entry = (*entry, alone)
                self.clean_profiles.append(entry)
            yield cam.render(dE, i, static_E=E0)

    def _delta(self, C, R, A, probes, view, bbox) -> np.ndarray:
        """The wall's irradiance change (gy, gx, 3) from spheres C, R, A in one frame."""
        L = body_radiance(self.room, C, A, view)
        if self.body_gain != 1.0:
            L = L * self.body_gain
        dE = body_delta(self.room, self.points, C, R, L, bbox, overlapping_pairs(probes, C, R))
        if self.config.shadows:
            dE = dE + self.shadow_gain * shadow_delta(self.room, self.points, C, R, A)
        return dE

    def truth(self, frames: int | None = None) -> dict:
        """The JSON sidecar: docs/contract.md fields plus everything needed to reproduce or study the clip."""
        n = len(self.times) if frames is None else frames
        persons = []
        for p, a, pose, (c, _, _) in zip(self.people, self.activities, self.poses, self.sphere_tracks()):
            persons.append({
                "activity": a, "height_m": round(p.height, 3), "girth": round(p.girth, 3),
                "top_albedo": np.round(p.top, 3).tolist(), "bottom_albedo": np.round(p.bottom, 3).tolist(),
                # per frame: floor position x, y (y = distance from the wall) and head height z, metres
                "positions": np.round(np.stack([pose["x"], pose["y"], c[:, 0, 2]], -1)[:n], 3).tolist(),
            })
        W, D, H = self.room.size
        return {
            "people": len(self.people), "activity": self.label_activity, "activities": list(self.activities),
            **moving_truth(self.activities),
            "fps": self.camera.fps, "frames": n, "seed": self.seed, "width": self.camera.width,
            "height": self.camera.height, "domain": self.config.domain,
            **({"world": "pt", "spp": int(self.config.spp)} if self.config.world == "pt" else {}),
            **({"body_gain": round(self.body_gain, 4), "shadow_gain": round(self.shadow_gain, 4)}
               if self.config.domain == "bracket" else {}),
            "room": {"size_m": [round(W, 3), round(D, 3), round(H, 3)], "lamps": len(self.room.lamp_radius),
                     "lamp_positions": np.round(self.room.lamp_pos, 3).tolist(), "windows": len(self.room.windows)},
            "wall_region_m": [round(v, 3) for v in self.region],
            "camera": self.camera.to_dict(),
            "persons": persons,
            "coordinates": "metres; observed wall is y=0, x along it, z up; positions are [x, y, head_z] per frame",
        }


def _region(rng, size, domain):
    W, D, H = size
    w = min(rng.uniform(0.6, 4.0) if domain in ("shifted", *WIDE_DOMAINS) else rng.uniform(0.8, 3.0), W - 0.4)
    h = min(w * rng.uniform(0.55, 0.85), H - 0.3)
    lo = 0.2 + w / 2
    xc = rng.uniform(lo, max(lo, W - 0.2 - w / 2))  # equal bounds (a wall-wide region) may round to hi < lo
    z0 = rng.uniform(0.1, H - h - 0.1)
    return xc - w / 2, xc + w / 2, z0, z0 + h


def _wall_points(rng, region, grid):
    """Wall points under a (gy, gx) grid of image positions, with mild keystone distortion."""
    x0, x1, z0, z1 = region
    gy, gx = grid
    v, u = np.meshgrid(np.linspace(0, 1, gy), np.linspace(0, 1, gx), indexing="ij")
    kx, kz = rng.uniform(-0.12, 0.12, 2)
    x = (x0 + x1) / 2 + (x1 - x0) * (u - 0.5) * (1 + kx * (v - 0.5))
    z = z1 - (z1 - z0) * v * (1 + kz * (u - 0.5))  # image row 0 is the top of the region
    return np.stack([x, np.zeros_like(x), z], -1)


def pick_people_activities(rng, people: int | None, activities: list[str] | None) -> tuple[int, list[str]]:
    n = int(rng.integers(0, 3)) if people is None else int(people)
    if activities:
        acts = [activities[i % len(activities)] for i in range(n)]
    else:
        acts = [str(rng.choice(ACTIVITIES, p=[0.1, 0.45, 0.15, 0.15, 0.15])) for _ in range(n)]
    return n, acts


def sample_scene(seed: int, config: SceneConfig | None = None, index: int | None = None) -> Scene:
    """Scene for ``seed`` (and dataset ``index``: scene i of a dataset uses SeedSequence([seed, i]))."""
    config = config or SceneConfig()
    ss = np.random.SeedSequence([int(seed), int(index)] if index is not None else int(seed))
    rng = np.random.default_rng(ss)
    room = sample_room(rng, config.domain)
    cam = sample_camera(rng, config.domain, nuisance_p=config.nuisance_p)
    cam = replace(cam, noise_scale=config.noise_scale, **config.camera_overrides)
    if config.fps:
        cam.fps = float(config.fps)
    if config.width:
        cam.width = int(config.width)
    if config.height:
        cam.height = int(config.height)
    if config.codec:
        cam.codec = config.codec
    if config.crf is not None:
        cam.crf = int(config.crf)
    region = _region(rng, room.size, config.domain)
    points = _wall_points(rng, region, config.grid)
    n, acts = pick_people_activities(rng, config.people, config.activities)
    W, D, _ = room.size
    xc = (region[0] + region[1]) / 2
    bounds = ((max(0.4, xc - config.roam), min(W - 0.4, xc + config.roam)),
              (config.distance[0], max(config.distance[0] + 0.2, min(config.distance[1], D - 0.4))))
    # people who stay in one spot stand roughly in front of the observed patch (as in the seed's
    # experiments); walkers roam +-config.roam around it
    half = (region[1] - region[0]) / 2 + 0.75
    spot_bounds = ((max(0.4, xc - half), min(W - 0.4, xc + half)), bounds[1])
    T = max(2, int(round(config.duration * cam.fps)))
    times = np.arange(T) / cam.fps
    walkers = [i for i, a in enumerate(acts) if a == "walking"]
    cross = {}
    if len(walkers) == 2 and rng.random() < 0.6:  # make them cross in front of the wall
        cross = {walkers[0]: 1, walkers[1]: -1}
    people, poses = [], []
    for i, a in enumerate(acts):
        people.append(bodies.sample_person(rng, config.domain))
        poses.append(motion.make_motion(rng, a, times, bounds if a == "walking" else spot_bounds, config.speed, cross.get(i, 0),
                                        config.domain))
    scene = Scene(int(seed), config, room, cam, region, points, people, acts, poses, times, rng)
    if config.domain == "bracket":  # drawn last: every other draw is the 'steady' scene's
        from wallcli.sim import BODY_GAIN, SHADOW_GAIN

        scene.body_gain = float(np.exp(rng.uniform(*np.log(BODY_GAIN))))
        scene.shadow_gain = float(np.exp(rng.uniform(*np.log(SHADOW_GAIN))))
    return scene
