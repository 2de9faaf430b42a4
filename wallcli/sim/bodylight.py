"""The light bodies of spheres take from (or add to) the observed wall: the analytic world's people.

Each sphere changes a wall point's irradiance by exactly pi * (r/D)^2 cos(beta) * (L_body -
L_behind) when the background behind it is uniform over its angular disc; L_behind is the radiance
of the room surface hit by the ray through the sphere's centre, looked up on radiance maps blurred
by ~15 cm (:mod:`wallcli.sim.room`, which models the room). Lamps behind a sphere are occluded by
the planar-disc overlap of the two angular discs; where two spheres overlap as seen from a wall
point the farther one's hidden part is removed (angular-disc overlap). The approximations and
their checks are in room.py's docstring and tests/sim/test_physics.py.
"""

from __future__ import annotations

import numpy as np

from wallcli.sim.geometry import disc_overlap, lambert_sphere_phase
from wallcli.sim.room import Room, _bg_lookup, area_irradiance, index_interp


def body_radiance(room: Room, centers: np.ndarray, albedo: np.ndarray, view: np.ndarray) -> np.ndarray:
    """Mean radiance (M, 3) of Lambertian spheres seen from ``view`` (a point on the wall)."""
    L = np.broadcast_to(room.ambient, albedo.shape) / np.pi
    L = L.copy()
    to_view = view - centers
    to_view /= np.linalg.norm(to_view, axis=-1, keepdims=True)
    for k in range(len(room.lamp_radius)):
        d = room.lamp_pos[k] - centers
        r2 = np.einsum("mk,mk->m", d, d)
        cos_a = np.einsum("mk,mk->m", d, to_view) / np.sqrt(r2)
        e = np.pi * room.lamp_radiance[k][None] * (room.lamp_radius[k] ** 2 / r2 * lambert_sphere_phase(np.arccos(np.clip(cos_a, -1, 1))))[:, None]
        L += e / np.pi
    if room.sources is not None and len(room.sources[0]):
        E, u = area_irradiance(room.sources, centers)  # (M, S, 3): each sub-source lights the sphere's facing side
        phase = lambert_sphere_phase(np.arccos(np.clip(np.einsum("msk,mk->ms", u, to_view), -1, 1)))
        L += np.einsum("msc,ms->mc", E, phase) / np.pi
    return albedo * L


def body_delta(room: Room, points: np.ndarray, centers: np.ndarray, radii: np.ndarray,
               L_body: np.ndarray, bbox: tuple | None = None, pairs: np.ndarray | None = None) -> np.ndarray:
    """Change of irradiance (..., 3) at wall points (..., 3) caused by spheres (module docstring).

    Form factors are exact at every point; the background behind a sphere is looked up on the
    blurred radiance maps, standing in for its mean over the sphere's angular disc.
    ``pairs`` (P, 2) lists sphere pairs that may overlap as seen from the wall (``overlapping_pairs``):
    the part of the farther sphere's angular disc that the nearer one covers is removed
    (angular-disc overlap; several hiders combine as independent, see _pair_overlap).
    """
    shape = points.shape[:-1]
    flat = points.reshape(-1, 3)
    if len(radii) == 0:
        return np.zeros(shape + (3,))
    if bbox is None:
        bbox = (flat[:, 0].min(), flat[:, 0].max(), flat[:, 2].min(), flat[:, 2].max())
    hidden = None
    if pairs is not None and len(pairs):
        if points.ndim == 3 and min(shape) > 5:
            # occlusion between spheres changes slowly along the wall (parallax): exact on a 5 x 5
            # sub-grid, interpolated linearly in between
            iy = np.linspace(0, shape[0] - 1, 5).round().astype(int)
            ix = np.linspace(0, shape[1] - 1, 5).round().astype(int)
            h = hidden_fraction(points[np.ix_(iy, ix)].reshape(-1, 3), centers, radii, np.asarray(pairs))
            h = (index_interp(shape[0], iy) @ h.reshape(5, -1)).reshape(shape[0], 5, -1)
            h = np.matmul(index_interp(shape[1], ix)[None], h)  # (gy, gx, M)
            hidden = h.reshape(len(flat), -1)
        else:
            hidden = hidden_fraction(flat, centers, radii, np.asarray(pairs))
    chunk = 768  # keeps the (points, spheres) temporaries in cache
    out = np.concatenate([_delta_flat(room, flat[i : i + chunk], centers, radii, L_body, bbox,
                                      None if hidden is None else hidden[i : i + chunk])
                          for i in range(0, len(flat), chunk)])
    return out.reshape(shape + (3,))


def _delta_flat(room, flat, centers, radii, L_body, bbox, hidden=None):
    # float32 is ample here: these are the small terms themselves, not differences of large ones
    c = centers.astype(np.float32)
    f = flat.astype(np.float32)
    vx = c[None, :, 0] - f[:, 0:1]
    vy = c[None, :, 1] - f[:, 1:2]
    vz = c[None, :, 2] - f[:, 2:3]
    d2 = vx * vx + vy * vy + vz * vz
    dist = np.sqrt(d2)
    inv = 1.0 / dist
    F = (radii[None, :] ** 2).astype(np.float32) * vy * inv / d2
    if hidden is not None:
        F = F * (1 - hidden).astype(np.float32)  # the parts hidden behind nearer spheres
    L_bg = _bg_lookup(room, f[:, 0:1], f[:, 2:3], vx * inv, vy * inv, vz * inv, True)
    dE = np.pi * (F @ L_body - np.einsum("nm,nmc->nc", F, L_bg))
    if len(room.lamp_radius):
        dE -= _lamp_occlusion(room, flat, centers, radii, (vx, vy, vz), dist, L_bg, bbox)
    return dE


