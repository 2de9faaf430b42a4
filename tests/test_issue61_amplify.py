"""Issue 61.7: amplify's right half was coloured blobs with clipped whites, and an empty room's
noise was amplified without a word. The display is the luminance change in grey, bent smoothly
instead of clipped, and a video with nothing above the noise says so."""
from __future__ import annotations

import json

import numpy as np

from clips import write_clip
from wallcli.signal.amplify import Amplifier


def _display(amp, s):
    amp.push_signal(0.0, np.zeros_like(s))
    return amp.push_signal(1 / 30, s)[0][1]


def test_a_strong_shade_is_bent_not_clipped():
    amp = Amplifier(gain=100.0, smooth_seconds=0.0)
    s = np.array([[[-5.0] * 3, [-4.0] * 3, [0.01] * 3, [4.0] * 3, [5.0] * 3]])  # +-5 code values: 4x full scale
    d = _display(amp, s)[0, :, 0]
    assert np.all((d > 1.0) & (d < 255.0))  # was 128 + 100 x 5 = 628, cut flat to 255
    assert d[0] < d[1] < d[2] < d[3] < d[4]  # the shade keeps its shape beyond the range
    assert abs(d[2] - (128 + 100 * 0.01)) < 0.01  # linear, slope = gain, where a shade is faint


def test_the_display_is_the_luminance_change_in_grey_unless_colour():
    s = np.array([[[1.0, 0.0, -1.0]]])  # chroma, no luminance to speak of
    grey = _display(Amplifier(gain=20.0), s)[0, 0]
    assert grey[0] == grey[1] == grey[2]
    assert abs(grey[0] - 128 - 20 * (0.2126 - 0.0722)) < 0.05
    colour = _display(Amplifier(gain=20.0, colour=True), s)[0, 0]
    assert colour[0] > 128 > colour[2]


def _wall(tmp_path, name, shade):
    rng = np.random.default_rng(5)

    def frame(i):
        x = np.arange(64)[None, :]
        centre = 32 + 20 * np.sin(2 * np.pi * 0.3 * i / 30)
        img = 120.0 - shade * np.exp(-0.5 * ((x - centre) / 10.0) ** 2) + 2.0 * rng.standard_normal((48, 64))
        return np.repeat(img[:, :, None], 3, axis=2)

    return write_clip(tmp_path / name, frame, 150)


def test_nothing_above_the_noise_is_said(tmp_path, run_cli):
    empty = _wall(tmp_path, "empty.mp4", 0.0)
    code, out, err = run_cli("amplify", empty, tmp_path / "e.mp4", "--json")
    assert code == 0, err
    said = " ".join(err.split())
    assert "nothing stands above the noise" in said and said.index("column SNR") < said.index("nothing stands")
    obj = json.loads(out)
    assert obj["verdict"]["signal"] is False and obj["display"] == "luminance" and "column_snr_db" in obj
    shade = _wall(tmp_path, "shade.mp4", 4.0)
    code, out, err = run_cli("amplify", shade, tmp_path / "s.mp4", "--json")
    assert code == 0, err
    assert "nothing stands above the noise" not in err and json.loads(out)["verdict"]["signal"] is True
