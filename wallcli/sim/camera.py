"""Camera model: wall irradiance grid -> 8-bit RGB frames, with the faults of real cameras.

Pipeline per frame (float64 until the last step, never rounded in between):
  irradiance grid (gy, gx, 3) --bilinear--> image; x wall albedo texture x vignetting x PRNU
  x exposure (auto-exposure settles the clip's mean on ``level``) x light drift x mains flicker
  x auto-exposure steps; + sub-pixel shake (first-order shift of the static image);
  + photon shot noise (variance = code value x ``gain`` codes per electron) + read noise;
  x optional white-balance gains per colour, optional temporal noise reduction (sim/isp.py);
  -> optional tone curve (gamma) -> round to 8 bits.

Small frames stand for a larger sensor ROI: a (w x h) frame that images ``sensor_pixels``
real pixels averages ``sensor_pixels / (w h)`` of them per pixel, so the per-pixel noise is
divided by the square root of that ratio. The noise is floored at ``NOISE_FLOOR`` codes so that
8-bit rounding stays dithered, as it is in a real sensor whose every pixel carries noise.
"""

from __future__ import annotations

from dataclasses import asdict, dataclass

import numpy as np

from wallcli.sim import WIDE_DOMAINS
from wallcli.sim.isp import RecursiveFilter, awb_gains

NOISE_FLOOR = 0.35
CLIP_GUARD = 235.0  # output code the brightest 0.5 % of the static wall may reach (headroom for AE steps)


@dataclass
class CameraParams:
    width: int = 160
    height: int = 120
    fps: float = 30.0
    level: float = 120.0  # mean output code of the wall
    gain: float = 0.1  # codes per photo-electron (ISO): shot-noise strength
    read_noise: float = 1.0  # codes rms per real pixel
    sensor_pixels: float = 300_000.0  # real pixels the frame stands for
    prnu: float = 0.01  # relative pixel gain non-uniformity
    texture: float = 0.02  # fine wall texture (relative), also dithers the rounding
    vignette: float = 0.2
    gamma: float = 0.0  # 0: linear output, else code = 255 (x/255)^(1/gamma)
    codec: str = "ffv1"  # ffv1 (lossless mkv) | libx264
    crf: int = 18
    chroma: str = "444"  # FFV1 chroma sampling: 444 or 420 (H.264 is always 4:2:0)
    drift: float = 0.0  # relative amplitude of slow light drift
    flicker: float = 0.0  # relative amplitude of mains flicker (aliased to the frame rate)
    mains: float = 50.0
    rolling_shutter: float = 0.0  # readout time / frame interval: flicker as bands moving down the frame (0: global)
    ae_steps: int = 0
    ae_size: float = 0.02
    shake: float = 0.0  # rms sub-pixel shake (pixels)
    shake_exact: bool = False  # shake as an exact warp of each frame, not the first-order shift
    features: float = 0.0  # relative contrast of a door frame, a switch plate and a skirting
    # board on the wall (0: a plain wall): the structure a shaking camera's profiles move with
    noise_scale: float = 1.0  # user multiplier on all temporal noise
    tnr: float = 0.0  # temporal noise reduction: each frame blended with the last, out = a prev + (1 - a) in
    awb_drift: float = 0.0  # auto white balance hunting: relative amplitude of slow per-colour gains

    def to_dict(self) -> dict:
        return {k: (round(v, 6) if isinstance(v, float) else v) for k, v in asdict(self).items()}


def sample_camera(rng: np.random.Generator, domain: str = "base", *, nuisance_p: float = 0.35) -> CameraParams:
    """Random camera: from very clean (large ROI, low gain) to very noisy (small ROI, high ISO)."""
    if domain in WIDE_DOMAINS:
        return _sample_wide_camera(rng, nuisance_p=0.5 if domain == "wide" else 1 / 6)  # steady, bracket: a sixth
    shifted = domain == "shifted"
    w = int(rng.choice([128, 144, 160, 176, 192]) if not shifted else rng.choice([96, 112, 208, 224]))
    h = int(2 * round(w * rng.uniform(0.56, 0.8) / 2))
    p = CameraParams(width=w, height=max(h, 64))
    p.fps = float(rng.choice([15, 24, 25, 30, 30, 30, 48, 60]) if not shifted else rng.choice([20, 29.97, 50]))
    p.level = rng.uniform(50, 200)
    # Photon transfer of real cameras at indoor levels: 0.01-1 codes per electron (shot noise
    # 1-11 codes rms per pixel at level 120); the wall covers 50k-2M sensor pixels. The shifted
    # domain moves both ranges (noisier, smaller walls) without leaving the physical regime.
    p.gain = float(np.exp(rng.uniform(np.log(0.01), np.log(1.0)) if not shifted else rng.uniform(np.log(0.02), np.log(1.5))))
    p.read_noise = rng.uniform(0.3, 3.0)
    p.sensor_pixels = float(np.exp(rng.uniform(np.log(5e4), np.log(2e6)) if not shifted else rng.uniform(np.log(4e4), np.log(1.5e6))))
    p.prnu = rng.uniform(0.002, 0.02)
    p.texture = rng.uniform(0.005, 0.05)
    p.vignette = rng.uniform(0.0, 0.4)
    p.gamma = float(rng.uniform(1.6, 2.4)) if rng.random() < 0.6 else 0.0
    if rng.random() < 0.5:
        p.codec, p.crf = "libx264", int(rng.integers(8, 24 if not shifted else 28))
    p.chroma = "420" if rng.random() < 0.6 else "444"
    if rng.random() < nuisance_p:
        _nuisances(rng, p, drift=0.01, flicker=0.004, flicker_p=0.5)
    return p