def overlapping_pairs(probes: np.ndarray, centers: np.ndarray, radii: np.ndarray, margin: float = 1.25) -> np.ndarray:
    """Sphere pairs (P, 2) whose angular discs overlap (or nearly, x margin) seen from any probe
    point: candidates for the pair correction of body_delta. Probes: a few wall points spanning
    the observed region (parallax between them is small, the margin covers it)."""
    v = centers[None] - probes[:, None]  # (K, M, 3)
    dist = np.linalg.norm(v, axis=-1)
    u = v / dist[..., None]
    sig = np.arcsin(np.clip(radii[None] / dist, 0, 1))
    cos_g = np.einsum("kmc,knc->kmn", u, u)
    lim = np.cos(np.minimum(margin * (sig[:, :, None] + sig[:, None, :]), np.pi))
    close = (cos_g > lim).any(axis=0)
    a, b = np.nonzero(np.triu(close, 1))
    return np.stack([a, b], -1)


def hidden_fraction(points: np.ndarray, centers: np.ndarray, radii: np.ndarray, pairs: np.ndarray) -> np.ndarray:
    """(N, M) fraction of each sphere's angular disc hidden behind nearer spheres, seen from points.

    For every pair the nearer sphere hides the fraction f = overlap / disc of the farther one;
    a sphere hidden by several nearer ones keeps prod(1 - f) of its disc (the hiders' overlaps
    are treated as independent, which is exact for one hider and bounded for more)."""
    v = centers[None] - points[:, None]
    dist = np.linalg.norm(v, axis=-1)
    u = v / dist[..., None]
    sig = np.arcsin(np.clip(radii[None] / dist, 0, 1))
    a, b = pairs[:, 0], pairs[:, 1]
    cos_g = np.einsum("npc,npc->np", u[:, a], u[:, b])
    sa, sb = sig[:, a], sig[:, b]
    omega = disc_overlap(sa, sb, np.arccos(np.clip(cos_g, -1, 1)))
    a_far = dist[:, a] > dist[:, b]
    s_far = np.where(a_far, sa, sb)
    far = np.where(a_far, a[None], b[None])
    frac = np.clip(omega / (np.pi * s_far * s_far), 0, 1 - 1e-9)
    keep_log = np.zeros(dist.size)
    np.add.at(keep_log, (np.arange(len(points))[:, None] * dist.shape[1] + far).ravel(), np.log1p(-frac).ravel())
    return -np.expm1(keep_log.reshape(dist.shape))


def _lamp_occlusion(room, points, centers, radii, u, dist, L_bg, bbox):
    """Irradiance removed where spheres cover part of a lamp's angular disc (soft shadows)."""
    out = np.zeros((len(points), 3))
    x0, x1, z0, z1 = bbox
    for k in range(len(room.lamp_radius)):
        lp, a = room.lamp_pos[k], room.lamp_radius[k]
        cy = centers[:, 1]
        ok = cy + radii < lp[1] - a
        t = lp[1] / np.maximum(lp[1] - cy, 1e-9)
        sx = lp[0] + (centers[:, 0] - lp[0]) * t
        sz = lp[2] + (centers[:, 2] - lp[2]) * t
        reach = 1.3 * (radii * t + a * (t - 1)) + 0.05
        ok &= (sx + reach > x0) & (sx - reach < x1) & (sz + reach > z0) & (sz - reach < z1)
        js = np.flatnonzero(ok)
        if js.size == 0:
            continue
        w = lp - points
        R = np.linalg.norm(w, axis=-1)
        w /= R[:, None]
        vx, vy, vz = u
        cos_g = (vx[:, js] * w[:, 0:1] + vy[:, js] * w[:, 1:2] + vz[:, js] * w[:, 2:3]) / dist[:, js]
        sig = np.arcsin(np.clip(radii[js][None] / dist[:, js], 0, 1))
        lam = np.arcsin(np.clip(a / R, 0, 1))[:, None]
        # only (point, sphere) pairs whose discs can touch, and where the sphere is nearer than the lamp
        near = (cos_g > np.cos(np.minimum(sig + lam, np.pi))) & (dist[:, js] < R[:, None])
        n_i, j_i = np.nonzero(near)
        if n_i.size == 0:
            continue
        gamma = np.arccos(np.clip(cos_g[n_i, j_i], -1, 1))
        lam_n = lam[n_i, 0]
        frac = np.clip(disc_overlap(sig[n_i, j_i], lam_n, gamma) / (np.pi * lam_n * lam_n), 0, 1 - 1e-9)
        # several spheres over one lamp: the lamp keeps prod(1 - f) (not 1 - sum f, which could go negative)
        s_frac = np.zeros(len(points))
        s_log = np.zeros(len(points))
        np.add.at(s_frac, n_i, frac)
        np.add.at(s_log, n_i, np.log1p(-frac))
        scale = -np.expm1(s_log[n_i]) / np.maximum(s_frac[n_i], 1e-12)
        omega = frac * scale * (np.pi * lam_n * lam_n) * w[n_i, 1]
        contrast = room.lamp_radiance[k][None, :] - L_bg[n_i, js[j_i]]
        np.add.at(out, n_i, omega[:, None] * contrast)
    return out
