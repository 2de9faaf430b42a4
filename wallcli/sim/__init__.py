"""The simulator: physically grounded blank-wall recordings, pure numpy (no io/cli/plots imports).

- geometry.py   exact form factors (sphere, polygon), disc overlap, Lambert-sphere phase
- room.py       box room, lamps, windows, textures; static wall irradiance; body occlusion
- bodies.py     people as 20 spheres, forward kinematics
- motion.py     the five activities as randomised pose tracks
- camera.py     exposure, tone, shot/read noise, PRNU, 8-bit rounding, drift, flicker, AE, shake
- scene.py      one seeded recording of the 3-D room (frames + ground truth)
- shadows.py    bodies shadowing the room's other surfaces: the whole-wall dimming
- flatland.py   the seed's 2-D world with exact mutual visibility; world_flat.py: it as a recording
"""

# Domains drawn from the 'wide' ranges: 'steady' is 'wide' with lighting nuisances in a sixth of
# the clips instead of half (most rooms' light is steady; a net trained with half its empty rooms
# flickering learns that a whole-wall change is normal, and misses the people who cause one).
WIDE_DOMAINS = ("wide", "steady")
