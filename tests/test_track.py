"""wallcli track: streaks in a plot made here become tracks that follow them, and the command's outputs."""
from __future__ import annotations

import csv
import io
import json

import numpy as np
import pytest

from wallcli.signal import track as tr

FPS = 30.0


def _plot(seconds, paths, *, bins=64, depth=0.05, noise=0.01, width=3.0, seed=0, flicker=0.0):
    """(T, bins, 3) rows: a noisy wall with a dark Gaussian shade at each path(t) (fraction of the width)."""
    rng = np.random.default_rng(seed)
    t = np.arange(int(seconds * FPS)) / FPS
    b = np.arange(bins) + 0.5
    rows = np.full((t.size, bins), 100.0) + rng.normal(0, noise, (t.size, bins))
    for p in paths:
        x = np.array([p(s) for s in t])
        rows -= depth * np.exp(-0.5 * ((b[None, :] - x[:, None] * bins) / width) ** 2)
    rows *= 1.0 + flicker * np.sin(2 * np.pi * 3.0 * t)[:, None]  # the whole wall's light
    return np.repeat(rows[:, :, None], 3, axis=2).astype(np.float32), t


def _bounce(period, lo=0.1, hi=0.9, phase=0.0):
    def f(s):
        u = ((s / period + phase) % 1.0) * 2
        return lo + (hi - lo) * (u if u <= 1 else 2 - u)
    return f


def test_one_walker_is_one_track_that_follows_the_shade():
    walk = _bounce(8.0)
    rows, t = _plot(12, [walk])
    tracks = tr.track_rows(rows, t, FPS)
    assert len(tracks) == 1
    x, ts = np.array(tracks[0].x), np.array(tracks[0].t)
    truth = np.array([walk(s) for s in ts])
    assert tracks[0].duration > 10
    assert np.corrcoef(x, truth)[0, 1] > 0.98
    assert np.median(np.abs(x - truth)) < 0.03
    assert all(s >= min(g for _, g in tr.GEOMETRY_BY_STRENGTH) for s in tracks[0].sigma)
    assert tr.simultaneous(tracks)["seconds"] == 0.0


def test_two_walkers_apart_are_two_tracks_at_once():
    rows, t = _plot(12, [_bounce(4.0, 0.05, 0.4), _bounce(5.0, 0.6, 0.95, phase=0.3)])
    tracks = tr.track_rows(rows, t, FPS)
    assert len(tracks) == 2
    assert sorted(round(float(np.median(k.x)), 1) for k in tracks) == [0.2, 0.8]
    assert tr.simultaneous(tracks)["seconds"] >= 10


def test_an_empty_wall_and_a_light_change_have_no_tracks():
    for flicker in (0.0, 0.02):
        rows, t = _plot(12, [], flicker=flicker, seed=3)
        assert tr.track_rows(rows, t, FPS) == []


def test_a_faint_shade_under_the_noise_is_not_tracked_but_a_plain_one_is():
    walk = _bounce(6.0)
    faint, t = _plot(12, [walk], depth=0.002, noise=0.05, seed=4)
    plain, _ = _plot(12, [walk], depth=0.1, noise=0.05, seed=4)
    assert tr.track_rows(faint, t, FPS) == []
    assert len(tr.track_rows(plain, t, FPS)) == 1


def test_a_long_stream_is_tracked_in_chunks_and_linked_across_them():
    walk = _bounce(10.0)
    rows, t = _plot(60, [walk], seed=5)
    b = tr.TrackBuilder(FPS)
    held = 0
    for ti, r in zip(t, rows):
        b.push(ti, r)
        held = max(held, len(b._rows))
    tracks = b.finish()
    assert held <= b.chunk  # memory: one chunk of rows, whatever the length
    assert len(tracks) == 1 and tracks[0].duration > 55
    ts = np.array(tracks[0].t)
    assert np.all(np.diff(ts) > 0)  # each time once, in order, across the overlaps
    assert np.median(np.abs(np.array(tracks[0].x) - [walk(s) for s in ts])) < 0.03


def test_a_person_in_place_is_a_track_that_stays():
    rows, t = _plot(12, [lambda s: 0.6], depth=0.0, seed=6)
    b = np.arange(64) + 0.5
    rows = rows - (0.08 * (0.5 + 0.5 * np.sin(2 * np.pi * 1.5 * t))[:, None]
                   * np.exp(-0.5 * ((b - 0.6 * 64) / 3.0) ** 2))[:, :, None]
    tracks = tr.track_rows(rows.astype(np.float32), t, FPS)
    assert tracks and abs(np.median(tracks[0].x) - 0.6) < 0.05
    assert not tracks[0].as_dict()["moving"]


