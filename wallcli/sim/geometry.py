"""Small exact geometric formulas shared by the room renderer and the tests.

Conventions: the observed wall is the plane y = 0 with normal +y; the room is x in [0, W],
y in [0, D], z in [0, H]. Irradiance E is in W/m^2-like units, radiance L in the same units / sr,
so a uniform surround of radiance L gives E = pi * L.
"""

from __future__ import annotations

import numpy as np


def sphere_form_factor(points: np.ndarray, centers: np.ndarray, radii: np.ndarray) -> np.ndarray:
    """Form factor (fraction of the projected hemisphere) of spheres seen from wall points.

    Exact: for a sphere wholly in front of the plane y = 0 the differential-area-to-sphere form
    factor is (r/D)^2 cos(beta), D the distance to the centre and beta its angle from the normal.
    points (N, 3), centers (M, 3), radii (M,) -> (N, M).
    """
    v = centers[None, :, :] - points[:, None, :]
    d2 = np.einsum("nmk,nmk->nm", v, v)
    return radii[None, :] ** 2 * v[..., 1] / (d2 * np.sqrt(d2))


def polygon_form_factor(points: np.ndarray, normal: np.ndarray, polys: np.ndarray) -> np.ndarray:
    """Exact point-to-polygon form factors by Lambert's contour integral.

    F = 1/(2 pi) * sum_k angle(v_k, v_k+1) * n . unit(v_k x v_k+1), valid for polygons wholly on
    the visible side of the receiving point's plane. points (N, 3), polys (P, V, 3) -> (N, P).
    """
    v = polys[None, :, :, :] - points[:, None, None, :]  # (N, P, V, 3)
    v /= np.linalg.norm(v, axis=-1, keepdims=True)
    w = np.roll(v, -1, axis=2)
    cross = np.cross(v, w)
    sin_t = np.linalg.norm(cross, axis=-1)
    cos_t = np.einsum("npvk,npvk->npv", v, w)
    angle = np.arctan2(sin_t, cos_t)
    proj = np.einsum("npvk,k->npv", cross, normal) / np.maximum(sin_t, 1e-12)
    return np.abs((angle * proj).sum(axis=2)) / (2.0 * np.pi)


def disc_overlap(r1: np.ndarray, r2: np.ndarray, d: np.ndarray) -> np.ndarray:
    """Area of intersection of two planar discs (radii r1, r2, centre distance d), broadcast."""
    r1, r2, d = np.broadcast_arrays(np.asarray(r1, float), np.asarray(r2, float), np.asarray(d, float))
    out = np.zeros(d.shape)
    small = np.minimum(r1, r2)
    inside = d <= np.abs(r1 - r2)
    out[inside] = np.pi * small[inside] ** 2
    part = (~inside) & (d < r1 + r2)
    if np.any(part):
        a, b, c = r1[part], r2[part], np.maximum(d[part], 1e-12)
        x1 = np.clip((c * c + a * a - b * b) / (2 * c * a), -1, 1)
        x2 = np.clip((c * c + b * b - a * a) / (2 * c * b), -1, 1)
        k = np.clip((-c + a + b) * (c + a - b) * (c - a + b) * (c + a + b), 0, None)
        out[part] = a * a * np.arccos(x1) + b * b * np.arccos(x2) - 0.5 * np.sqrt(k)
    return out


def lambert_sphere_phase(alpha: np.ndarray) -> np.ndarray:
    """Mean radiance of a Lambertian sphere's visible disc at phase angle alpha, relative to
    rho*E/pi of a surface facing the source (2/3 at full phase, 0 at new phase)."""
    alpha = np.clip(alpha, 0.0, np.pi)
    return (2.0 / (3.0 * np.pi)) * (np.sin(alpha) + (np.pi - alpha) * np.cos(alpha))
