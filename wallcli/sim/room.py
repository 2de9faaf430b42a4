"""A box room lit by lamps and windows (the light bodies of spheres take from a wall: bodylight.py).

Model (units arbitrary but consistent; a uniform surround of radiance L gives E = pi L):
- Surfaces 0..4 (left x=0, right x=W, back y=D, floor z=0, ceiling z=H) are Lambertian with
  albedo textures. Their radiance is rho * (E_direct + E_ambient) / pi; E_direct comes from the
  lamps (small emitting spheres, exact sphere form factor) and the windows and ceiling panels
  (each split into 4 x 4 point sources), E_ambient is the closed-box radiosity estimate
  rho_mean * flux / (area * (1 - rho_mean)) that stands in for all further bounces.
  Windows and panels are emitting rectangles painted into the surface radiance maps.
- The observed wall (y = 0) receives E_static(x) = lamps (exact sphere form factors) + the five
  surfaces, integrated as piecewise-constant patches with exact polygon form factors (Lambert).
- Bodies are spheres. Each changes a wall point's irradiance by exactly
  pi * (r/D)^2 cos(beta) * (L_body - L_behind) when the background behind it is uniform over its
  angular disc; L_behind is the radiance of the room surface hit by the ray through the sphere's
  centre, looked up on radiance maps blurred by ~15 cm (approximation: the mean behind the disc).
  Lamps behind a sphere are occluded by the planar-disc overlap of the two angular discs
  (small-angle approximation, < 1 % for discs under 15 degrees), which gives soft shadows.
- Approximations, documented: where two spheres overlap as seen from a wall point (along a
  torso, an arm in front of the body, one person behind another) the farther one's hidden part
  is removed (angular-disc overlap; several hiders combine as independent; computed on a 5 x 5
  sub-grid of the wall and interpolated; whole bodies match brute-force ray casting within ~2.5 %
  at 1 m, see tests/sim/test_physics.py); bodies do not shadow
  the other room surfaces (a second-order effect on the observed wall); body radiance uses one
  view direction (to the centre of the observed patch) and ambient + lamp + window/panel light
  without self-shadowing.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from wallcli.sim import WIDE_DOMAINS

from wallcli.sim.geometry import polygon_form_factor

NORMALS = np.array([[1, 0, 0], [-1, 0, 0], [0, -1, 0], [0, 0, 1], [0, 0, -1]], float)
TEX = 48  # radiance-map texels per surface side
PATCHES = 8  # patches per surface side for the static irradiance integral


@dataclass
class Room:
    size: np.ndarray  # (W, D, H) metres
    albedo: np.ndarray  # (5, TEX, TEX, 3) surface albedo maps, [surface, v, u]
    radiance: np.ndarray  # (5, TEX, TEX, 3) surface radiance maps (windows included)
    lamp_pos: np.ndarray  # (K, 3)
    lamp_radius: np.ndarray  # (K,)
    lamp_radiance: np.ndarray  # (K, 3)
    ambient: np.ndarray  # (3,) ambient irradiance used for bodies and surfaces
    windows: list = field(default_factory=list)  # [(surface, u0, u1, v0, v1)] for previews
    radiance_blur: np.ndarray = None  # radiance maps blurred by ~15 cm: the mean behind a body sphere
    # windows and ceiling panels as point sources that light the bodies: positions (S, 3), inward
    # normals (S, 3), radiance x area (S, 3); see area_sources()
    sources: tuple = None

    def __post_init__(self):
        if self.radiance_blur is None:
            self.radiance = self.radiance.astype(np.float32)
            self.radiance_blur = _blur(self.radiance, max(1, int(round(0.15 / (self.size.max() / TEX)))))
        if self.sources is None:
            self.sources = area_sources(self.size, self.windows, self.radiance)

    @property
    def lamp_intensity(self) -> np.ndarray:
        return self.lamp_radiance * (np.pi * self.lamp_radius**2)[:, None]


AREA_SPLIT = 4  # an area light is lit from as AREA_SPLIT x AREA_SPLIT point sources


def area_sources(size, windows, radiance) -> tuple:
    """Windows and ceiling panels as AREA_SPLIT^2 point sources each: (positions, normals, L*A).

    A person under a ceiling panel or beside a window is lit by it directly, and far more than by
    the room's ambient light: a raised arm near a panel is one of the brightest things in the room.
    Each sub-rectangle's radiance is read back from the radiance maps (windows are painted there)."""
    W, D, H = (float(v) for v in size)
    area = np.array([D * H, D * H, W * H, W * D, W * D])
    pos, nrm, power = [], [], []
    k = AREA_SPLIT
    for s, u0, u1, v0, v1 in windows:
        du, dv = (u1 - u0) / k, (v1 - v0) / k
        for j in range(k):
            for i in range(k):
                a, b = u0 + i * du, v0 + j * dv
                iu = slice(int(a * TEX), max(int(a * TEX) + 1, int((a + du) * TEX)))
                iv = slice(int(b * TEX), max(int(b * TEX) + 1, int((b + dv) * TEX)))
                pos.append(surface_uv_to_xyz(size, s, a + du / 2, b + dv / 2))
                nrm.append(NORMALS[s])
                power.append(radiance[s, iv, iu].reshape(-1, 3).mean(axis=0) * du * dv * area[s])
    if not pos:
        return np.zeros((0, 3)), np.zeros((0, 3)), np.zeros((0, 3))
    return np.array(pos, float), np.array(nrm, float), np.array(power, float)


