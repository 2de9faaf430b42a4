"""Training-time augmentation of raw windows, before ``normalize_window``.

Each transform is something a real recording can do to a space-time plot without changing
its label, which is how a model trained on the simulator learns to ignore the room:

- space mirror (p 0.5): the hidden scene seen left-right flipped.  Horizontal plot only:
  mirroring the vertical plot would swap floor and ceiling, and crouching/jumping depend on it.
- time reversal (p 0.5, all plots together): walking right-to-left is still walking; a crouch
  reversed is standing up from a crouch, still the crouching activity; waving and jumping
  are symmetric.
- colour-channel permutation (p 0.5, same permutation for all plots): rooms and clothes of
  any colour.
- per-channel gain jitter (log-normal, sigma 0.25): white balance and light colour; a global
  gain would be removed by the window normalisation anyway.
- added white noise (p 0.5, std a log-uniform 2-50 % of the window's RMS): other cameras,
  darker rooms, stronger compression.
- slow illumination drift (p 0.3): a ramp common to all positions (daylight, auto exposure),
  up to half the window's RMS.
- a change of the whole room's light (p 0.4, needs the windows' level offsets): every raw level
  multiplied by 1 + g(t), g a sinusoid of 0.1-6 Hz (mains flicker aliased to the frame rate,
  a flickering lamp), a slow drift or an exposure step, of 0.2-3x the window's RMS, the same for
  all plots. Rooms do this with nobody in them; the label stays.

Count only, optional (``--superpose P``, off by default):

- superposition: a window becomes itself plus another window of the batch (labels add, never
  above 2 people). Light transport is linear, and a person changes the wall's light by well under
  1 %, so two people's changes add; the sum of a one-person window from one room and a
  one-person window from another is what two people look like to the plot, noise included
  (each part brings its own, so a sum's noise level says nothing about its label: 0 + 0, 0 + 1
  and 0 + 2 sums exist too). The partner is scaled so its RMS is 0.5-2x the window's (log-
  uniform): neither part drowns the other, as both movers of a training window are visible.
  It multiplies the two-person configurations the net sees at no simulation cost; real
  two-person scenes still teach what one room with two people looks like.

Augmentations draw from a generator seeded by (seed, epoch, batch), so resumed runs repeat them.
"""
from __future__ import annotations

import numpy as np

DESCRIPTION = [
    "space mirror, horizontal plot only (p=0.5)",
    "time reversal, all plots together (p=0.5)",
    "colour-channel permutation, same for all plots (p=0.5)",
    "per-channel gain jitter, log-normal sigma 0.25",
    "added white noise, std log-uniform 2-50% of window RMS (p=0.5)",
    "slow illumination ramp common to all positions, up to 0.5x window RMS (p=0.3)",
    "whole-room light change x(1+g(t)) on the raw levels: sinusoid 0.1-6 Hz, drift or step, 0.2-3x window RMS (p=0.4)",
]


SUPERPOSE_DESCRIPTION = ("superposition with another window of the batch (count: labels add, at most 2), "
                         "partner scaled to 0.5-2x the window's RMS, log-uniform (p={p:g})")


def window_rms(x: np.ndarray) -> np.ndarray:
    """RMS of each window's own variation (B, bins, T, C) -> (B,): the per-bin mean over time is
    removed first, as it is irrelevant after normalisation."""
    centred = x - x.mean(axis=2, keepdims=True)
    return np.sqrt((centred.astype(np.float64) ** 2).mean(axis=(1, 2, 3))) + 1e-12


def superpose(batch: dict[str, np.ndarray], inputs: list[str], rng: np.random.Generator, p: float,
              max_label: int = 2) -> dict[str, np.ndarray]:
    """Replace a fraction ``p`` of windows by their sum with a partner of the batch (count labels add).

    Partners come from the unmodified batch and keep label sums <= ``max_label``; a partner is
    mirrored in space (horizontal plot) and reversed in time independently, half the time each.
    """
    y = np.asarray(batch["label"])
    out = dict(batch)
    if p <= 0 or len(y) < 2:
        return out
    arrays = {n: batch[n].astype(np.float32, copy=True) for n in inputs}
    labels = y.copy()
    rms = window_rms(batch[inputs[0]])
    for i in np.flatnonzero(rng.random(len(y)) < p):
        ok = np.flatnonzero((y + y[i] <= max_label) & (np.arange(len(y)) != i))
        if not len(ok):
            continue
        j = int(rng.choice(ok))
        ratio = float(np.exp(rng.uniform(np.log(0.5), np.log(2.0))))
        flip, rev = rng.random() < 0.5, rng.random() < 0.5
        scale = ratio * rms[i] / rms[j]
        for n in inputs:
            part = batch[n][j].astype(np.float32)
            if flip and n == "horizontal":
                part = part[::-1]
            if rev:
                part = part[:, ::-1]
            arrays[n][i] += np.float32(scale) * part
        labels[i] = y[i] + y[j]
    out.update(arrays)
    out["label"] = labels
    return out


