"""Physics checks of the renderer against closed forms and brute-force integration (seed §3, §5)."""

import numpy as np
import pytest

from wallcli.sim import bodies, flatland
from wallcli.sim.geometry import disc_overlap, polygon_form_factor, sphere_form_factor
from wallcli.sim.motion import standing
from wallcli.sim.bodylight import body_delta, overlapping_pairs
from wallcli.sim.room import static_irradiance, uniform_room


def _hemisphere_quadrature(point, covered, n=1200):
    """Brute force: fraction of the projected hemisphere at ``point`` (normal +y) where covered(dirs) holds."""
    # midpoint rule in (sin^2 theta, phi): cos-weighted hemisphere measure is uniform in that chart
    u = (np.arange(n) + 0.5) / n
    phi = (np.arange(2 * n) + 0.5) / (2 * n) * 2 * np.pi
    s = np.sqrt(u)[:, None]
    c = np.sqrt(1 - u)[:, None]
    dirs = np.stack(np.broadcast_arrays(s * np.cos(phi), c, s * np.sin(phi)), -1)
    return covered(point, dirs).mean()


def _ray_hits_sphere(center, r):
    def f(p, d):
        oc = center - p
        t = d @ oc
        return (t > 0) & (np.einsum("...k,...k", oc, oc) - t * t < r * r)
    return f


@pytest.mark.parametrize("beta_deg", [0, 30, 60])
def test_sphere_form_factor_matches_brute_force(beta_deg):
    p = np.array([0.0, 0.0, 0.0])
    D, r = 1.5, 0.3
    b = np.radians(beta_deg)
    c = np.array([D * np.sin(b), D * np.cos(b), 0.0])
    exact = sphere_form_factor(p[None], c[None], np.array([r]))[0, 0]
    brute = _hemisphere_quadrature(p, _ray_hits_sphere(c, r))
    assert exact == pytest.approx((r / D) ** 2 * np.cos(b))
    assert brute == pytest.approx(exact, rel=0.02)


@pytest.mark.parametrize("r,d", [(0.25, 1.0), (0.3, 2.0), (0.5, 3.0)])
def test_disc_changes_irradiance_by_theta_tilde_times_contrast(r, d):
    """Seed §3: a disc of radius r facing x at distance d covers r^2/(r^2+d^2) of the projected
    hemisphere. Brute-force the disc; render the sphere with the same silhouette cone."""
    L_s, L_p = 1.0, 0.35
    theta = r * r / (r * r + d * d)
    p = np.array([2.5, 0.0, 1.5])

    def disc(pt, dirs):
        t = d / np.maximum(dirs[..., 1], 1e-12)
        hx, hz = dirs[..., 0] * t, dirs[..., 2] * t
        return hx * hx + hz * hz < r * r

    assert _hemisphere_quadrature(p, disc) == pytest.approx(theta, rel=0.02)
    room = uniform_room(radiance=(L_s,) * 3)
    E0 = static_irradiance(room, p[None])[0]
    R = d * np.sqrt(theta)  # sphere at distance d whose silhouette cone is the disc's
    dE = body_delta(room, p[None], p[None] + [0, d, 0], np.array([R]), np.full((1, 3), L_p))[0]
    assert dE / E0 == pytest.approx(theta * (L_p - L_s) / L_s, rel=0.02)


def test_uniform_room_static_irradiance_is_pi_L_everywhere():
    room = uniform_room(size=(4.0, 6.0, 2.7), radiance=(0.5, 1.0, 2.0))
    pts = np.array([[2.0, 0, 1.3], [0.05, 0, 0.05], [3.9, 0, 2.6], [1.0, 0, 2.0]])
    E = static_irradiance(room, pts)
    np.testing.assert_allclose(E, np.pi * np.array([0.5, 1.0, 2.0])[None].repeat(4, 0), rtol=1e-9)