def _nuisances(rng, p: CameraParams, *, drift: float, flicker: float, flicker_p: float) -> None:
    """Lighting and camera nuisances of one clip (up to these amplitudes), drawn in a fixed order."""
    p.drift = rng.uniform(0.0, drift)
    p.flicker = rng.uniform(0.0, flicker) * (rng.random() < flicker_p)
    p.mains = float(rng.choice([50.0, 60.0]))
    p.ae_steps = int(rng.integers(0, 3))
    p.ae_size = rng.uniform(0.005, 0.03)
    p.shake = rng.uniform(0.0, 0.3) * (rng.random() < 0.5)


def _sample_wide_camera(rng, nuisance_p: float = 0.5) -> CameraParams:
    """The 'wide' domain's camera: the union of the base and shifted ranges, small frames too, and
    lighting nuisances (drift, aliased mains flicker of up to 1 %, exposure steps) in half the clips:
    real rooms change their whole light while nobody moves, and a model must not count that."""
    w = int(rng.choice([96, 112, 128, 144, 160, 192, 224]))
    h = int(2 * round(w * rng.uniform(0.56, 0.8) / 2))
    p = CameraParams(width=w, height=max(h, 64))
    p.fps = float(rng.choice([15, 20, 24, 25, 29.97, 30, 30, 48, 50, 60]))
    p.level = rng.uniform(40, 210)
    p.gain = float(np.exp(rng.uniform(np.log(0.01), np.log(1.5))))
    p.read_noise = rng.uniform(0.3, 3.0)
    p.sensor_pixels = float(np.exp(rng.uniform(np.log(3e4), np.log(2e6))))
    p.prnu = rng.uniform(0.002, 0.03)
    p.texture = rng.uniform(0.005, 0.05)
    p.vignette = rng.uniform(0.0, 0.5)
    p.gamma = float(rng.uniform(1.6, 2.4)) if rng.random() < 0.6 else 0.0
    if rng.random() < 0.55:
        # crf 0 is lossless H.264, which some recorders write
        p.codec, p.crf = "libx264", (0 if rng.random() < 0.2 else int(rng.integers(6, 26)))
    p.chroma = "420" if rng.random() < 0.6 else "444"
    if rng.random() < nuisance_p:
        _nuisances(rng, p, drift=0.015, flicker=0.01, flicker_p=0.6)
    return p


def video_pix_fmt(p: CameraParams) -> str:
    """Pixel format to store: H.264 4:2:0; FFV1 4:4:4 or 4:2:0 (lossless after the camera's YUV step)."""
    return "yuv444p" if (p.codec == "ffv1" and p.chroma == "444") else "yuv420p"


def interp_matrix(n_out: int, n_in: int) -> np.ndarray:
    """(n_out, n_in) linear interpolation from n_in samples spanning [0, 1] to pixel centres."""
    pos = np.clip(((np.arange(n_out) + 0.5) / n_out) * (n_in - 1), 0, n_in - 1)
    k = np.minimum(pos.astype(int), n_in - 2) if n_in > 1 else np.zeros(n_out, int)
    A = np.zeros((n_out, n_in))
    if n_in == 1:
        A[:, 0] = 1
        return A
    w = pos - k
    A[np.arange(n_out), k] = 1 - w
    A[np.arange(n_out), k + 1] = w
    return A


def _smooth_noise(rng, n: int, scale: float) -> np.ndarray:
    y, x = np.mgrid[0:n, 0:n] / n
    f = sum(np.cos(2 * np.pi * (rng.uniform(0.3, 3) * x + rng.uniform(0.3, 3) * y) + rng.uniform(0, 6.3)) for _ in range(4))
    return scale * f / 4


