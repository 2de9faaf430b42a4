"""wallcli track, issue 61.4: sigma that says how far the person is, tracks on the view's edge seen
in the picture, and help that says what a person standing still gives."""
from __future__ import annotations

import numpy as np

from test_track import FPS, _bounce, _plot
from wallcli.signal import track as tr


def _walker(depth, seed=21):
    rows, t = _plot(12, [_bounce(8.0)], depth=depth, noise=0.01, seed=seed)
    (k,) = tr.track_rows(rows, t, FPS)
    return k


def test_sigma_is_the_shade_width_and_the_geometry_of_a_shade_that_strong():
    faint, strong = _walker(0.015), _walker(0.2)
    assert np.median(faint.strength) < 15 < 60 < np.median(strong.strength)
    # a faint shade falls near the person on the recordings, a strong one far: sigma follows
    assert np.median(faint.sigma) < 0.42 < 0.5 < np.median(strong.sigma)
    for k in (faint, strong):
        d = k.as_dict()["samples"]
        assert all(0 < s["sigma_shade"] < s["sigma"] for s in d)
        for s, st in zip(d, k.strength):
            geo = float(tr.geometry_sigma(st))
            assert s["sigma"] ** 2 == __import__("pytest").approx(s["sigma_shade"] ** 2 + geo ** 2, abs=2e-3)


def test_a_track_on_the_views_edge_is_drawn_inside_the_picture(tmp_path, monkeypatch):
    from types import SimpleNamespace

    import wallcli.plots.track as pt

    seen = {}
    monkeypatch.setattr(pt, "save_figure", lambda fig, path, force=False: seen.setdefault("ax", fig.axes[0]))
    plot = SimpleNamespace(horizontal=np.zeros((64, 90, 3), np.float32), time=np.arange(90) / 30.0)
    samples = [{"t": i / 10, "x": 0.9922, "sigma": 0.4, "sigma_shade": 0.05} for i in range(30)]
    pt.save_track_png(tmp_path / "t.png", plot, {"input": "c", "tracks": [{"id": 0, "samples": samples}]})
    ax = seen["ax"]
    hi, lo = ax.get_ylim()
    assert hi > 1.0 and lo < 0.0  # the frame does not cover a line at x = 0 or 1
    (line,) = ax.get_lines()
    assert not line.get_clip_on()


def test_help_says_what_standing_still_gives_and_what_geometry_sigma_is(run_cli):
    code, out, err = run_cli("track", "--help")
    text = " ".join(out.split())
    assert code == 0
    assert "standing still" in text and "geometry_sigma" in text and "sigma_shade" in text
