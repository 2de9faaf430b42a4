"""A path-traced data set says, before it starts, whether its clean scenes are cached or will be path traced here."""

import numpy as np

from wallcli.datagen import ptcache


def test_a_recipe_not_in_the_cache_is_announced_and_the_cached_one_is_not(tmp_path, monkeypatch, capsys):
    from wallcli.cli.simulate import _say_uncached

    monkeypatch.setenv("WALLCLI_CACHE", str(tmp_path / "cache"))
    rec = ptcache.recipe(seed=7, grid=(4, 6), spp=16)
    meta = {"recipe": rec, "format": ptcache.FORMAT, "version": ptcache.VERSION}
    arrays = {"E0": np.ones((4, 6, 3), np.float32), "dE": np.zeros((2, 4, 6, 3), np.float32),
              "alone": np.zeros((0, 0, 6, 3), np.float32), "alone_t": np.zeros(0, np.int32),
              "wall_albedo": np.full(3, 0.5, np.float32)}
    ptcache.store_scene(ptcache.scene_file(rec, 0), arrays, meta)
    # 8 windows, 4 a scene, 2 draws a clean scene: clean scene 0 only, which is cached
    _say_uncached(8, "count", 7, "wide", "transfer", (4, 6), 16, 4, 2)
    err = capsys.readouterr().err
    assert "all 1 clean path-traced scenes are cached" in err and "Warning" not in err
    # another grid is another recipe: nothing cached, and the cached recipe of the seed is named
    _say_uncached(8, "count", 7, "wide", "transfer", (8, 8), 16, 4, 2)
    err = " ".join(capsys.readouterr().err.split())
    assert "Warning: 1 of the 1 clean path-traced scenes are not in the cache" in err
    assert ptcache.folder(rec).name in err
    # twice the windows need a second clean scene, which is not there
    _say_uncached(16, "count", 7, "wide", "transfer", (4, 6), 16, 4, 2)
    assert "1 of the 2" in " ".join(capsys.readouterr().err.split())
