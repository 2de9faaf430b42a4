"""The 'pt' world: wall irradiance by Mitsuba 3 path tracing, an independent light transport.

The analytic world (room.py) renders people as spheres with closed-form form factors and the
room's interreflections as a closed-box estimate. Here the same ``Scene`` (room, people, poses,
observed wall points) is path traced instead:

- the room is six diffuse rectangles (the five surfaces of room.py with their albedo maps as
  bitmap textures, and the observed wall y = 0 with its mean albedo, as scene.py's wall_albedo);
- windows and ceiling panels are rectangular area emitters just inside their surface (radiance =
  the mean of the room's radiance map over the window, which is how room.py paints them), lamps
  are spherical area emitters;
- each person is one triangle mesh of ten boxes (torso, head, upper arms, forearms, thighs,
  shins) built on ``bodies.joints``; its vertices are moved every frame through
  ``mi.traverse`` (the scene is built, and JIT-compiled, once);
- the sensor is orthographic, 2 cm in front of the wall and looking at it (sensors occlude
  nothing), its film covering the bounding box of the wall points with one pixel centred on each
  grid corner; E = pi L / albedo_wall, then interpolated bilinearly at the exact (keystoned)
  points.

Every frame is rendered with the same sampler seed: a path that never meets a person draws the
same random numbers and finds the same surfaces every frame, so the static room cancels exactly
in E(t) - E_empty (correlated sampling) and only paths that touch a person carry Monte Carlo
noise. ``max_depth`` 4 = light that reached the wall after up to three bounces. The sampler is
multi-jittered: on a walker 1.5 m from the wall (24 x 32 points, 256 spp) the Monte Carlo noise of
the column profiles of dE / E is 1.7 per mille against 6.2 for independent samples at the same
cost (0.7 per mille at 1024 spp; the walker's own signal there is ~20-40 per mille).

Mitsuba is optional (the ``pt`` extra; wallcli/extras.py says how to install it) and imported only here, inside functions.
Variant: ``WALLCLI_PT_VARIANT`` if set, else cuda_ad_rgb where a CUDA device works, else
llvm_ad_rgb (needs libLLVM), else scalar_rgb.
"""

from __future__ import annotations

import os

import numpy as np

from wallcli.errors import WallcliError
from wallcli.extras import PT
from wallcli.sim import bodies
from wallcli.sim.room import NORMALS, TEX, Room, surface_uv_to_xyz

VARIANTS = ("cuda_ad_rgb", "llvm_ad_rgb", "scalar_rgb")
SENSOR_GAP = 0.02  # m between the wall and the orthographic sensor (people stay >= 0.3 m away)
PARKED = -50.0  # y of a hidden person's collapsed vertices: behind the observed wall, outside the box
_state = {"variant": None}

# boxes per person: (name, first joint, second joint, sphere indices whose radii set the side)
LIMBS = [("upperarm", "shoulder", "elbow", (4, 5)), ("forearm", "elbow", "wrist", (6, 7)),
         ("thigh", "hip", "knee", (12, 13)), ("shin", "knee", "ankle", (14, 15))]
# box faces as vertex-index triangles over the corners (i, j, k) -> 4 i + 2 j + k
_BOX_FACES = np.array([[0, 1, 3], [0, 3, 2], [4, 6, 7], [4, 7, 5], [0, 4, 5], [0, 5, 1],
                       [2, 3, 7], [2, 7, 6], [0, 2, 6], [0, 6, 4], [1, 5, 7], [1, 7, 3]], np.uint32)
N_BOXES = 2 + 2 * len(LIMBS)


MISSING = ("--world pt needs the path tracer Mitsuba 3, which is not installed", PT)


def require() -> None:
    """Fail early, with the extra to install, when Mitsuba is missing; imports nothing (the CLI
    calls this before it forks dataset workers, which must not inherit a started JIT backend)."""
    import importlib.util

    if importlib.util.find_spec("mitsuba") is None:
        raise WallcliError(*MISSING)


def mitsuba():
    """The mitsuba module with a variant set (chosen once per process)."""
    try:
        import mitsuba as mi
    except ImportError as exc:
        raise WallcliError(*MISSING) from exc
    if _state["variant"] is None:
        _state["variant"] = _pick_variant(mi)
    return mi


def variant() -> str:
    mitsuba()
    return _state["variant"]


