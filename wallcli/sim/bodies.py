"""Articulated people built of spheres, posed by forward kinematics.

A person is 20 spheres: head, three along the torso (pelvis, belly, chest), two per upper arm,
two per forearm, two per thigh, two per shin. The torso spheres overlap each other and the
shoulders and hips (``OVERLAP_PAIRS``), and in profile an arm overlaps the torso; the renderer
finds the pairs that overlap as seen from the wall (bodylight.overlapping_pairs) and counts their
common solid angle once. Limb spheres leave small gaps (a chain of spheres covers ~80 % of a
cylinder's silhouette). The spheres' total cross-section is 0.45 m^2 for a 1.75 m adult of
average girth (girth is randomised).

Poses come from ``wallcli.sim.motion`` as arrays over frames; everything here is vectorised
over time: ``sphere_centers(person, pose)`` -> (T, 20, 3).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from wallcli.sim import WIDE_DOMAINS

N_SPHERES = 20
# sphere -> body part: 0 head, 1 torso (top clothing), 2 arms (top / skin), 3 legs (bottom)
PART = np.array([0, 1, 1, 1] + [2] * 8 + [3] * 8)
# sphere pairs that overlap in every pose: pelvis-belly, belly-chest, chest-upper arms, pelvis-thighs
OVERLAP_PAIRS = np.array([[1, 2], [2, 3], [3, 4], [3, 8], [1, 12], [1, 16]])


@dataclass
class Person:
    height: float  # metres
    girth: float  # width factor, 1 = average build
    top: np.ndarray  # (3,) albedo of upper clothing
    bottom: np.ndarray  # (3,) albedo of trousers / skirt
    skin: np.ndarray  # (3,) albedo of face / hands
    sleeves: bool  # long sleeves: forearms take the top colour

    @property
    def s(self) -> float:
        return self.height / 1.75

    def radii(self) -> np.ndarray:
        s, g = self.s, self.girth
        r = [0.105 * s, 0.155 * s * g, 0.145 * s * g, 0.165 * s * g]
        r += [0.058 * s * g, 0.052 * s * g, 0.046 * s * g, 0.042 * s * g] * 2
        r += [0.085 * s * g, 0.075 * s * g, 0.062 * s * g, 0.052 * s * g] * 2
        return np.array(r)

    def albedo(self) -> np.ndarray:
        a = np.empty((N_SPHERES, 3))
        a[0] = 0.6 * self.skin + 0.4 * np.array([0.08, 0.06, 0.05])  # face and hair
        a[1:4] = self.top
        for side in (0, 4):
            a[4 + side : 6 + side] = self.top
            a[6 + side : 8 + side] = self.top if self.sleeves else self.skin
        a[12:] = self.bottom
        return a


def _colour(rng, lo: float, hi: float) -> np.ndarray:
    """A clothing albedo: a random hue with saturation, brightness from dark to light."""
    v = rng.uniform(lo, hi)
    sat = rng.uniform(0.0, 0.8)
    hue = rng.uniform(0, 2 * np.pi)
    rgb = 1 + sat * np.cos(hue - np.array([0.0, 2.094, 4.189]))
    return np.clip(v * rgb / rgb.max(), 0.02, 0.9)


def sample_person(rng: np.random.Generator, domain: str = "base") -> Person:
    shifted, wide = domain == "shifted", domain in WIDE_DOMAINS
    height = rng.uniform(1.25, 2.0) if (shifted or wide) else rng.uniform(1.5, 1.95)
    girth = rng.uniform(0.8, 1.35) if (shifted or wide) else rng.uniform(0.85, 1.2)
    lo, hi = (0.02, 0.5) if shifted else ((0.02, 0.85) if wide else (0.03, 0.85))
    skin = np.clip(rng.uniform(0.12, 0.6) * np.array([1.0, 0.75, 0.6]), 0.02, 0.9)
    return Person(height, girth, _colour(rng, lo, hi), _colour(rng, lo, hi), skin, bool(rng.random() < 0.6))


def _unit(*components):
    return np.stack(components, -1)


def _skeleton(person: Person, pose: dict) -> dict:
    """Joints and the body's frame per frame (arrays (T, 3)); sides are 'l' (the person's left,
    the first of each pose pair) and 'r'. Limb directions (unit, (T, 3)) ride along as d_*."""
    s, g = person.s, person.girth
    x, y, psi = pose["x"], pose["y"], pose["heading"]
    T = len(x)
    f = _unit(np.cos(psi), np.sin(psi), np.zeros(T))  # forward
    lat = _unit(-np.sin(psi), np.cos(psi), np.zeros(T))  # to the person's left
    up = np.array([0.0, 0.0, 1.0])
    thigh = shin = 0.45 * s
    crouch = pose["crouch"]
    # hip height: standing 0.92 s, squat drops it, gait bobs it, jumps lift everything
    hip_z = 0.92 * s - crouch * 0.5 * s + pose.get("bob", 0.0) * s
    root = _unit(x, y, np.zeros(T))
    lift = pose["lift"][:, None] * up

    lean = pose["lean"]
    trunk = np.cos(lean)[:, None] * up + np.sin(lean)[:, None] * f
    pelvis = root + hip_z[:, None] * up + lift
    j = {"forward": f, "left": lat, "trunk": trunk, "pelvis": pelvis,
         "head": pelvis + 0.72 * s * trunk, "neck": pelvis + 0.53 * s * trunk}
    for k, side in enumerate((1.0, -1.0)):
        n = "lr"[k]
        # arms: sagittal swing (forward +) and abduction (sideways up), elbow flex
        sw, ab, el = pose["arm_swing"][:, k], pose["arm_abduct"][:, k], pose["elbow"][:, k]
        sh = j["neck"] + (side * 0.19 * s * g) * lat
        d1 = (-np.cos(ab) * np.cos(sw))[:, None] * up + (np.cos(ab) * np.sin(sw))[:, None] * f + (side * np.sin(ab))[:, None] * lat
        wave = pose["wave"][:, k]  # forearm rotation in the arm's frontal plane
        a2 = ab + el * 0.5 + wave
        d2 = (-np.cos(a2) * np.cos(sw + el * 0.5))[:, None] * up + (np.cos(a2) * np.sin(sw + el * 0.5))[:, None] * f + (side * np.sin(a2))[:, None] * lat
        elbow = sh + 0.30 * s * d1
        j.update({f"shoulder_{n}": sh, f"elbow_{n}": elbow, f"wrist_{n}": elbow + 0.28 * s * d2,
                  f"d_upperarm_{n}": d1, f"d_forearm_{n}": d2})

        # legs: hip angle (forward +) and knee flex; in a squat the knee is solved so feet stay down
        hip = pelvis + (side * 0.09 * s * g) * lat
        span = np.clip(hip_z - 0.03 * s, 0.2 * s, thigh + shin)
        squat = np.arccos(np.clip(span / (thigh + shin), -1, 1))
        th = pose["hip"][:, k] + squat
        kn = pose["knee"][:, k] + 2 * squat
        d_t = np.sin(th)[:, None] * f - np.cos(th)[:, None] * up
        d_s = np.sin(th - kn)[:, None] * f - np.cos(th - kn)[:, None] * up
        knee = hip + thigh * d_t
        j.update({f"hip_{n}": hip, f"knee_{n}": knee, f"ankle_{n}": knee + shin * d_s,
                  f"d_thigh_{n}": d_t, f"d_shin_{n}": d_s})
    return j


def joints(person: Person, pose: dict) -> dict:
    """Joint positions (T, 3) for pose tracks: pelvis, neck (between the shoulders), head (its
    centre), shoulder/elbow/wrist/hip/knee/ankle _l and _r; plus the unit vectors forward, left
    and trunk (pelvis to neck). The path tracer builds its box people from these."""
    return {k: v for k, v in _skeleton(person, pose).items() if not k.startswith("d_")}


def sphere_centers(person: Person, pose: dict) -> np.ndarray:
    """Sphere centres (T, 20, 3) for pose tracks (arrays of length T, see motion.py)."""
    s = person.s
    j = _skeleton(person, pose)
    pelvis, trunk = j["pelvis"], j["trunk"]
    out = np.empty((len(pelvis), N_SPHERES, 3))
    out[:, 1] = pelvis + 0.03 * s * trunk
    out[:, 2] = pelvis + 0.22 * s * trunk
    out[:, 3] = pelvis + 0.40 * s * trunk
    out[:, 0] = j["head"]
    thigh = shin = 0.45 * s
    for k, n in enumerate("lr"):
        sh, d1, d2, elbow = j[f"shoulder_{n}"], j[f"d_upperarm_{n}"], j[f"d_forearm_{n}"], j[f"elbow_{n}"]
        base = 4 + 4 * k
        out[:, base] = sh + 0.30 * s * 0.25 * d1
        out[:, base + 1] = sh + 0.30 * s * 0.72 * d1
        out[:, base + 2] = elbow + 0.28 * s * 0.3 * d2
        out[:, base + 3] = elbow + 0.28 * s * 0.8 * d2
        hip, d_t, d_s, knee = j[f"hip_{n}"], j[f"d_thigh_{n}"], j[f"d_shin_{n}"], j[f"knee_{n}"]
        base = 12 + 4 * k
        out[:, base] = hip + thigh * 0.3 * d_t
        out[:, base + 1] = hip + thigh * 0.78 * d_t
        out[:, base + 2] = knee + shin * 0.3 * d_s
        out[:, base + 3] = knee + shin * 0.78 * d_s
    return out