def _features(H: int, W: int, contrast: float) -> np.ndarray:
    """A reflectance map with a door frame (a vertical band), a switch plate and a skirting board
    (a horizontal band), each ``contrast`` darker than the wall, edges a pixel soft."""
    import cv2

    m = np.ones((H, W), np.float32)
    m[:, int(0.70 * W):int(0.74 * W)] -= contrast
    m[int(0.45 * H):int(0.55 * H), int(0.20 * W):int(0.25 * W)] -= contrast
    m[int(0.92 * H):int(0.95 * H), :] -= contrast
    return cv2.GaussianBlur(np.clip(m, 0.05, 1.0), (0, 0), 0.7)


def _warp_chw(img: np.ndarray, dx: float, dy: float) -> np.ndarray:
    """An (H, 3, W) image moved by (dx, dy) pixels, bicubic, edges reflected."""
    import cv2

    hwc = np.ascontiguousarray(img.transpose(0, 2, 1))
    m = np.float32([[1, 0, dx], [0, 1, dy]])
    out = cv2.warpAffine(hwc, m, (hwc.shape[1], hwc.shape[0]), flags=cv2.INTER_CUBIC, borderMode=cv2.BORDER_REFLECT)
    return np.ascontiguousarray(out.transpose(0, 2, 1))


