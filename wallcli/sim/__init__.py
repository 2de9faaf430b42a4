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
# 'bracket' is 'steady' with the analytic world's known departures from a path tracer randomised
# per scene (issue 35): the bodies' own radiance 0.3-1.5x, the shadows they cast on the room's other
# surfaces (the whole-wall share of the signal) 0.5-3x, so that the analytic world brackets the
# path tracer's signal instead of missing it on one side.
WIDE_DOMAINS = ("wide", "steady", "bracket")
BODY_GAIN = (0.3, 1.5)
SHADOW_GAIN = (0.5, 3.0)


def moving_truth(activities) -> dict:
    """The truth file's count of people who move (what ``wallcli count`` answers; ``people``
    counts everyone in the room), with the same words as the README and ``count --help``."""
    from wallcli.wording import COUNT_COUNTS

    return {"moving": sum(a != "none" for a in activities), "moving_note": COUNT_COUNTS}
