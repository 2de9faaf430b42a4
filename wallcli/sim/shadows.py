"""People's shadows on the room's other surfaces, as the observed wall sees them.

bodylight.body_delta gives what a body does to the observed wall directly: it hides the room behind it
and shows its own lit surface. A body also intercepts light on its way from every lamp, window and
ceiling panel to the floor, the ceiling and the other walls; those surfaces then reflect less onto
the observed wall. In a path tracer (and in a real room) this is a whole-wall dimming that follows
the person, often larger than the direct term: a walker between a window and the floor darkens the
pool of light the whole wall sees (research/pathtrace/README.md measured 1.5 x the analytic signal
without it).

Model, per light source s and body sphere j (both exact in the limit of small spheres):
- the sphere intercepts the flux I_s(u) * pi r^2 / R^2 (times the part of its disc that no nearer
  sphere already covers, seen from the source: bodylight.hidden_fraction);
- that flux is missing where the ray from the source through the sphere's centre meets a room
  surface (its shadow: the flux a shadow removes from a plane equals the flux the occluder
  intercepts, whatever the plane's slope);
- the shadowed patch reflected rho(P) of it as a Lambertian emitter; the observed wall point x
  loses rho * Phi * cos(theta_P) cos(theta_x) / (pi (|x - P|^2 + sigma^2)), sigma the shadow's
  radius (it softens the term where the shadow is near x);
- the rest of the room's interreflected light (the closed-box ambient of room.py) loses the part of
  the flux the body absorbs, (1 - albedo) * Phi: a uniform change of rho_mean^2 / (1 - rho_mean) /
  area per unit flux over the whole observed wall.
Shadows that fall on the observed wall itself (y = 0) are bodylight.body_delta's (lamps) or belong to
no patch the wall sees (a plane does not light itself), so they are skipped.
"""

from __future__ import annotations

import numpy as np

from wallcli.sim.bodylight import hidden_fraction, overlapping_pairs
from wallcli.sim.room import NORMALS, TEX, Room, index_interp

SUB = 6  # the term is smooth over the wall (distant, soft sources): exact on SUB x SUB points


