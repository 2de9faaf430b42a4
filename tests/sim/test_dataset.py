"""Dataset mode: shard format of the spec, determinism for a seed, resumability, class labels."""

import json

import numpy as np

from wallcli.datagen.clips import scene_plan
from wallcli.datagen.dataset import build_dataset
from wallcli.io.arrays import load_npz

FAST = {"fps": 15.0, "width": 64, "height": 48, "codec": "ffv1"}


def _build(path, **kw):
    args = dict(seed=3, jobs=1, windows_per_scene=2, shard_scenes=1, grid=(6, 8), camera_overrides=FAST)
    args.update(kw)
    return build_dataset(path, 3, "count", **args)


def test_dataset_shards_are_deterministic_and_resumable(tmp_path):
    m = _build(tmp_path / "a")
    assert m["format"] == "wallcli.dataset" and m["classes"] == [0, 1, 2] and m["window"] == 256 and m["bins"] == 64
    assert [s["n"] for s in m["shards"]] == [2, 1]
    arrays, meta = load_npz(tmp_path / "a" / "shard-00000.npz", kind="wallcli.dataset-shard")
    assert arrays["horizontal"].shape == (2, 64, 256, 3) and arrays["horizontal"].dtype == np.float32
    assert arrays["vertical"].shape == (2, 64, 256, 3)
    assert arrays["label"].dtype == np.int64 and np.array_equal(arrays["label"], arrays["people"])
    assert len(meta["scenes"]) == 2 and meta["task"] == "count"
    # windows are mean-removed stplot rows in code units, not normalised and not all zero
    assert 0 < np.abs(arrays["horizontal"]).mean() < 20
    # resume: remove one shard, the other must be left untouched
    shard1 = tmp_path / "a" / "shard-00001.npz"
    shard1.unlink()
    before = (tmp_path / "a" / "shard-00000.npz").stat().st_mtime_ns
    _build(tmp_path / "a")
    assert (tmp_path / "a" / "shard-00000.npz").stat().st_mtime_ns == before and shard1.exists()
    assert json.loads((tmp_path / "a" / "dataset.json").read_text())["complete"] is True
    # determinism: a second folder gets identical arrays
    _build(tmp_path / "b", shard_scenes=1)
    a1, _ = load_npz(shard1)
    b1, _ = load_npz(tmp_path / "b" / "shard-00001.npz")
    for k in a1:
        np.testing.assert_array_equal(a1[k], b1[k])


def test_scene_plans_cover_every_class_and_mixed_pairs():
    rng = np.random.default_rng(0)
    count = [scene_plan(rng, "count") for _ in range(600)]
    assert {lab for _, _, lab in count} == {0, 1, 2}
    # count counts movers: every moving activity appears, nobody stands still, label == people
    assert {a for n, acts, _ in count if n == 1 for a in acts} == {"walking", "crouching", "waving", "jumping"}
    assert all(lab == n == len(acts) and "none" not in acts for n, acts, lab in count)
    assert any(n == 2 and len(set(acts)) == 2 for n, acts, _ in count)
    act = [scene_plan(rng, "activity") for _ in range(300)]
    assert {lab for _, _, lab in act} == {0, 1, 2, 3, 4}
    assert {n for n, _, lab in act if lab == 0} == {0, 1}


def test_window_snr_measures_the_signal_left_in_the_recorded_plot():
    from types import SimpleNamespace

    from wallcli.datagen.clips import WINDOW, _window_snr_db
    from wallcli.sim.camera import interp_matrix

    rng = np.random.default_rng(0)
    T, gx = 400, 32
    t = np.arange(T) / 30.0
    ramp = np.linspace(0.5, 1.5, gx)[:, None, None] * np.ones((1, 1, 3))
    a = np.sin(2 * np.pi * 0.4 * t)[None, :, None] * ramp * 1e-3  # person A
    b = np.cos(2 * np.pi * 0.13 * t)[None, :, None] * ramp[::-1] * 1e-5  # person B: 40 dB fainter
    cam = SimpleNamespace(fps=30.0)
    up = interp_matrix(64, gx)
    starts = [0, T - WINDOW]

    def record(clean, sigma):
        sig = 50.0 * np.einsum("bg,gtc->btc", up, clean)  # gain 50 codes per unit change
        return (sig + rng.standard_normal(sig.shape) * sigma).astype(np.float32), sig

    one = SimpleNamespace(clean_profiles=[(a[:, i], None) for i in range(T)])
    h, sig = record(a, 0.02)
    want = 10 * np.log10(np.mean((sig - sig.mean(1, keepdims=True))[:, :WINDOW] ** 2) / 0.02**2)
    both, weakest = _window_snr_db(one, cam, h, t, starts)
    assert np.allclose(both, want, atol=0.3) and np.allclose(weakest, both)
    # a codec that erased the signal (frames repeated: no change at all) leaves nothing visible
    flat = (rng.standard_normal(h.shape) * 1e-4).astype(np.float32)
    assert (_window_snr_db(one, cam, flat, t, starts)[0] < -20).all()
    # two people, one of them far under the noise: together visible, the weakest is not
    two = SimpleNamespace(clean_profiles=[((a + b)[:, i], None, [a[:, i], b[:, i]]) for i in range(T)])
    h2, _ = record(a + b, 0.02)
    both, weakest = _window_snr_db(two, cam, h2, t, starts)
    assert (both > 3).all() and (weakest < -20).all()