class Camera:
    """Turns irradiance grids into frames; all static maps and nuisance tracks fixed at init."""

    LUT_STEP = 64  # linear-value resolution of the tone/rounding table (1/64 code)

    def __init__(self, params: CameraParams, static_E: np.ndarray, wall_albedo: np.ndarray,
                 frames: int, rng: np.random.Generator):
        p = self.p = params
        H, W = p.height, p.width
        gy, gx = static_E.shape[:2]
        self.Ry = interp_matrix(H, gy).astype(np.float32)
        self.RxT = np.ascontiguousarray(interp_matrix(W, gx).T, dtype=np.float32)
        yy, xx = np.mgrid[0:H, 0:W]
        r2 = ((xx - W / 2) ** 2 + (yy - H / 2) ** 2) / ((W / 2) ** 2 + (H / 2) ** 2)
        fine = 1 + p.texture * rng.standard_normal((H, W, 1)) * np.array([1.0, 0.97, 1.03])
        low = wall_albedo * (1 + _smooth_noise(rng, max(H, W), 0.06)[:H, :W, None])
        prnu = 1 + p.prnu * rng.standard_normal((H, W, 3))
        self.gain_map = low * np.clip(fine, 0.5, 1.5) * (1 - p.vignette * r2)[..., None] * prnu
        if p.features:
            self.gain_map = self.gain_map * _features(H, W, p.features)[..., None]
        img = self.gain_map * self.upsample(static_E).transpose(0, 2, 1)
        lin_level = 255.0 * (p.level / 255.0) ** p.gamma if p.gamma else p.level
        self.k = lin_level / img.mean()
        # Exposure meters the wall's mean to `level` but never lets its brightest 0.5 % clip: a
        # clipped wall carries neither signal nor noise (a bright lamp near the wall made 5-12 %
        # of random scenes clip), and an operator or highlight-priority metering avoids it.
        lin_cap = 255.0 * (CLIP_GUARD / 255.0) ** p.gamma if p.gamma else CLIP_GUARD
        k_cap = lin_cap / max(float(np.percentile(img, 99.5)), 1e-12)
        if k_cap < self.k:
            self.k = k_cap
            # the params describe the clip that was made (sidecar, SNR bookkeeping): record the
            # mean level the capped exposure gives
            lin_mean = self.k * float(img.mean())
            p.level = 255.0 * (lin_mean / 255.0) ** (1.0 / p.gamma) if p.gamma else lin_mean
        # per-frame work runs in (H, 3, W) layout, the natural output of the separable upsampling
        chw = lambda a: np.ascontiguousarray(np.asarray(a, np.float32).transpose(0, 2, 1))  # noqa: E731
        self.static = chw(img * self.k)
        self.gain_k = chw(self.gain_map * self.k)
        self.grad_x = np.gradient(self.static, axis=2)
        self.grad_y = np.gradient(self.static, axis=0)
        # tone curve + rounding as one lookup on a 1/LUT_STEP grid of linear values
        x = np.arange(0, 256 * self.LUT_STEP + 1) / self.LUT_STEP
        tone = 255.0 * (x / 255.0) ** (1.0 / p.gamma) if p.gamma else x
        self.lut = np.clip(np.rint(tone), 0, 255).astype(np.uint8)
        ratio = max(p.sensor_pixels / (H * W), 1.0)
        var = (np.clip(self.static, 0, None) * p.gain + p.read_noise**2) / ratio
        self.sigma = (np.maximum(np.sqrt(var) * p.noise_scale, NOISE_FLOOR)).astype(np.float32)  # (H, 3, W)
        self.rng = rng
        self.row_gains = None  # (frames, H) flicker of a rolling shutter, else None
        self.gains, self.shifts = self._tracks(frames, rng)
        # the ISP's stages (sim/isp.py) draw from a child stream: with and without them, a seed
        # renders the same room, camera and noise
        self.awb = awb_gains(frames, p.fps, p.awb_drift, rng.spawn(1)[0]) if p.awb_drift else None
        self.tnr = RecursiveFilter(p.tnr) if p.tnr else None

    def upsample(self, E: np.ndarray) -> np.ndarray:
        """(gy, gx, 3) grid -> (H, 3, W) float32 image, bilinear."""
        gy, gx, c = E.shape
        a = (self.Ry @ np.asarray(E, np.float32).reshape(gy, gx * c)).reshape(-1, gx, c).transpose(0, 2, 1)
        return a @ self.RxT

    def _tracks(self, n: int, rng):
        """Per-frame global gain (drift x flicker x AE steps) and (dx, dy) shake."""
        p = self.p
        t = np.arange(n) / p.fps
        dur = max(t[-1], 1e-3) if n else 1.0
        g = np.ones(n)
        if p.drift:
            slow = sum(np.sin(2 * np.pi * rng.uniform(0.01, 0.15) * t + rng.uniform(0, 6.3)) for _ in range(2)) / 2
            g *= 1 + p.drift * (slow + rng.uniform(-1, 1) * t / dur)
        if p.flicker:
            f = 2 * p.mains
            alias = f - p.fps * np.round(f / p.fps)
            phase = 2 * np.pi * alias * t + rng.uniform(0, 6.3)
            if p.rolling_shutter:
                # row y is read rolling_shutter * y / H frame intervals after the first: the lamp's
                # phase (at its true 2 f_mains) advances down the frame, and at the frame times the
                # bands move at the alias frequency
                rows = 2 * np.pi * f * (p.rolling_shutter / p.fps) * (np.arange(p.height) + 0.5) / p.height
                self.row_gains = (1 + p.flicker * np.sin(phase[:, None] + rows[None, :])).astype(np.float32)
            else:
                g *= 1 + p.flicker * np.sin(phase)
        for _ in range(p.ae_steps):
            at = rng.uniform(0.1, 0.9) * dur
            ramp = np.clip((t - at) / rng.uniform(0.05, 0.3), 0, 1)
            g *= 1 + rng.choice([-1, 1]) * p.ae_size * ramp
        shifts = np.zeros((n, 2))
        if p.shake and n:
            tau = rng.uniform(0.05, 1.0) * p.fps
            a = np.exp(-1 / tau)
            e = rng.standard_normal((n, 2)) * p.shake * np.sqrt(1 - a * a)
            s = np.zeros(2)
            for i in range(n):
                s = a * s + e[i]
                shifts[i] = s
        return g, shifts

    def render(self, E: np.ndarray, index: int, static_E: np.ndarray | None = None) -> np.ndarray:
        """uint8 (H, W, 3) frame for irradiance grid E. If ``static_E`` is given, E is the change
        from it (cheaper and more exact: the static image is already computed)."""
        lin = self.upsample(E)
        lin *= self.gain_k
        if static_E is not None:
            lin += self.static
        dx, dy = self.shifts[index]
        if (dx or dy) and self.p.shake_exact:
            lin = _warp_chw(lin, dx, dy)
        elif dx or dy:
            lin += np.float32(dx) * self.grad_x + np.float32(dy) * self.grad_y
        noise = self.rng.standard_normal(lin.shape, dtype=np.float32)
        noise *= self.sigma
        lin *= np.float32(self.gains[index] * self.LUT_STEP)
        if self.row_gains is not None:
            lin *= self.row_gains[index][:, None, None]
        lin += noise * np.float32(self.LUT_STEP)
        if self.awb is not None:  # the ISP's gains apply to what the sensor read, noise and all
            lin *= self.awb[index].astype(np.float32)[None, :, None]
        if self.tnr is not None:
            lin = self.tnr(lin)
        lin += np.float32(0.5)
        np.clip(lin, 0, len(self.lut) - 1, out=lin)
        return np.ascontiguousarray(self.lut[lin.astype(np.uint16)].transpose(0, 2, 1))