def augment(batch: dict[str, np.ndarray], inputs: list[str], rng: np.random.Generator) -> dict[str, np.ndarray]:
    """Augment raw windows (B, bins, T, 3) per input name; returns new arrays, labels untouched."""
    out = dict(batch)
    first = batch[inputs[0]]
    b, _, t, c = first.shape
    mirror = rng.random(b) < 0.5
    reverse = rng.random(b) < 0.5
    permute = rng.random(b) < 0.5
    perms = np.array([rng.permutation(c) if p else np.arange(c) for p in permute])
    gains = np.exp(rng.normal(0.0, 0.25, size=(b, 1, 1, c))).astype(np.float32)
    noisy = rng.random(b) < 0.5
    noise_rel = np.exp(rng.uniform(np.log(0.02), np.log(0.5), size=b)) * noisy
    drifting = rng.random(b) < 0.3
    drift_rel = rng.uniform(-0.5, 0.5, size=b) * drifting
    ramp = np.linspace(-1.0, 1.0, t, dtype=np.float32)
    for name in inputs:
        x = batch[name].astype(np.float32, copy=True)
        key = {"horizontal": "h_offset", "vertical": "v_offset"}[name]
        off = batch[key].astype(np.float32, copy=True) if key in batch else None
        if name == "horizontal":
            x[mirror] = x[mirror, ::-1]
            if off is not None:
                off[mirror] = off[mirror, ::-1]
        x[reverse] = x[reverse, :, ::-1]
        x = np.take_along_axis(x, perms[:, None, None, :], axis=3)
        x *= gains
        if off is not None:  # the level moves with its window: same mirror, colours and gains
            off = np.take_along_axis(off, perms[:, None, :], axis=2) * gains[:, 0]
            out[key] = off
        rms = window_rms(x)
        x += (rng.standard_normal(x.shape, dtype=np.float32)
              * (noise_rel * rms).astype(np.float32)[:, None, None, None])
        x += (drift_rel * rms).astype(np.float32)[:, None, None, None] * ramp[None, None, :, None]
        out[name] = x
    if all(OFFSET_KEYS[n] in out for n in inputs):
        _light_change(out, inputs, rng)
    return out


OFFSET_KEYS = {"horizontal": "h_offset", "vertical": "v_offset"}


def _light_change(out: dict, inputs: list[str], rng: np.random.Generator, p: float = 0.4) -> None:
    """In place: raw levels (window + offset) of a share ``p`` of windows times 1 + g(t)."""
    first = out[inputs[0]]
    b, _, t, _ = first.shape
    sel = rng.random(b) < p
    if not sel.any():
        return
    tt = np.arange(t, dtype=np.float64) / 30.0
    g = np.zeros((b, t))
    kind = rng.integers(0, 3, b)
    for i in np.flatnonzero(sel):
        if kind[i] == 0:
            g[i] = np.sin(2 * np.pi * np.exp(rng.uniform(np.log(0.1), np.log(6.0))) * tt + rng.uniform(0, 2 * np.pi))
        elif kind[i] == 1:
            g[i] = sum(np.sin(2 * np.pi * rng.uniform(0.02, 0.3) * tt + rng.uniform(0, 2 * np.pi)) for _ in range(2)) / 2
        else:
            g[i] = np.tanh((tt - rng.uniform(0.1, 0.9) * tt[-1]) / rng.uniform(0.05, 0.5))
        g[i] -= g[i].mean()
    # amplitude relative to the window's own variation, measured on the first plot
    level = np.abs(out[OFFSET_KEYS[inputs[0]]] + first.mean(axis=2)).mean(axis=(1, 2)) + 1e-9
    amp = np.exp(rng.uniform(np.log(0.2), np.log(3.0), b)) * window_rms(first) / level / (np.abs(g).max(axis=1) + 1e-9)
    g *= (amp * sel)[:, None]
    for name in inputs:
        raw = out[name] + out[OFFSET_KEYS[name]][:, :, None, :]
        out[name] = (out[name] + raw * g[:, None, :, None]).astype(np.float32)
