"""The path-traced clean-scene cache (wallcli/datagen/ptcache.py): render once, re-noise many times."""

import numpy as np
import pytest

pytest.importorskip("mitsuba")

from wallcli.datagen import ptcache  # noqa: E402


@pytest.fixture
def cache(tmp_path, monkeypatch):
    monkeypatch.setenv("WALLCLI_CACHE", str(tmp_path / "cache"))
    return tmp_path / "cache"


def _rec(**kw):
    # a tiny grid and few samples: the plumbing, not the light transport (tests/sim/test_pathtrace.py)
    # and the shortest clip that holds a window (8.53 s at 30 fps, resampled from 24-30 fps)
    return ptcache.recipe(seed=3, grid=(4, 6), spp=4, duration=8.8, **kw)


def _index_with_people(rec, n):
    for i in range(50):
        cfg, _ = ptcache._config(rec, i)
        if cfg.people == n:
            return i
    raise AssertionError(f"no scene with {n} people in the first 50")


def test_the_cache_lives_outside_the_work_tree_and_is_overridable(cache, monkeypatch):
    assert ptcache.cache_root() == cache / "pt"
    monkeypatch.delenv("WALLCLI_CACHE")
    assert ptcache.cache_root().parts[-3:] == (".cache", "wallcli", "pt")


def test_a_scene_is_rendered_once_then_read_back(cache):
    rec = _rec()
    i = _index_with_people(rec, 1)
    a, m = ptcache.ensure_scene(rec, i)
    path = ptcache.scene_file(rec, i)
    assert path.is_file() and path.is_relative_to(cache)
    stamp = path.stat().st_mtime_ns
    b, m2 = ptcache.ensure_scene(rec, i)
    assert path.stat().st_mtime_ns == stamp  # not rendered again
    assert np.array_equal(a["dE"], b["dE"]) and m2["index"] == i
    assert a["dE"].dtype == np.float32 and a["dE"].shape[1:] == (4, 6, 3) and len(a["dE"]) == m["frames"]
    assert m["fps"] in ptcache.RATES and np.any(a["dE"])
    # another recipe is another folder: its scenes never mix with these
    assert ptcache.folder(_rec(placement="wide")) != ptcache.folder(rec)


def test_a_damaged_file_is_rendered_again(cache):
    rec = _rec()
    i = _index_with_people(rec, 0)
    ptcache.ensure_scene(rec, i)
    path = ptcache.scene_file(rec, i)
    path.write_bytes(b"not an npz")
    a, _ = ptcache.ensure_scene(rec, i)
    assert ptcache.load_scene(path) is not None and not np.any(a["dE"])  # an empty room changes nothing


def test_each_draw_is_a_new_camera_over_the_same_clean_scene(cache):
    rec = _rec()
    i = _index_with_people(rec, 2)
    a, m = ptcache.ensure_scene(rec, i)
    assert a["alone"].shape[0] == 2  # each person's own change, for the weakest mover's SNR
    w0 = ptcache.compose_windows(a, m, 0, windows=1)
    w1 = ptcache.compose_windows(a, m, 1, windows=1)
    again = ptcache.compose_windows(a, m, 0, windows=1)
    assert w0["horizontal"].shape == (1, 64, 256, 3) and w0["horizontal"].dtype == np.float32
    assert (w0["label"] == 2).all() and (w0["people"] == 2).all()
    assert np.array_equal(w0["horizontal"], again["horizontal"])  # a draw is decided by its number
    assert not np.allclose(w0["horizontal"], w1["horizontal"])
    assert w0["scenes"][0]["camera"] != w1["scenes"][0]["camera"]
    assert w0["scenes"][0]["world"] == "pt" and np.isfinite(w0["snr_db_weakest"]).all()