def _pick_variant(mi) -> str:
    wanted = os.environ.get("WALLCLI_PT_VARIANT", "").strip()
    if wanted:
        if wanted not in mi.variants():
            raise WallcliError(f"WALLCLI_PT_VARIANT={wanted} is not a Mitsuba variant here",
                               hint=f"one of {', '.join(mi.variants())}")
        mi.set_variant(wanted)
        return wanted
    errors = []
    for v in VARIANTS:
        if v not in mi.variants():
            continue
        why = _probe(v) if v != "scalar_rgb" else None
        if why is None:
            mi.set_variant(v)
            return v
        errors.append(f"{v}: {why}")
    raise WallcliError("no Mitsuba variant works here (" + "; ".join(errors) + ")",
                       hint="set WALLCLI_PT_VARIANT to one that does")


def _probe(v: str) -> str | None:
    """None if variant v renders a small scene with a person in a child process, else why not.

    A child, because a JIT backend can fail by aborting the process: without a CUDA device
    cuda_* raises, but llvm_* with an old libLLVM (Debian bookworm's 15) compiles the first real
    render kernel into 'LLVM ERROR: Cannot select ... fminimum' and abort()."""
    import subprocess
    import sys

    env = dict(os.environ, WALLCLI_PT_VARIANT=v)
    try:
        r = subprocess.run([sys.executable, "-m", "wallcli.sim.pt_selftest"],
                           env=env, capture_output=True, text=True, timeout=300)
    except subprocess.TimeoutExpired:
        return "the test render took over 300 s"
    if r.returncode == 0 and r.stdout.strip().endswith("ok"):
        return None
    lines = [ln for ln in (r.stderr or r.stdout).splitlines() if ln.strip()]
    return (lines[0][:160] if lines else f"exit {r.returncode}")


def _frame(s: int, size, u0=0.0, u1=1.0, v0=0.0, v1=1.0, inset: float = 0.0) -> list:
    """to_world matrix (4 x 4 list) mapping Mitsuba's rectangle [-1, 1]^2 (normal +z, uv =
    (x + 1) / 2, (y + 1) / 2) onto surface s's (u, v) range, normal into the room. s = 5 is the
    observed wall y = 0 (u along x, v along z)."""
    W, D, H = (float(v) for v in size)
    if s == 5:
        p = lambda u, v: np.array([u * W, 0.0, v * H])  # noqa: E731
        n = np.array([0.0, 1.0, 0.0])
    else:
        p = lambda u, v: surface_uv_to_xyz(size, s, u, v)  # noqa: E731
        n = NORMALS[s]
    c = p((u0 + u1) / 2, (v0 + v1) / 2) + inset * n
    ex = (p(u1, v0) - p(u0, v0)) / 2
    ey = (p(u0, v1) - p(u0, v0)) / 2
    m = np.eye(4)
    m[:3, 0], m[:3, 1], m[:3, 2], m[:3, 3] = ex, ey, n, c
    return m.tolist()


def _person_boxes(person: bodies.Person, pose: dict) -> tuple[np.ndarray, np.ndarray]:
    """Box corners (T, N_BOXES, 8, 3) and the boxes' albedo (N_BOXES, 3) for a person's pose tracks."""
    j = bodies.joints(person, pose)
    s, g = person.s, person.girth
    r, alb = person.radii(), person.albedo()
    fwd, left, trunk = j["forward"], j["left"], j["trunk"]
    side_t = np.cross(trunk, fwd)  # the torso's width axis, square to its length
    side_t /= np.linalg.norm(side_t, axis=-1, keepdims=True)
    front_t = np.cross(side_t, trunk)
    boxes = [_box(j["pelvis"], j["neck"], side_t, front_t, 0.38 * s * g, 0.22 * s * g),
             _box(j["head"] - 0.1 * s * trunk, j["head"] + 0.1 * s * trunk, side_t, front_t, 0.17 * s, 0.2 * s)]
    colours = [alb[1], alb[0]]
    for k, n in enumerate("lr"):
        for name, a, b, idx in LIMBS:
            ia = [i + 4 * k for i in idx]  # the right side's spheres follow the left's
            p, q = j[f"{a}_{n}"], j[f"{b}_{n}"]
            axis = q - p
            axis = axis / np.maximum(np.linalg.norm(axis, axis=-1, keepdims=True), 1e-9)
            e1 = np.cross(axis, fwd)
            bad = np.linalg.norm(e1, axis=-1) < 1e-3  # limb along the forward axis: use the left one
            e1[bad] = np.cross(axis[bad], left[bad])
            e1 /= np.linalg.norm(e1, axis=-1, keepdims=True)
            e2 = np.cross(e1, axis)
            side = 2 * r[ia].mean()
            boxes.append(_box(p, q, e1, e2, side, side))
            colours.append(alb[ia[0]])
    return np.stack(boxes, axis=1), np.array(colours)