def test_polygon_form_factor_of_facing_square_closed_form():
    # unit square centred on the normal at height h: F = (2/pi) * [a/sqrt(1+a^2) atan(1/sqrt(1+a^2))]*2 (a = half/h... )
    h, s = 1.0, 0.5
    poly = np.array([[[-s, h, -s], [s, h, -s], [s, h, s], [-s, h, s]]])
    F = polygon_form_factor(np.zeros((1, 3)), np.array([0.0, 1.0, 0.0]), poly)[0, 0]
    a = s / h
    closed = (2 / np.pi) * 2 * (a / np.sqrt(1 + a * a)) * np.arctan(a / np.sqrt(1 + a * a))
    assert F == pytest.approx(closed, rel=1e-9)


def test_sphere_fully_covering_a_lamp_removes_its_light():
    room = uniform_room(radiance=(0.0, 0.0, 0.0))
    room.lamp_pos = np.array([[2.0, 3.0, 1.5]])
    room.lamp_radius = np.array([0.05])
    room.lamp_radiance = np.array([[100.0, 100.0, 100.0]])
    p = np.array([[2.0, 0.0, 1.5]])
    E_lamp = static_irradiance(room, p)[0]
    assert E_lamp == pytest.approx(np.pi * 100 * 0.05**2 / 9, rel=1e-9)
    # dark sphere on the line of sight, angular radius 0.2/1.5 > lamp's 0.05/3: full shadow
    dE = body_delta(room, p, np.array([[2.0, 1.5, 1.5]]), np.array([0.2]), np.zeros((1, 3)))[0]
    assert dE == pytest.approx(-E_lamp, rel=0.01)
    # moved sideways until the discs just touch: no shadow; half way: a partial (soft) shadow
    far = body_delta(room, p, np.array([[2.3, 1.5, 1.5]]), np.array([0.2]), np.zeros((1, 3)))[0]
    assert far == pytest.approx(np.zeros(3), abs=1e-12)
    part = body_delta(room, p, np.array([[2.2, 1.5, 1.5]]), np.array([0.2]), np.zeros((1, 3)))[0]
    assert -E_lamp[0] < part[0] < 0


def test_disc_overlap_limits():
    assert disc_overlap(1.0, 0.5, 0.2) == pytest.approx(np.pi * 0.25)
    assert disc_overlap(1.0, 1.0, 2.5) == 0
    assert disc_overlap(1.0, 1.0, 0.0) == pytest.approx(np.pi)
    # two unit discs at distance 1: lens area 2 pi/3 - sqrt(3)/2
    assert disc_overlap(1.0, 1.0, 1.0) == pytest.approx(2 * np.pi / 3 - np.sqrt(3) / 2)


def test_person_signal_falls_with_distance_as_seed_predicts():
    """Seed §3: the zero-mean signal ~ A (L_p - L_s) / d^2 (power ~ 1/d^4)."""
    rng = np.random.default_rng(0)
    person = bodies.Person(1.75, 1.0, np.full(3, 0.3), np.full(3, 0.3), np.full(3, 0.3), True)
    room = uniform_room(size=(6.0, 6.0, 3.0), radiance=(1.0, 1.0, 1.0))
    L_p = 0.2
    p = np.array([[3.0, 0.0, 1.2]])
    A = np.pi * np.sum(person.radii() ** 2)
    dists = np.array([1.0, 1.5, 2.0, 3.0, 4.0])
    sig = []
    for d in dists:
        pose = standing(rng, np.zeros(1), (3.0, d))
        pose["x"][:], pose["y"][:] = 3.0, d
        c = bodies.sphere_centers(person, pose)[0]
        sig.append(-body_delta(room, p, c, person.radii(), np.full((20, 3), L_p))[0, 0])
    sig = np.array(sig)
    assert np.all(np.diff(sig) < 0)
    slope = np.polyfit(np.log(dists[2:]), np.log(sig[2:]), 1)[0]
    assert -2.4 < slope < -1.6
    predicted = A * (1.0 - L_p) / dists**2
    np.testing.assert_allclose(sig[2:], predicted[2:], rtol=0.3)