def area_irradiance(sources: tuple, points: np.ndarray, normals: np.ndarray | None = None) -> tuple:
    """Direct irradiance (N, S, 3) of each area-light point source at points, on a surface of
    the given normals (N, 3) or, with None, facing the source; and the unit directions (N, S, 3)."""
    pos, nrm, power = sources
    d = pos[None] - points[:, None]
    r2 = np.maximum(np.einsum("nsk,nsk->ns", d, d), 1e-6)
    u = d / np.sqrt(r2)[..., None]
    emit = np.clip(-np.einsum("nsk,sk->ns", u, nrm), 0, None)  # the source's cos toward the point
    recv = 1.0 if normals is None else np.clip(np.einsum("nsk,nk->ns", u, normals), 0, None)
    return power[None] * (emit * recv / r2)[..., None], u


def _blur(maps: np.ndarray, k: int) -> np.ndarray:
    """Box blur (2k+1 texels) of each surface map, edges clamped."""
    out = maps.copy()
    for axis in (1, 2):
        pad = [(0, 0)] * 4
        pad[axis] = (k, k)
        c = np.cumsum(np.pad(out, pad, mode="edge"), axis=axis, dtype=np.float64)
        c = np.concatenate([np.zeros_like(np.take(c, [0], axis=axis)), c], axis=axis)
        n = out.shape[axis]
        out = ((np.take(c, np.arange(2 * k + 1, n + 2 * k + 1), axis=axis) - np.take(c, np.arange(n), axis=axis)) / (2 * k + 1)).astype(np.float32)
    return out


def surface_uv_to_xyz(size: np.ndarray, s: int, u: np.ndarray, v: np.ndarray) -> np.ndarray:
    W, D, H = size
    u, v = np.broadcast_arrays(np.asarray(u, float), np.asarray(v, float))
    z0 = np.zeros(u.shape)
    if s == 0:
        return np.stack([z0, u * D, v * H], -1)
    if s == 1:
        return np.stack([z0 + W, u * D, v * H], -1)
    if s == 2:
        return np.stack([u * W, z0 + D, v * H], -1)
    if s == 3:
        return np.stack([u * W, v * D, z0], -1)
    return np.stack([u * W, v * D, z0 + H], -1)


def _smooth_field(rng, n: int, octaves: int = 3) -> np.ndarray:
    """Zero-mean random field on an n x n grid from a few low-frequency cosines."""
    y, x = np.mgrid[0:n, 0:n] / n
    f = np.zeros((n, n))
    for k in range(octaves):
        for _ in range(3):
            fx, fy = rng.uniform(0.5, 2.5) * 2**k, rng.uniform(0.5, 2.5) * 2**k
            f += np.cos(2 * np.pi * (fx * x + fy * y) + rng.uniform(0, 2 * np.pi)) / 2**k
    return f / (np.abs(f).max() + 1e-9)


def _paint(rng, lo: float, hi: float, tint: float) -> np.ndarray:
    base = rng.uniform(lo, hi)
    return np.clip(base * (1 + rng.uniform(-tint, tint, 3)), 0.02, 0.95)


def sample_room(rng: np.random.Generator, domain: str = "base") -> Room:
    """A random furnished box room. ``domain='shifted'`` moves every range (held-out validation);
    ``domain='wide'`` spans both and lights rooms the ways rooms are lit (``_wide_lighting``)."""
    if domain in WIDE_DOMAINS:
        return _sample_room(rng, "wide", rng.uniform(3.0, 9.0), rng.uniform(4.5, 10.0), rng.uniform(2.4, 3.8))
    shifted = domain == "shifted"
    W = rng.uniform(5.5, 9.0) if shifted else rng.uniform(3.0, 7.0)
    D = rng.uniform(6.0, 9.5) if shifted else rng.uniform(4.5, 8.0)
    H = rng.uniform(2.9, 3.8) if shifted else rng.uniform(2.4, 3.1)
    return _sample_room(rng, domain, W, D, H)


