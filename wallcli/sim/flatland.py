"""Flatland (Sharma et al. 2021, supplementary §4): a 2-D world of a receiver line, an emitter line and 1-2 occluders.

Geometry: the receiver (the observed wall) is y = 0, x in [0, width]; the emitter (the lighting
environment) is the line y = depth, x in [x0, x1], split into cells of constant radiance;
directions that miss the emitter see the ambient radiance. Occluders are segments between the
lines moving back and forth in distorted sinusoids along random directions.

Rendering: the 2-D rendering equation at a receiver point is E = integral of L(theta) cos(theta)
d theta over (-pi/2, pi/2) = integral of L d(sin theta). The sin(theta) axis is cut at every
emitter-cell edge and occluder end point; in each piece one thing is visible (the nearest
occluder, else the emitter cell, else ambient), found by casting the piece's middle ray, so the
integral is exact for piecewise-constant radiance and non-intersecting occluders (mutual
visibility included: an occluder hides the emitter and a farther occluder).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np


@dataclass
class Flatland:
    width: float  # receiver length (m)
    depth: float  # receiver-emitter distance (m)
    emitter_edges: np.ndarray  # (K+1,) x of the emitter cells' edges
    emitter_radiance: np.ndarray  # (K, 3)
    ambient: np.ndarray  # (3,)
    occ_radiance: np.ndarray  # (n_occ, 3) radiance of each occluder's receiver-facing side
    albedo: np.ndarray  # (n_recv, 3) receiver albedo along x
    n_recv: int = 64

    @property
    def receiver_x(self) -> np.ndarray:
        return (np.arange(self.n_recv) + 0.5) / self.n_recv * self.width


def _sin_to(x: np.ndarray, p: np.ndarray, y: np.ndarray) -> np.ndarray:
    """sin(theta) of the direction from receiver points p (N, 1) to points (x, y)."""
    dx = x - p
    return dx / np.sqrt(dx * dx + y * y)


def irradiance(world: Flatland, segments: np.ndarray, xs: np.ndarray | None = None) -> np.ndarray:
    """Irradiance (N, 3) at receiver positions xs for occluder segments (n_occ, 2, 2) [[ax, ay], [bx, by]]."""
    p = (world.receiver_x if xs is None else np.asarray(xs, float))[:, None]
    N = p.shape[0]
    edges = world.emitter_edges[None, :]
    cuts = [np.broadcast_to(_sin_to(edges, p, world.depth), (N, edges.shape[1]))]
    for seg in segments:
        for end in seg:
            cuts.append(_sin_to(np.array([[end[0]]]), p, np.array([[end[1]]])))
    s = np.sort(np.concatenate([np.full((N, 1), -1.0), *cuts, np.full((N, 1), 1.0)], axis=1), axis=1)
    mid = 0.5 * (s[:, 1:] + s[:, :-1])
    ds = s[:, 1:] - s[:, :-1]
    dx, dy = mid, np.sqrt(np.clip(1 - mid * mid, 1e-12, None))
    # default: the emitter where the ray meets it, else ambient
    hit_x = p + world.depth * dx / dy
    cell = np.searchsorted(world.emitter_edges, hit_x) - 1
    on = (cell >= 0) & (cell < len(world.emitter_radiance))
    L = np.where(on[..., None], world.emitter_radiance[np.clip(cell, 0, len(world.emitter_radiance) - 1)], world.ambient)
    best = np.full(mid.shape, np.inf)
    for k, (a, b) in enumerate(segments):
        # p + t d = a + u (b - a): Cramer's rule
        ex, ey = b[0] - a[0], b[1] - a[1]
        den = dx * (-ey) - dy * (-ex)
        with np.errstate(divide="ignore", invalid="ignore"):
            rx, ry = a[0] - p, a[1]
            t = (rx * (-ey) - ry * (-ex)) / den
            u = (dx * ry - dy * rx) / den
        hit = (np.abs(den) > 1e-12) & (t > 0) & (u >= 0) & (u <= 1) & (t < best)
        best = np.where(hit, t, best)
        L = np.where(hit[..., None], world.occ_radiance[k], L)
    return np.einsum("nk,nkc->nc", ds, L)


def sample_world(rng: np.random.Generator, n_occ: int, n_recv: int = 64, domain: str = "base") -> Flatland:
    shifted = domain == "shifted"
    width = rng.uniform(1.0, 3.0)
    depth = rng.uniform(3.0, 8.0) if shifted else rng.uniform(2.0, 6.0)
    K = int(rng.integers(8, 48))
    x0, x1 = -rng.uniform(0.5, 4.0), width + rng.uniform(0.5, 4.0)
    edges = np.sort(np.concatenate([[x0, x1], rng.uniform(x0, x1, K - 1)]))
    base = rng.uniform(0.3, 1.0) * np.array([1.0, 0.9, 0.8]) * (1 + rng.uniform(-0.1, 0.1, 3))
    L = base * (1 + 0.3 * rng.standard_normal((K, 1))).clip(0.2)
    for _ in range(rng.integers(0, 4)):  # lamps / windows: a few bright cells
        k = rng.integers(0, K)
        L[k] *= rng.uniform(3, 30)
    ambient = base * rng.uniform(0.2, 1.0)
    occ = np.array([rng.uniform(0.02, 0.8) * (1 + rng.uniform(-0.5, 0.5, 3)) * base.mean() for _ in range(n_occ)]).reshape(-1, 3)
    albedo = rng.uniform(0.3, 0.9) * (1 + 0.1 * np.cumsum(rng.standard_normal(n_recv)) / np.sqrt(n_recv))
    albedo = np.clip(albedo[:, None] * (1 + rng.uniform(-0.1, 0.1, 3)), 0.05, 0.95)
    return Flatland(width, depth, edges, L, ambient, np.abs(occ), albedo, n_recv)


def occluder_tracks(rng: np.random.Generator, world: Flatland, n_occ: int, t: np.ndarray) -> np.ndarray:
    """(T, n_occ, 2, 2) segment end points moving in distorted sinusoids along random directions."""
    out = np.zeros((len(t), n_occ, 2, 2))
    for k in range(n_occ):
        half = rng.uniform(0.12, 0.35)
        c0 = np.array([rng.uniform(0, world.width), rng.uniform(0.5, world.depth - 0.5)])
        ang = rng.uniform(-0.6, 0.6) + (0 if rng.random() < 0.7 else np.pi / 2)  # mostly along the wall
        direction = np.array([np.cos(ang), np.sin(ang)])
        amp = rng.uniform(0.5, 2.5)
        f = rng.uniform(0.05, 0.3)
        phase = 2 * np.pi * f * t + rng.uniform(0, 2 * np.pi)
        s = np.sin(phase + rng.uniform(0, 0.8) * np.sin(2 * np.pi * rng.uniform(0.1, 0.5) * t + rng.uniform(0, 6.3)))
        c = c0 + amp * s[:, None] * direction
        c[:, 1] = np.clip(c[:, 1], 0.3, world.depth - 0.2)
        tilt = rng.uniform(-0.3, 0.3) + 0.1 * np.sin(2 * np.pi * rng.uniform(0.2, 1.0) * t)
        e = np.stack([np.cos(tilt), np.sin(tilt)], -1) * half
        out[:, k, 0], out[:, k, 1] = c - e, c + e
    return out