# ---------------------------------------------------------------- flatland

def _world(L=1.0, amb=None, occ=(0.2,), x0=-50.0, x1=50.0, n=32):
    amb = L if amb is None else amb
    return flatland.Flatland(2.0, 3.0, np.array([x0, x1]), np.full((1, 3), L), np.full(3, amb),
                             np.array([[o] * 3 for o in occ]), np.full((n, 3), 0.5), n)


def test_flatland_uniform_emitter_no_occluder_closed_form():
    w = _world(L=2.0, amb=0.5, x0=-1.0, x1=3.0)
    xs = w.receiver_x
    E = flatland.irradiance(w, np.zeros((0, 2, 2)))[:, 0]
    s1 = (3.0 - xs) / np.hypot(3.0 - xs, 3.0)
    s0 = (-1.0 - xs) / np.hypot(-1.0 - xs, 3.0)
    np.testing.assert_allclose(E, 2.0 * (s1 - s0) + 0.5 * (2 - (s1 - s0)), rtol=1e-12)


def test_flatland_parallel_occluder_closed_form():
    w = _world(L=1.0, occ=(0.2,))
    h, a, b = 1.2, 0.6, 1.1
    xs = w.receiver_x
    E = flatland.irradiance(w, np.array([[[a, h], [b, h]]]))[:, 0]
    sb = (b - xs) / np.hypot(b - xs, h)
    sa = (a - xs) / np.hypot(a - xs, h)
    # emitter spans +-50 m: the uniform field is L (sin) over nearly 2
    s1 = (50 - xs) / np.hypot(50 - xs, 3.0)
    s0 = (-50 - xs) / np.hypot(-50 - xs, 3.0)
    np.testing.assert_allclose(E, (s1 - s0) + 1.0 * (2 - (s1 - s0)) + (0.2 - 1.0) * (sb - sa), rtol=1e-12)


def test_flatland_mutual_visibility_matches_brute_force():
    rng = np.random.default_rng(5)
    w = flatland.sample_world(rng, 2, n_recv=8)
    segs = np.array([[[0.3, 1.0], [0.9, 1.1]], [[0.6, 1.8], [1.4, 1.7]]])  # the far one is partly hidden
    E = flatland.irradiance(w, segs)
    # brute force: 200k angles per receiver point, nearest hit wins
    th = (np.arange(200000) + 0.5) / 200000 * np.pi - np.pi / 2
    d = np.stack([np.sin(th), np.cos(th)], -1)
    for i, x in enumerate(w.receiver_x):
        t_best = np.full(len(th), np.inf)
        L = np.empty((len(th), 3))
        hx = x + w.depth * d[:, 0] / d[:, 1]
        cell = np.searchsorted(w.emitter_edges, hx) - 1
        on = (cell >= 0) & (cell < len(w.emitter_radiance))
        L[:] = w.ambient
        L[on] = w.emitter_radiance[cell[on]]
        for k, (a, b) in enumerate(segs):
            e = b - a
            den = d[:, 0] * (-e[1]) - d[:, 1] * (-e[0])
            r = a - np.array([x, 0.0])
            t = (r[0] * (-e[1]) - r[1] * (-e[0])) / den
            u = (d[:, 0] * r[1] - d[:, 1] * r[0]) / den
            hit = (t > 0) & (u >= 0) & (u <= 1) & (t < t_best)
            t_best[hit] = t[hit]
            L[hit] = w.occ_radiance[k]
        brute = (L * np.cos(th)[:, None]).sum(0) * (np.pi / len(th))
        np.testing.assert_allclose(E[i], brute, rtol=2e-3)


