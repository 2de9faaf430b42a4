"""Is this a usable static view of a wall? The view check (check.py) and its measurements: image, cuts, light, motion, thresholds."""
