"""The simulator: physically grounded blank-wall recordings, pure numpy (no io/cli/plots imports).

- geometry.py   exact form factors (sphere, polygon), disc overlap, Lambert-sphere phase
- room.py       box room, lamps, windows, textures; static wall irradiance; body occlusion
- bodies.py     people as 20 spheres, forward kinematics
- motion.py     the five activities as randomised pose tracks
- camera.py     exposure, tone, shot/read noise, PRNU, 8-bit rounding, drift, flicker, AE, shake
- scene.py      one seeded recording of the 3-D room (frames + ground truth)
- flatland.py   the seed's 2-D world with exact mutual visibility; world_flat.py: it as a recording
"""