# How a room is lit, for the 'wide' domain: daylight through a window in a side or back wall,
# ceiling panels (large area lights overhead), both, a few lamps, or any mix. The base and shifted
# domains light rooms with small lamps and wall windows only, and their models never saw an
# overhead area light or a room lit by one window alone.
WIDE_LIGHTING = ("window_side", "window_back", "ceiling", "ceiling_window", "lamps", "mixed")


def _wide_lighting(rng) -> tuple[int, list[int]]:
    """(number of lamps, surfaces of the area lights) for one 'wide' room."""
    kind = WIDE_LIGHTING[int(rng.integers(0, len(WIDE_LIGHTING)))]
    if kind == "window_side":
        return int(rng.random() < 0.3), [int(rng.integers(0, 2))] * int(rng.integers(1, 3))
    if kind == "window_back":
        return int(rng.random() < 0.3), [2] * int(rng.integers(1, 3))
    if kind == "ceiling":
        return 0, [4] * int(rng.integers(1, 5))
    if kind == "ceiling_window":
        return 0, [4] * int(rng.integers(1, 4)) + [int(rng.integers(0, 3))]
    if kind == "lamps":
        return int(rng.integers(1, 5)), []
    return int(rng.integers(0, 4)), [int(rng.choice([0, 1, 2, 4])) for _ in range(int(rng.integers(1, 4)))]


