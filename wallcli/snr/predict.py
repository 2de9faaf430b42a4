"""The SNR a wall should show, predicted from the physics (Sharma et al. 2021, supplementary §3.1)
and a camera model: ``snr --predict`` (the measurement is :mod:`wallcli.snr.estimate`)."""
from __future__ import annotations



from wallcli.errors import WallcliError
from wallcli.snr.estimate import snr_db


def coverage(radius: float, distance: float, *, approx: bool = False) -> float:
    """Fraction of the wall point's projected hemisphere a person covers: r^2/(r^2+d^2) exactly
    for a disk facing the point, A/(pi d^2) = r^2/d^2 in the far-field approximation."""
    if approx:
        return radius**2 / distance**2
    return radius**2 / (radius**2 + distance**2)


def predict(*, distance: float, radius: float, albedo: float, contrast: float, occupancy: float,
            approx: bool = False, mean_code: float | None = None, gain: float | None = None,
            read_noise: float = 0.0, bits: int = 8, pixels: float = 1.0, frames: float = 1.0) -> dict:
    """Seed §3.1: signal power q (alpha theta (L_p - L_s))^2 in code values^2.

    Radiances are in code values (what a white wall lit by that radiance alone would record), so
    alpha * theta * contrast is the change of the wall's code value. With a camera model (mean code
    value, electrons per 8-bit code value, read noise in electrons, bit depth) the per-pixel noise
    power is shot mean/gain + (read/gain)^2 + step^2/12 (step = 2^(8-bits) on the 8-bit scale),
    divided by the pixels and frames averaged (the slow signal survives both averages).
    """
    if distance <= 0 or radius <= 0:
        raise WallcliError("distance and radius must be positive")
    theta = coverage(radius, distance, approx=approx)
    amplitude = albedo * theta * contrast
    out = {"theta": theta, "amplitude": amplitude, "signal_power": occupancy * amplitude**2}
    if mean_code is not None and gain is not None:
        if gain <= 0:
            raise WallcliError("--gain (electrons per code value) must be positive")
        step = 2.0 ** (8 - bits)
        shot = max(mean_code, 0.0) / gain
        read = (read_noise / gain) ** 2
        quant = step**2 / 12.0
        noise = (shot + read + quant) / (pixels * frames)
        out.update({"noise_power": noise, "shot": shot / (pixels * frames), "read": read / (pixels * frames),
                    "quantisation": quant / (pixels * frames), "snr": out["signal_power"] / noise,
                    "snr_db": float(snr_db(out["signal_power"], noise))})
    return out
