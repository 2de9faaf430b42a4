"""Activity -> pose tracks over time, randomised in timing, amplitude, position and path.

Every generator returns a dict of float arrays over the T frame times (see bodies.py):
x, y (floor position, y = distance from the observed wall), heading, crouch (0 standing .. 1
deep squat), bob (hip height offset / scale), lift (whole-body height offset, jumps), lean
(torso forward), and per-side (T, 2) arm_swing, arm_abduct, elbow, wave, hip, knee.

Activities (the classes): none (standing still: breathing-scale sway only), walking (waypoint
paths at 0.5-1.8 m/s with smooth turns and stops), crouching (squat down/hold/up bouts),
waving (one or both arms raised, forearm oscillating 1-3 Hz, in bouts; 'wide' also whole arms
swinging from the shoulder, and half the time without pause), jumping (pre-crouch, ballistic
flight of 5-40 cm, 'wide' up to 50 cm and arms overhead, landing, pauses; 'wide' half the time
in a steady rhythm).
"""

from __future__ import annotations

import numpy as np

from wallcli.sim import WIDE_DOMAINS

ACTIVITIES = ["none", "walking", "crouching", "waving", "jumping"]
G = 9.81


def _smooth(x: np.ndarray, n: int) -> np.ndarray:
    """Moving average of odd width n along axis 0 with edge padding."""
    n = max(1, int(n) | 1)
    if n == 1:
        return x
    pad = [(n // 2, n // 2)] + [(0, 0)] * (x.ndim - 1)
    c = np.cumsum(np.pad(x, pad, mode="edge"), axis=0)
    c = np.concatenate([np.zeros_like(c[:1]), c])
    return (c[n:] - c[:-n]) / n


def _base(t: np.ndarray, x: float, y: float, heading: float) -> dict:
    T = len(t)
    z = np.zeros(T)
    z2 = np.zeros((T, 2))
    return dict(x=np.full(T, x), y=np.full(T, y), heading=np.full(T, heading), crouch=z.copy(), bob=z.copy(),
                lift=z.copy(), lean=z.copy(), arm_swing=z2.copy(), arm_abduct=np.full((T, 2), 0.08),
                elbow=np.full((T, 2), 0.15), wave=z2.copy(), hip=z2.copy(), knee=z2.copy())


def _sway(rng, t, pose, amp):
    """Standing people are never perfectly still: slow, centimetre-scale weight shifts."""
    for key in ("x", "y"):
        a = rng.uniform(0.3, 1.0) * amp
        f = rng.uniform(0.05, 0.3)
        pose[key] = pose[key] + a * np.sin(2 * np.pi * f * t + rng.uniform(0, 2 * np.pi))
    return pose


def _bouts(rng, t, on_range, off_range):
    """A 0/1 track of randomly timed 'active' bouts, starting at a random phase."""
    out = np.zeros(len(t))
    now = t[0] - rng.uniform(0, on_range[1] + off_range[1])
    while now < t[-1]:
        on = rng.uniform(*on_range)
        out[(t >= now) & (t < now + on)] = 1
        now += on + rng.uniform(*off_range)
    return out


def standing(rng, t, spot):
    pose = _base(t, spot[0], spot[1], rng.uniform(0, 2 * np.pi))
    return _sway(rng, t, pose, 0.01)


def walking(rng, t, bounds, speed=(0.5, 1.8), cross: int = 0):
    """Waypoint walk. cross=+1/-1 starts at the left/right end heading across (two people cross)."""
    (x0, x1), (y0, y1) = bounds
    dt = t[1] - t[0] if len(t) > 1 else 1 / 30
    v_base = rng.uniform(*speed)
    if cross:
        p = np.array([x0 + 0.1 * (x1 - x0) if cross > 0 else x1 - 0.1 * (x1 - x0), rng.uniform(y0, y1)])
        targets = [np.array([x1 - rng.uniform(0, 0.2) * (x1 - x0) if cross > 0 else x0 + rng.uniform(0, 0.2) * (x1 - x0), rng.uniform(y0, y1)])]
    else:
        p = np.array([rng.uniform(x0, x1), rng.uniform(y0, y1)])
        targets = []
    pts = []
    lead = int(rng.uniform(0, 3) / dt)  # start mid-walk, not at rest
    need = len(t) + lead + 40
    while len(pts) < need:
        goal = targets.pop(0) if targets else np.array([rng.uniform(x0, x1), rng.uniform(y0, y1)])
        dist = np.linalg.norm(goal - p)
        if dist < 0.6:
            continue
        v = float(np.clip(v_base * rng.uniform(0.85, 1.15), speed[0], speed[1]))
        n = max(2, int(dist / (v * dt)))
        seg = p + (goal - p) * (np.arange(1, n + 1) / n)[:, None]
        pts.extend(seg)
        p = goal
        if rng.random() < 0.3:  # stop for a while
            pts.extend([p] * int(rng.uniform(0.4, 2.5) / dt))
    pts = np.array(pts[lead : lead + len(t) + 40])
    pts = _smooth(pts, 0.7 / dt)[: len(t)]  # rounds corners, ramps speed at stops
    vel = np.gradient(pts, dt, axis=0)
    speed_t = np.linalg.norm(vel, axis=1)
    heading = np.unwrap(np.arctan2(vel[:, 1], vel[:, 0]))
    moving = speed_t > 0.05
    if moving.any():
        idx = np.maximum.accumulate(np.where(moving, np.arange(len(t)), 0))
        first = np.argmax(moving)
        idx[:first] = first
        heading = _smooth(heading[idx], 0.3 / dt)
    pose = _base(t, 0.0, 0.0, 0.0)
    pose["x"], pose["y"], pose["heading"] = pts[:, 0], pts[:, 1], heading
    cadence = 0.75 + 0.2 * speed_t  # gait cycles (two steps) per second
    phase = np.cumsum(2 * np.pi * cadence * dt) + rng.uniform(0, 2 * np.pi)
    amp = np.clip(speed_t / 1.2, 0, 1.4)
    hip_a = rng.uniform(0.28, 0.4) * amp
    pose["hip"] = np.stack([hip_a * np.sin(phase), -hip_a * np.sin(phase)], -1)
    knee = 0.9 * amp[:, None] * np.clip(np.stack([np.sin(phase - 1.2), np.sin(phase - 1.2 + np.pi)], -1), 0, None)
    pose["knee"] = knee + 0.05
    arm_a = rng.uniform(0.15, 0.45) * amp
    pose["arm_swing"] = np.stack([-arm_a * np.sin(phase), arm_a * np.sin(phase)], -1)
    pose["bob"] = 0.015 * amp * np.cos(2 * phase)
    pose["lean"] = 0.05 * amp
    return pose


def crouching(rng, t, spot):
    pose = standing(rng, t, spot)
    depth = rng.uniform(0.35, 1.0)
    c = np.zeros(len(t))
    now = t[0] - rng.uniform(0, 4)
    while now < t[-1]:
        down, hold, up, rest = rng.uniform(0.5, 1.5), rng.uniform(0, 2.0), rng.uniform(0.5, 1.5), rng.uniform(0.3, 2.5)
        d = depth * rng.uniform(0.75, 1.0)
        for a, b, f in ((now, now + down, lambda u: 0.5 - 0.5 * np.cos(np.pi * u)), (now + down, now + down + hold, lambda u: 1 + 0 * u),
                        (now + down + hold, now + down + hold + up, lambda u: 0.5 + 0.5 * np.cos(np.pi * u))):
            m = (t >= a) & (t < b)
            c[m] = d * f((t[m] - a) / max(b - a, 1e-6))
        now += down + hold + up + rest
    pose["crouch"] = c
    pose["lean"] = 0.6 * c
    pose["arm_swing"] = (c * rng.uniform(0.3, 1.2))[:, None] * np.ones(2)
    return pose


def waving(rng, t, spot, domain: str = "base"):
    """A raised arm waving its forearm (hello), or, in the 'wide' domain, as often a whole arm or
    both swinging from the shoulder between hip and overhead (signalling, cheering): the larger
    motion that people also make and that changes a wall's light many times more."""
    pose = standing(rng, t, spot)
    both = rng.random() < (0.5 if domain in WIDE_DOMAINS else 0.35)
    side = int(rng.integers(0, 2))
    on = _smooth(_bouts(rng, t, (2.0, 7.0), (0.3, 2.0)), 0.5 / max(t[1] - t[0], 1e-3))
    if domain in WIDE_DOMAINS and rng.random() < 0.5:
        # waving without pause for the whole clip (flagging someone down, a long cheer): then the
        # wall's change is the wave itself, periodic with its harmonics, not the slow raising and
        # lowering of the arm between bouts (research/features/README.md)
        on = np.ones(len(t))
    if domain in WIDE_DOMAINS and rng.random() < 0.55:
        freq = rng.uniform(0.6, 2.5)
        lo, hi = rng.uniform(0.15, 1.4), rng.uniform(2.2, 3.0)
        phase = rng.uniform(0, 2 * np.pi)
        for k in (0, 1):
            if both or k == side:
                swing = lo + (hi - lo) * (0.5 - 0.5 * np.cos(2 * np.pi * freq * t + phase + (k * np.pi if rng.random() < 0.2 else 0)))
                pose["arm_abduct"][:, k] = 0.08 + on * (swing - 0.08)
                pose["arm_swing"][:, k] = on * rng.uniform(-0.3, 0.6)
                pose["elbow"][:, k] = 0.15 + on * rng.uniform(0.0, 0.4)
        return pose
    freq = rng.uniform(1.0, 3.0)
    amp = rng.uniform(0.25, 0.7)
    raise_to = rng.uniform(2.0, 2.9)
    for k in (0, 1):
        if both or k == side:
            pose["arm_abduct"][:, k] = 0.08 + on * (raise_to - 0.08)
            pose["elbow"][:, k] = 0.15 + on * rng.uniform(0.1, 0.6)
            pose["wave"][:, k] = on * amp * np.sin(2 * np.pi * freq * t + rng.uniform(0, 2 * np.pi))
    return pose


def jumping(rng, t, spot, domain: str = "base"):
    """Jumps in place; in the 'wide' domain also higher, and half the time with the arms thrown
    overhead (jumping jacks, a cheer) instead of swung forward."""
    pose = standing(rng, t, spot)
    c, lift, arms = np.zeros(len(t)), np.zeros(len(t)), np.zeros(len(t))
    now = t[0] - rng.uniform(0, 2)
    wide = domain in WIDE_DOMAINS
    height_base = rng.uniform(0.06, 0.5 if wide else 0.4)
    overhead = wide and rng.random() < 0.5
    # 'wide' also jumps in a steady rhythm half the time (skipping, jumping jacks): one pause and
    # one height for the clip, so the wall's change is periodic, as a jumping person's often is
    rhythm = rng.uniform(0.02, 0.3) if wide and rng.random() < 0.5 else None
    while now < t[-1]:
        prep, land = rng.uniform(0.2, 0.45), rng.uniform(0.15, 0.35)
        h = height_base * rng.uniform(0.7, 1.2)
        if rhythm is not None:
            prep, land, h = 0.3, 0.25, height_base
        fly = 2 * np.sqrt(2 * h / G)
        depth = rng.uniform(0.15, 0.45)
        m = (t >= now) & (t < now + prep)
        u = (t[m] - now) / prep
        c[m] = depth * np.sin(np.pi * u) ** 2 * (u < 0.75) + depth * (u >= 0.75) * (1 - (u - 0.75) * 4)
        arms[m] = -0.6 * np.sin(np.pi * u)
        m = (t >= now + prep) & (t < now + prep + fly)
        tau = t[m] - now - prep
        lift[m] = np.sqrt(2 * G * h) * tau - 0.5 * G * tau**2
        arms[m] = 1.2 * np.sin(np.pi * tau / fly)
        m = (t >= now + prep + fly) & (t < now + prep + fly + land)
        c[m] = depth * 0.8 * np.sin(np.pi * (t[m] - now - prep - fly) / land)
        if rhythm is not None:
            now += prep + fly + land + rhythm
            continue
        now += prep + fly + land + (rng.uniform(0.05, 0.6) if rng.random() < 0.6 else rng.uniform(0.6, 2.5))
    pose["crouch"], pose["lift"] = c, lift
    pose["lean"] = 0.5 * c
    if overhead:  # arms from the sides to overhead in flight, back down on landing
        pose["arm_abduct"] = 0.08 + (np.clip(arms, 0, None) / 1.2 * rng.uniform(1.8, 2.9))[:, None] * np.ones(2)
    else:
        pose["arm_swing"] = arms[:, None] * np.ones(2)
    return pose


def make_motion(rng, activity: str, t: np.ndarray, bounds, speed=(0.5, 1.8), cross: int = 0,
                domain: str = "base") -> dict:
    """Pose tracks for one person doing ``activity`` inside bounds ((x0, x1), (y0, y1))."""
    (x0, x1), (y0, y1) = bounds
    spot = (rng.uniform(x0, x1), rng.uniform(y0, y1))
    if activity == "walking":
        return walking(rng, t, bounds, speed, cross)
    if activity == "none":
        return standing(rng, t, spot)
    if activity == "crouching":
        return crouching(rng, t, spot)
    return {"waving": waving, "jumping": jumping}[activity](rng, t, spot, domain)