def _sample_room(rng, domain, W, D, H) -> Room:
    shifted = domain == "shifted"
    wide = domain in WIDE_DOMAINS
    size = np.array([W, D, H])
    albedo = np.empty((5, TEX, TEX, 3))
    wall_paint = _paint(rng, 0.25, 0.6, 0.25) if shifted else (_paint(rng, 0.25, 0.9, 0.25) if wide else _paint(rng, 0.4, 0.9, 0.15))
    for s in range(5):
        paint = wall_paint if s < 3 else (_paint(rng, 0.1, 0.5, 0.3) if s == 3 else _paint(rng, 0.6, 0.9, 0.05))
        if s < 3 and rng.random() < 0.3:
            paint = _paint(rng, 0.1, 0.9, 0.5)  # an accent wall
        var = rng.uniform(0.02, 0.25 if s == 3 else 0.12)
        albedo[s] = paint * (1 + var * _smooth_field(rng, TEX))[..., None]
        for _ in range(rng.integers(0, 5)):  # furniture, pictures, rugs: coloured rectangles
            u0, v0 = rng.uniform(0, 0.85, 2)
            du, dv = rng.uniform(0.05, 0.4, 2)
            iu, iv = (np.array([u0, u0 + du]) * TEX).astype(int), (np.array([v0, v0 + dv]) * TEX).astype(int)
            if s < 3:  # furniture stands on the floor
                iv = iv - iv[0] if rng.random() < 0.6 else iv
            albedo[s, iv[0] : iv[1], iu[0] : iu[1]] = _paint(rng, 0.03, 0.8, 0.6)
    albedo = np.clip(albedo, 0.02, 0.95)

    if wide:
        n_lamps, area_lights = _wide_lighting(rng)
        n_windows = len(area_lights)
    else:
        n_lamps = int(rng.integers(0, 5 if shifted else 4))
        n_windows = int(rng.integers(0, 3))
        area_lights = None
        if n_lamps + n_windows == 0:
            n_lamps = 1
    lamp_pos, lamp_radius, lamp_rad = [], [], []
    for _ in range(n_lamps):
        kind = rng.random()
        a = rng.uniform(0.03, 0.2)
        if kind < 0.5:  # ceiling lamp
            z = H - rng.uniform(0.1, 0.6)
        elif kind < 0.8:  # floor lamp
            z = rng.uniform(1.2, 1.9)
        else:  # desk lamp
            z = rng.uniform(0.6, 1.1)
        pos = np.array([rng.uniform(0.3, W - 0.3), rng.uniform(0.4, D - 0.3), min(z, H - a - 0.02)])
        if kind >= 0.5:  # standing lamps stand by a side or back wall, out of the walkers' way
            side = rng.integers(0, 3)
            if side < 2:
                pos[0] = rng.uniform(0.15, 0.35) if side == 0 else W - rng.uniform(0.15, 0.35)
            else:
                pos[1] = D - rng.uniform(0.15, 0.35)
        temp = rng.uniform(0, 1)  # warm .. cool white
        colour = np.array([1.0, 0.72 + 0.25 * temp, 0.45 + 0.55 * temp]) * (1 + rng.uniform(-0.05, 0.05, 3))
        intensity = rng.uniform(15, 300) * (0.5 if shifted else 1.0) * (np.exp(rng.uniform(-1.2, 0.3)) if wide else 1.0)
        lamp_pos.append(pos)
        lamp_radius.append(a)
        lamp_rad.append(colour * intensity / (np.pi * a * a))
    lamp_pos = np.array(lamp_pos).reshape(-1, 3)
    lamp_radius = np.array(lamp_radius, float)
    lamp_rad = np.array(lamp_rad).reshape(-1, 3)

    # Surface irradiance: direct lamp light + closed-box ambient estimate.
    vv, uu = (np.mgrid[0:TEX, 0:TEX] + 0.5) / TEX
    direct = np.zeros((5, TEX, TEX, 3))
    area = np.array([D * H, D * H, W * H, W * D, W * D])
    for s in range(5):
        p = surface_uv_to_xyz(size, s, uu, vv)
        for k in range(len(lamp_radius)):
            d = lamp_pos[k] - p
            r2 = np.einsum("...k,...k", d, d)
            cos = np.clip(d @ NORMALS[s] / np.sqrt(r2), 0, None)
            direct[s] += (np.pi * lamp_rad[k] * (lamp_radius[k] ** 2 / r2 * cos)[..., None])
    windows, window_flux = [], np.zeros(3)
    sky = np.array([0.85, 0.93, 1.0]) * (1 + rng.uniform(-0.08, 0.08, 3))
    window_mask = np.zeros((5, TEX, TEX), bool)
    window_rad = np.zeros((5, TEX, TEX, 3))
    for j in range(n_windows):
        s = int(rng.integers(0, 3)) if area_lights is None else area_lights[j]
        if s == 4:  # a ceiling panel: anywhere overhead, warm to cool white, as bright as a window
            wu, wv = rng.uniform(0.08, 0.35), rng.uniform(0.08, 0.35)
            u0, v0 = rng.uniform(0.02, 0.98 - wu), rng.uniform(0.02, 0.98 - wv)
            temp = rng.uniform(0, 1)
            L = rng.uniform(5, 80) * np.array([1.0, 0.8 + 0.18 * temp, 0.6 + 0.4 * temp])
        else:
            wu, wv = rng.uniform(0.15, 0.45), rng.uniform(0.3, 0.55)
            u0, v0 = rng.uniform(0.05, 0.95 - wu), rng.uniform(0.25, 0.95 - wv)
            L = rng.uniform(3, 60) * sky
        iu = slice(int(u0 * TEX), int((u0 + wu) * TEX))
        iv = slice(int(v0 * TEX), int((v0 + wv) * TEX))
        grad = 1 + rng.uniform(-0.2, 0.2) * (vv[iv, iu] - v0) / wv
        window_mask[s, iv, iu] = True
        window_rad[s, iv, iu] = L * grad[..., None]
        window_flux += np.pi * L * (wu * wv * area[s])
        windows.append((s, u0, u0 + wu, v0, v0 + wv))
    # windows and panels light the room's surfaces directly too (a bright pool on the floor under a
    # panel, a sunlit strip of wall), not only through the ambient estimate
    sources = area_sources(size, windows, window_rad)
    if len(sources[0]):
        cap = np.pi * window_rad.reshape(-1, 3).max(axis=0)  # no surface gets more than a sky of it
        for s in range(5):
            p = surface_uv_to_xyz(size, s, uu, vv).reshape(-1, 3)
            E, _ = area_irradiance(sources, p, np.broadcast_to(NORMALS[s], p.shape))
            direct[s] += np.minimum(E.sum(axis=1), cap).reshape(TEX, TEX, 3)
    rho_mean = float(np.average(albedo.mean(axis=(1, 2, 3)), weights=area))
    lamp_flux = 4 * np.pi * (lamp_rad * (np.pi * lamp_radius**2)[:, None]).sum(axis=0)
    ambient = rho_mean * (lamp_flux + window_flux) / (area.sum() + W * H) / (1 - rho_mean)
    radiance = albedo * (direct + ambient) / np.pi
    radiance[window_mask] = window_rad[window_mask]
    return Room(size, albedo, radiance, lamp_pos, lamp_radius, lamp_rad, ambient, windows)