def _ray_exit(room: Room, origin: np.ndarray, d: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Where rays (K, 3) from points inside the box leave it: (hit points, surface index with 5 =
    the observed wall y = 0, distance)."""
    W, D, H = (float(v) for v in room.size)
    lo, hi = np.zeros(3), np.array([W, D, H])
    with np.errstate(divide="ignore", invalid="ignore"):
        t_axis = np.where(d > 0, (hi - origin) / d, np.where(d < 0, (lo - origin) / d, np.inf))
    t_axis = np.where(np.isfinite(t_axis) & (t_axis > 0), t_axis, np.inf)
    axis = np.argmin(t_axis, axis=1)
    t = t_axis[np.arange(len(d)), axis]
    positive = d[np.arange(len(d)), axis] > 0
    # axis 0 -> walls 0 (x=0) / 1 (x=W); axis 1 -> 5 (y=0, observed) / 2 (back); axis 2 -> 3 floor / 4 ceiling
    surf = np.select([axis == 0, axis == 1], [positive.astype(int), np.where(positive, 2, 5)], 3 + positive)
    return origin + t[:, None] * d, surf, t


def _albedo_at(room: Room, surf: np.ndarray, p: np.ndarray) -> np.ndarray:
    """Albedo (K, 3) of surfaces 0..4 at points p (nearest texel)."""
    W, D, H = (float(v) for v in room.size)
    s = np.clip(surf, 0, 4)
    u = np.where(s <= 1, p[:, 1] / D, p[:, 0] / W)
    v = np.where(s <= 2, p[:, 2] / H, p[:, 1] / D)
    iu = np.clip((u * TEX).astype(np.intp), 0, TEX - 1)
    iv = np.clip((v * TEX).astype(np.intp), 0, TEX - 1)
    return room.albedo[s, iv, iu]


def _sources(room: Room) -> tuple[np.ndarray, np.ndarray, np.ndarray | None]:
    """Every light as a point: positions (S, 3), intensity scale (S, 3) and emitting normals
    (S, 3) for area lights (None rows are isotropic lamps, marked by a zero normal)."""
    pos = [room.lamp_pos.reshape(-1, 3)]
    power = [room.lamp_intensity.reshape(-1, 3)]
    nrm = [np.zeros((len(room.lamp_radius), 3))]
    if room.sources is not None and len(room.sources[0]):
        a_pos, a_nrm, a_pow = room.sources
        pos.append(a_pos)
        # a Lambertian emitter of radiance L and area A sends L A cos(theta) per steradian
        power.append(a_pow)
        nrm.append(a_nrm)
    return np.concatenate(pos), np.concatenate(power), np.concatenate(nrm)


def shadow_delta(room: Room, points: np.ndarray, centers: np.ndarray, radii: np.ndarray,
                 body_albedo: np.ndarray) -> np.ndarray:
    """Change of irradiance (..., 3) at wall points (..., 3) from the bodies' shadows on the other
    room surfaces (module docstring); spheres (M, 3), radii (M,), albedo (M, 3)."""
    shape = points.shape[:-1]
    if len(radii) == 0:
        return np.zeros(shape + (3,))
    S_pos, S_pow, S_nrm = _sources(room)
    if len(S_pos) == 0:
        return np.zeros(shape + (3,))
    v = centers[None] - S_pos[:, None]  # (S, M, 3)
    R2 = np.maximum(np.einsum("smk,smk->sm", v, v), 1e-6)
    R = np.sqrt(R2)
    u = v / R[..., None]
    lamp = ~np.any(S_nrm != 0, axis=1)
    cos_e = np.where(lamp[:, None], 1.0, np.clip(np.einsum("smk,sk->sm", u, S_nrm), 0, None))
    pairs = overlapping_pairs(S_pos, centers, radii)
    seen = 1.0 - (hidden_fraction(S_pos, centers, radii, pairs) if len(pairs) else 0.0)
    phi = S_pow[:, None, :] * (cos_e * np.pi * radii[None] ** 2 / R2 * seen)[..., None]  # (S, M, 3)
    S, M = R.shape
    hit, surf, t = _ray_exit(room, np.repeat(S_pos, M, axis=0), u.reshape(-1, 3))
    phi = phi.reshape(-1, 3)
    keep = (surf != 5) & (t > R.ravel()) & np.any(phi > 0, axis=1)
    hit, surf, phi = hit[keep], surf[keep], phi[keep]
    # the light each sphere would have sent on: first the shadowed patch's own reflection ...
    rho_p = _albedo_at(room, surf, hit)
    sigma2 = (np.repeat(radii[None], S, axis=0).ravel()[keep] * t[keep] / R.ravel()[keep]) ** 2
    flat = points.reshape(-1, 3)
    gy, gx = shape if len(shape) == 2 else (1, len(flat))
    if len(shape) == 2 and min(shape) > SUB:
        iy = np.linspace(0, gy - 1, SUB).round().astype(int)
        ix = np.linspace(0, gx - 1, SUB).round().astype(int)
        probe = points[np.ix_(iy, ix)].reshape(-1, 3)
    else:
        probe = flat
    w = probe[:, None] - hit[None]  # (N, K, 3) from the shadow to the wall point
    d2 = np.einsum("nkc,nkc->nk", w, w)
    cos_p = np.clip(np.einsum("nkc,kc->nk", w, NORMALS[surf]), 0, None) / np.sqrt(np.maximum(d2, 1e-9))
    cos_x = np.clip(-w[..., 1], 0, None) / np.sqrt(np.maximum(d2, 1e-9))
    dE = -np.einsum("nk,kc->nc", cos_p * cos_x / (np.pi * (d2 + sigma2[None])), rho_p * phi)
    # ... then every further bounce: the room's ambient loses what the bodies absorb
    sphere_of = np.tile(np.arange(M), S)[keep]
    absorbed = ((1 - body_albedo[sphere_of]) * phi).sum(axis=0)
    W, D, H = (float(x) for x in room.size)
    area = 2 * (W * D + W * H + D * H)
    rho = float(room.albedo.mean())
    dE = dE - rho * rho / (1 - rho) * absorbed / area
    if probe is not flat:
        dE = np.einsum("ya,abc,xb->yxc", index_interp(gy, iy), dE.reshape(SUB, SUB, 3), index_interp(gx, ix))
    return dE.reshape(shape + (3,))
