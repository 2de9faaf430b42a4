"""How strong is the wall's signal: the estimator (estimate), per grid cell (map), predicted from physics (predict), said in one line (verdict)."""