def uniform_room(size=(5.0, 5.0, 3.0), radiance=(1.0, 1.0, 1.0)) -> Room:
    """A room of uniform radiance and no lamps: the test bed for the analytic checks."""
    L = np.asarray(radiance, float)
    rad = np.broadcast_to(L, (5, TEX, TEX, 3)).copy()
    return Room(np.asarray(size, float), np.full((5, TEX, TEX, 3), 0.5), rad, np.zeros((0, 3)),
                np.zeros(0), np.zeros((0, 3)), np.pi * L)


def _patches(room: Room):
    """Corner polygons (S*P*P, 4, 3), normals and mean radiance of every surface patch."""
    P = PATCHES
    g = np.linspace(0, 1, P + 1)
    polys, normals, rad = [], [], []
    pooled = room.radiance.reshape(5, P, TEX // P, P, TEX // P, 3).mean(axis=(2, 4))
    for s in range(5):
        for j in range(P):
            for i in range(P):
                u = np.array([g[i], g[i + 1], g[i + 1], g[i]])
                v = np.array([g[j], g[j], g[j + 1], g[j + 1]])
                polys.append(surface_uv_to_xyz(room.size, s, u, v))
                normals.append(NORMALS[s])
                rad.append(pooled[s, j, i])
    return np.array(polys), np.array(normals), np.array(rad)


def static_irradiance(room: Room, points: np.ndarray, chunk: int = 256) -> np.ndarray:
    """Irradiance (N, 3) at points on the wall y = 0 from the empty room."""
    polys, _, rad = _patches(room)
    wall_n = np.array([0.0, 1.0, 0.0])
    out = np.zeros((len(points), 3))
    for i in range(0, len(points), chunk):
        F = polygon_form_factor(points[i : i + chunk], wall_n, polys)
        out[i : i + chunk] = np.pi * F @ rad
    for k in range(len(room.lamp_radius)):
        d = room.lamp_pos[k] - points
        r2 = np.einsum("nk,nk->n", d, d)
        out += np.pi * room.lamp_radiance[k] * (room.lamp_radius[k] ** 2 * d[:, 1] / r2**1.5)[:, None]
    return out


def background_radiance(room: Room, points: np.ndarray, dirs: np.ndarray, blurred: bool = False) -> np.ndarray:
    """Radiance of the room surface hit by rays from wall points (..., 3) along dirs (..., 3) (dir_y > 0)."""
    p, d = np.broadcast_arrays(points, dirs)
    return _bg_lookup(room, p[..., 0], p[..., 2], d[..., 0], d[..., 1], d[..., 2], blurred)


def _bg_lookup(room, px, pz, dx, dy, dz, blurred):
    """Ray-box exit for rays from the wall y = 0, then a nearest-texel lookup of the hit surface."""
    W, D, H = (float(v) for v in room.size)
    with np.errstate(divide="ignore", invalid="ignore"):
        inv_x = 1.0 / dx
        inv_z = 1.0 / dz
        tx = np.where(dx > 0, W - px, -px) * inv_x
        tz = np.where(dz > 0, H - pz, -pz) * inv_z
        ty = D / dy
    tx[~np.isfinite(tx)] = np.inf
    tz[~np.isfinite(tz)] = np.inf
    side_x = tx < tz
    t_side = np.where(side_x, tx, tz)
    back = ty <= t_side
    t = np.where(back, ty, t_side)
    hx, hy, hz = px + t * dx, t * dy, pz + t * dz
    # surface index: 2 back; else 0/1 side walls by sign of dx; else 3/4 floor/ceiling by sign of dz
    s = np.where(back, 2, np.where(side_x, (dx > 0).astype(np.int8), 3 + (dz > 0)))
    u = np.where(s <= 1, hy * (TEX / D), hx * (TEX / W))
    v = np.where(s <= 2, hz * (TEX / H), hy * (TEX / D))
    iu = np.clip(u.astype(np.intp), 0, TEX - 1)
    iv = np.clip(v.astype(np.intp), 0, TEX - 1)
    return (room.radiance_blur if blurred else room.radiance)[s, iv, iu]


def index_interp(n: int, idx: np.ndarray) -> np.ndarray:
    """(n, len(idx)) linear interpolation weights from samples at sorted integer positions idx."""
    A = np.zeros((n, len(idx)))
    if len(idx) == 1:
        A[:, 0] = 1
        return A
    for r in range(n):
        k = min(np.searchsorted(idx, r, side="right") - 1, len(idx) - 2)
        w = (r - idx[k]) / (idx[k + 1] - idx[k])
        A[r, k], A[r, k + 1] = 1 - w, w
    return A