@pytest.mark.parametrize("d,heading", [(1.0, 0.0), (1.0, 1.57), (2.5, 0.7)])
def test_whole_person_form_factor_matches_brute_force_union_of_spheres(d, heading):
    """Overlapping torso spheres are counted once: the rendered person equals the union of its spheres."""
    rng = np.random.default_rng(1)
    person = bodies.Person(1.8, 1.1, np.full(3, 0.3), np.full(3, 0.3), np.full(3, 0.3), False)
    pose = standing(rng, np.zeros(1), (3.0, d))
    pose["x"][:], pose["y"][:], pose["heading"][:] = 2.8, d, heading
    c, r = bodies.sphere_centers(person, pose)[0], person.radii()
    p = np.array([[3.0, 0.0, 1.1]])
    room = uniform_room(size=(6.0, 6.0, 3.0))
    pairs = overlapping_pairs(p, c, r)
    assert {tuple(q) for q in bodies.OVERLAP_PAIRS} <= {tuple(q) for q in pairs}
    rendered = -body_delta(room, p, c, r, np.zeros((20, 3)), pairs=pairs)[0, 0] / np.pi

    def union(pt, dirs):
        hit = np.zeros(dirs.shape[:-1], bool)
        for cc, rr in zip(c, r):
            hit |= _ray_hits_sphere(cc, rr)(pt, dirs)
        return hit

    assert rendered == pytest.approx(_hemisphere_quadrature(p[0], union, n=800), rel=0.04)


def _panel_room(L=40.0, rect=(0.4, 0.6, 0.4, 0.6)):
    """A uniform grey room lit only by one ceiling panel (surface 4) of radiance L."""
    from wallcli.sim.room import TEX, Room

    size = np.array([5.0, 5.0, 3.0])
    rad = np.full((5, TEX, TEX, 3), 0.1)
    u0, u1, v0, v1 = rect
    rad[4, int(v0 * TEX):int(v1 * TEX), int(u0 * TEX):int(u1 * TEX)] = L
    return Room(size, np.full((5, TEX, TEX, 3), 0.5), rad, np.zeros((0, 3)), np.zeros(0), np.zeros((0, 3)),
                np.full(3, 0.3), [(4, *rect)])


@pytest.mark.parametrize("height", [0.8, 1.6])
def test_area_light_sources_match_the_exact_polygon_irradiance(height):
    """The 4 x 4 point sources a panel is split into give the irradiance of Lambert's exact contour
    integral at a point facing it (what lights a person's head under a ceiling panel)."""
    from wallcli.sim.room import area_irradiance, surface_uv_to_xyz

    room = _panel_room()
    p = np.array([[2.3, 2.6, 3.0 - height]])  # below the panel, off its centre
    E, _ = area_irradiance(room.sources, p, np.array([[0.0, 0.0, 1.0]]))
    poly = surface_uv_to_xyz(room.size, 4, np.array([0.4, 0.6, 0.6, 0.4]), np.array([0.4, 0.4, 0.6, 0.6]))
    exact = np.pi * 40.0 * polygon_form_factor(p, np.array([0.0, 0.0, 1.0]), poly[None])[0, 0]
    assert E.sum(axis=1)[0, 1] == pytest.approx(exact, rel=0.04)


def test_a_person_under_a_ceiling_panel_is_lit_by_it():
    """Bodies take direct light from windows and panels, not only the room's ambient light: under
    a bright panel a raised hand is far brighter than one held low, and brighter than ambient alone."""
    from wallcli.sim.bodylight import body_radiance

    room = _panel_room()
    albedo = np.full((2, 3), 0.5)
    centres = np.array([[2.5, 2.5, 2.5], [2.5, 2.5, 0.8]])  # a hand overhead, a hand by the hip
    L = body_radiance(room, centres, albedo, np.array([2.5, 0.0, 1.5]))[:, 1]
    ambient_only = 0.5 * 0.3 / np.pi
    assert L[1] > 1.5 * ambient_only
    assert L[0] > 4 * L[1]