def _box(p, q, e1, e2, w1, w2) -> np.ndarray:
    """(T, 8, 3) corners of the box from p to q (T, 3) of cross-section w1 x w2 along e1, e2;
    corner 4 i + 2 j + k is at end i, e1 side j, e2 side k."""
    out = []
    for end in (p, q):
        for a in (-0.5, 0.5):
            for b in (-0.5, 0.5):
                out.append(end + a * w1 * e1 + b * w2 * e2)
    return np.stack(out, axis=1)


class PathTracer:
    """Renders the wall irradiance (gy, gx, 3) of a room with box people, one frame at a time."""

    def __init__(self, room: Room, points: np.ndarray, people: list, poses: list, *, spp: int = 256,
                 max_depth: int = 4, seed: int = 0, textures: bool = True, sampler: str = "multijitter"):
        mi = self.mi = mitsuba()
        self.points = np.asarray(points, float)
        self.spp, self.seed = int(spp), int(seed)
        self.room = room
        self.wall_albedo = np.clip(room.albedo[2].mean(axis=(0, 1)), 0.05, 0.95)
        gy, gx = self.points.shape[:2]
        x, z = self.points[..., 0], self.points[..., 2]
        self.x0, self.x1, self.z0, self.z1 = float(x.min()), float(x.max()), float(z.min()), float(z.max())
        # one pixel centred on each grid corner: pixel pitch = span / (n - 1), film half a pixel wider
        self.px = (self.x1 - self.x0) / max(gx - 1, 1) or 1e-3
        self.pz = (self.z1 - self.z0) / max(gy - 1, 1) or 1e-3
        hx, hz = (self.x1 - self.x0 + self.px) / 2, (self.z1 - self.z0 + self.pz) / 2
        T = mi.ScalarTransform4f
        xc, zc = (self.x0 + self.x1) / 2, (self.z0 + self.z1) / 2
        # Mitsuba's orthographic film spans [-1, 1] x [-1/aspect, 1/aspect] in camera space
        cam = T().look_at(origin=[xc, SENSOR_GAP, zc], target=[xc, -1.0, zc], up=[0, 0, 1]) @ T().scale([hx, hz * gx / gy, 1.0])
        d = {"type": "scene",
             "integrator": {"type": "path", "max_depth": int(max_depth)},
             "sensor": {"type": "orthographic", "near_clip": 1e-4, "far_clip": 1.0, "to_world": cam,
                        "film": {"type": "hdrfilm", "width": gx, "height": gy, "rfilter": {"type": "box"},
                                 "pixel_format": "rgb", "component_format": "float32", "sample_border": False},
                        "sampler": {"type": sampler, "sample_count": self.spp, "seed": self.seed}}}
        black = {"type": "diffuse", "reflectance": {"type": "rgb", "value": [0.0, 0.0, 0.0]}}
        for s in range(5):
            if textures:
                refl = {"type": "bitmap", "data": mi.TensorXf(np.ascontiguousarray(room.albedo[s], dtype=np.float32)),
                        "raw": True, "filter_type": "nearest"}
            else:
                refl = {"type": "rgb", "value": room.albedo[s].mean(axis=(0, 1)).tolist()}
            d[f"surface{s}"] = {"type": "rectangle", "to_world": T(_frame(s, room.size)),
                                "bsdf": {"type": "twosided", "bsdf": {"type": "diffuse", "reflectance": refl}}}
        d["wall"] = {"type": "rectangle", "to_world": T(_frame(5, room.size)),
                     "bsdf": {"type": "twosided", "bsdf": {"type": "diffuse", "reflectance": {
                         "type": "rgb", "value": self.wall_albedo.tolist()}}}}
        for k, (s, u0, u1, v0, v1) in enumerate(room.windows):
            iu = slice(int(u0 * TEX), max(int(u0 * TEX) + 1, int(u1 * TEX)))
            iv = slice(int(v0 * TEX), max(int(v0 * TEX) + 1, int(v1 * TEX)))
            L = room.radiance[s, iv, iu].reshape(-1, 3).mean(axis=0)
            # 1 mm inside the surface, so the wall behind never wins the intersection
            d[f"window{k}"] = {"type": "rectangle", "to_world": T(_frame(s, room.size, u0, u1, v0, v1, inset=1e-3)),
                               "emitter": {"type": "area", "radiance": {"type": "rgb", "value": L.tolist()}},
                               "bsdf": black}
        for k in range(len(room.lamp_radius)):
            d[f"lamp{k}"] = {"type": "sphere", "center": room.lamp_pos[k].tolist(), "radius": float(room.lamp_radius[k]),
                             "emitter": {"type": "area", "radiance": {"type": "rgb", "value": room.lamp_radiance[k].tolist()}},
                             "bsdf": black}
        # people: ten boxes per person, one mesh each; face colours from the boxes' albedo
        self.tracks = []
        for i, (person, pose) in enumerate(zip(people, poses)):
            corners, colours = _person_boxes(person, pose)
            self.tracks.append(corners.astype(np.float32))
            d[f"person{i}"] = self._mesh(f"person{i}", colours)
        self.scene = mi.load_dict(d)
        self.params = mi.traverse(self.scene)
        self.hide_all()

    def _mesh(self, name: str, colours: np.ndarray):
        mi = self.mi
        nv, nf = 8 * N_BOXES, 12 * N_BOXES
        bsdf = mi.load_dict({"type": "twosided", "bsdf": {"type": "diffuse", "reflectance": {
            "type": "mesh_attribute", "name": "face_color"}}})
        props = mi.Properties()
        props["bsdf"] = bsdf
        mesh = mi.Mesh(name, nv, nf, props=props, has_vertex_normals=False, has_vertex_texcoords=False)
        faces = (_BOX_FACES[None] + 8 * np.arange(N_BOXES, dtype=np.uint32)[:, None, None]).ravel()
        mp = mi.traverse(mesh)
        # the buffers' own types: dr.scalar.ArrayXf in scalar variants, mi.Float in JIT ones
        self._floats = type(mp["vertex_positions"])
        mp["vertex_positions"] = self._floats(self._parked(nv).ravel())
        mp["faces"] = type(mp["faces"])(faces)
        mp.update()
        mesh.add_attribute("face_color", 3, self._floats(np.repeat(colours.astype(np.float32), 12, axis=0).ravel()))
        return mesh

    def _parked(self, nv: int) -> np.ndarray:
        W, _, H = self.room.size
        return np.tile(np.array([W / 2, PARKED, H / 2], np.float32), (nv, 1))

    def _set(self, i: int, verts: np.ndarray | None) -> None:
        if verts is None:
            verts = self._parked(8 * N_BOXES)
        self.params[f"person{i}.vertex_positions"] = self._floats(np.ascontiguousarray(verts, np.float32).ravel())

    def hide_all(self) -> None:
        for i in range(len(self.tracks)):
            self._set(i, None)
        self.params.update()

    def irradiance(self, frame: int | None = None, who: list[int] | None = None) -> np.ndarray:
        """Wall irradiance (gy, gx, 3) float32 with the people in ``who`` (default: all) posed at
        ``frame``; ``frame=None`` renders the empty room."""
        who = list(range(len(self.tracks))) if who is None else list(who)
        for i in range(len(self.tracks)):
            self._set(i, self.tracks[i][frame].reshape(-1, 3) if frame is not None and i in who else None)
        if self.tracks:
            self.params.update()
        img = np.array(self.mi.render(self.scene, seed=self.seed, spp=self.spp), dtype=np.float64)[..., :3]
        # column 0 of Mitsuba's image is camera-space +x, which look_at put at world +x
        E = np.pi * img[:, ::-1] / self.wall_albedo
        return self._at_points(E).astype(np.float32)

    def _at_points(self, E: np.ndarray) -> np.ndarray:
        """Bilinear lookup of the pixel-centre grid at the exact (keystoned) wall points."""
        gy, gx = E.shape[:2]
        fx = np.clip((self.points[..., 0] - self.x0) / self.px, 0, gx - 1)
        fz = np.clip((self.z1 - self.points[..., 2]) / self.pz, 0, gy - 1)
        ix = np.minimum(fx.astype(int), max(gx - 2, 0))
        iz = np.minimum(fz.astype(int), max(gy - 2, 0))
        ax, az = (fx - ix)[..., None], (fz - iz)[..., None]
        ix1, iz1 = np.minimum(ix + 1, gx - 1), np.minimum(iz + 1, gy - 1)
        top = E[iz, ix] * (1 - ax) + E[iz, ix1] * ax
        bot = E[iz1, ix] * (1 - ax) + E[iz1, ix1] * ax
        return top * (1 - az) + bot * az