def test_as_dict_gives_metres_from_the_view_centre():
    rows, t = _plot(12, [_bounce(6.0)], seed=7)
    d = tr.track_rows(rows, t, FPS)[0].as_dict(view_width=2.0)
    s = d["samples"][len(d["samples"]) // 2]
    assert s["x_m"] == pytest.approx((s["x"] - 0.5) * 2.0, abs=1e-3)
    assert {"id", "samples", "start", "end"} <= set(d)


# --- the command, on a video made here ---------------------------------------------------------

def _wall(path, seconds=8.0, walker=True, size=(96, 72)):
    from clips import write_clip

    w, h = size
    xs = np.arange(w) + 0.5
    rng = np.random.default_rng(1)
    walk = _bounce(6.0, 0.15, 0.85)

    def frame(i):
        img = np.full((h, w), 120.0)
        if walker:
            img -= 1.5 * np.exp(-0.5 * ((xs - walk(i / 30.0) * w) / 8.0) ** 2)[None, :]  # 1.2 % of the light
        img += rng.normal(0, 1.0, img.shape)
        return np.repeat(img[:, :, None], 3, axis=2)

    return write_clip(path, frame, int(seconds * 30), options={"crf": "0", "preset": "ultrafast"},
                      pix_fmt="yuv444p"), walk


@pytest.fixture(scope="module")
def walker_clip(tmp_path_factory):
    from wallcli.cli.app import main

    clip = tmp_path_factory.mktemp("track") / "walker.mp4"
    with pytest.raises(SystemExit) as exc:
        main(["simulate", "-o", str(clip), "--people", "1", "--activity", "walking", "--seed", "5", "--size", "96x72",
              "--duration", "10.5"])
    assert exc.value.code in (0, None)
    return clip


def test_cli_json_csv_and_png(walker_clip, run_cli, tmp_path):
    clip = walker_clip
    png, csv_path = tmp_path / "t.png", tmp_path / "t.csv"
    code, out, err = run_cli("track", str(clip), "--json", "--png", str(png), "--csv", str(csv_path),
                             "--view-width", "2.5")
    assert code == 0, err
    res = json.loads(out)
    assert res["task"] == "track" and res["view"]["usable"] and res["reason"] is None
    longest = max(res["tracks"], key=lambda k: k["end"] - k["start"])
    assert longest["end"] - longest["start"] > 3 and longest["moving"]
    assert all("x_m" in s and s["sigma"] > 0 for s in longest["samples"])
    assert png.stat().st_size > 10_000 and png.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    rows = list(csv.DictReader(io.StringIO(csv_path.read_text())))
    assert len(rows) == sum(len(k["samples"]) for k in res["tracks"])
    assert set(rows[0]) == {"track", "t", "x", "sigma", "x_m"}
    # an existing output is not overwritten without --force
    code, out, err = run_cli("track", str(clip), "--csv", str(csv_path))
    assert code == 1 and "exists" in err and out == ""
    code, out, err = run_cli("track", str(clip), "--csv", "-")
    assert code == 0 and out.startswith("track,t,x,sigma\n")


def test_cli_empty_wall_says_nobody_moves(tmp_path, run_cli):
    clip, _ = _wall(tmp_path / "empty.mp4", walker=False)
    code, out, err = run_cli("track", str(clip), "--json")
    assert code == 0, err
    res = json.loads(out)
    assert res["tracks"] == [] and "nobody moves" in res["reason"]
    code, out, err = run_cli("track", str(clip))
    assert code == 0 and "no tracks" in " ".join(err.split())


def test_cli_reads_a_plot_file_and_refuses_bad_input(walker_clip, run_cli, tmp_path):
    clip = walker_clip
    npz = tmp_path / "p.npz"
    assert run_cli("stplot", str(clip), "-o", str(npz))[0] == 0
    code, out, err = run_cli("track", str(npz), "--json")
    assert code == 0, err
    assert json.loads(out)["tracks"]
    short, _ = _wall(tmp_path / "short.mp4", seconds=1.0)
    code, out, err = run_cli("track", str(short))
    assert code == 1 and "too short" in err and len(err.strip().splitlines()) == 1
    code, out, err = run_cli("track", str(tmp_path / "missing.mp4"))
    assert code == 1 and err.startswith("Error:")
    code, out, err = run_cli("track", str(clip), "--json", "--csv", "-")
    assert code == 2


def test_follow_prints_samples_as_chunks_complete_and_ends_with_the_whole_result(tmp_path, run_cli):
    from wallcli.cli.app import main

    clip = tmp_path / "long.mp4"
    with pytest.raises(SystemExit):
        main(["simulate", "-o", str(clip), "--people", "1", "--activity", "walking", "--seed", "8", "--size", "96x72",
              "--duration", "30"])
    code, out, err = run_cli("track", str(clip), "--follow", "--idle-timeout", "0")
    assert code == 0, err
    lines = [json.loads(x) for x in out.splitlines()]
    assert lines[-1]["task"] == "track"
    updates = lines[:-1]
    assert len(updates) >= 2  # a 30 s clip is read in more than one chunk
    code, out, _ = run_cli("track", str(clip), "--json")
    whole = json.loads(out)
    assert lines[-1]["tracks"] == whole["tracks"]
    # the lines, joined per track, are the whole result's samples, each once
    for k in whole["tracks"]:
        joined = [s for u in updates if u["id"] == k["id"] for s in u["samples"]]
        assert joined == k["samples"]
    code, out, err = run_cli("track", str(clip), "--follow", "--png", str(tmp_path / "x.png"))
    assert code == 2 and out == ""


def test_a_region_narrower_than_the_bins_reads_no_infinite_darkness(walker_clip, run_cli, tmp_path):
    # a 4x4 region repeats each pixel over 16 bins: nothing changes bin by bin, so the noise is read
    # on the map's own spread (it once read 1e-12, and every wobble was a track of strength 2e11)
    code, out, err = run_cli("track", str(walker_clip), "--roi", "0,0,4,4", "--json")
    assert code == 0, err
    assert all(k["strength"] < 1e3 for k in json.loads(out)["tracks"])


def test_a_plot_file_under_two_seconds_is_too_short(tmp_path, run_cli):
    from clips import write_plot

    short = write_plot(tmp_path / "short.npz", seconds=1.0)
    code, out, err = run_cli("track", str(short))
    assert code == 1 and "too short" in err and out == ""
