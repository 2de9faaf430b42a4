import numpy as np
import pytest

torch = pytest.importorskip("torch")

from wallcli.errors import WallcliError  # noqa: E402
from wallcli.train.augment import augment  # noqa: E402
from wallcli.train.data import ShardDataset, split_validation  # noqa: E402
from wallcli.train.loop import ANNEAL_FLOOR, TrainConfig, learning_rate, train  # noqa: E402


def test_dataset_plan_covers_indices_once(make_dataset):
    ds = ShardDataset(make_dataset("count", 50, shards=3), "count", buffer_windows=20)
    idx = np.arange(3, 50)
    batches = ds.plan(idx, 8, np.random.default_rng(1))
    flat = np.concatenate(batches)
    assert sorted(flat.tolist()) == idx.tolist()  # 47 = 5*8 + 7: last batch kept (size >= 2)
    again = ds.plan(idx, 8, np.random.default_rng(1))
    assert all(np.array_equal(a, b) for a, b in zip(batches, again))
    b = ds.gather(np.array([49, 0, 20]))
    assert b["horizontal"].shape == (3, 64, 256, 3) and b["label"].shape == (3,)


def test_dataset_rejects_wrong_task_and_missing_manifest(make_dataset, tmp_path):
    root = make_dataset("count", 8)
    with pytest.raises(WallcliError, match="count"):
        ShardDataset(root, "activity")
    with pytest.raises(WallcliError, match="dataset.json"):
        ShardDataset(tmp_path, "count")


def test_split_validation_is_disjoint_and_seeded():
    tr, va = split_validation(100, 0.1, 3)
    assert len(va) == 10 and not set(tr) & set(va) and len(tr) + len(va) == 100
    assert np.array_equal(va, split_validation(100, 0.1, 3)[1])


def test_augment_preserves_shapes_and_is_seeded():
    rng = np.random.default_rng(0)
    b = {"horizontal": rng.normal(size=(6, 64, 256, 3)).astype(np.float32),
         "vertical": rng.normal(size=(6, 64, 256, 3)).astype(np.float32), "label": np.arange(6)}
    a1 = augment(b, ["horizontal", "vertical"], np.random.default_rng(5))
    a2 = augment(b, ["horizontal", "vertical"], np.random.default_rng(5))
    assert a1["horizontal"].shape == b["horizontal"].shape and a1["horizontal"].dtype == np.float32
    assert np.array_equal(a1["vertical"], a2["vertical"])
    assert not np.array_equal(a1["horizontal"], b["horizontal"])
    assert np.array_equal(a1["label"], b["label"])


def _cfg(tmp_path, data, **kw):
    base = dict(task="count", data=data, out=tmp_path / "m.onnx", epochs=2, batch_size=16, threads=2, seed=0,
                val_fraction=0.125)
    base.update(kw)
    return TrainConfig(**base)


@pytest.mark.slow
def test_two_epochs_reduce_loss_and_checkpoint(make_dataset, tmp_path):
    data = make_dataset("count", 64)
    cfg = _cfg(tmp_path, data)
    events = []
    res = train(cfg, lambda kind, **f: events.append((kind, f)))
    assert [h["epoch"] for h in res["history"]] == [1, 2]
    assert cfg.checkpoint_path().is_file()
    # training-mode loss (what the optimiser sees) falls from epoch 1 to epoch 2
    assert res["history"][1]["train_loss"] < 0.9 * res["history"][0]["train_loss"], res["history"]
    kinds = [k for k, _ in events]
    assert kinds.count("epoch_end") == 2 and "step" in kinds and "checkpoint" in kinds
    v = res["validation"]
    assert v["windows"] == 8 and np.array(v["confusion_matrix"]).sum() == 8


def test_anneal_keeps_the_seeds_rate_then_falls_to_the_floor(tmp_path):
    cfg = _cfg(tmp_path, tmp_path, epochs=5)
    assert {learning_rate(cfg, e, b, 10) for e in range(5) for b in range(10)} == {1e-3}  # no --anneal
    cfg.anneal = 2
    rates = [learning_rate(cfg, e, b, 10) for e in range(5) for b in range(10)]
    assert set(rates[:30]) == {1e-3}  # epochs 1-3 at the seed's rate
    tail = rates[30:]
    assert all(a > b for a, b in zip(tail[1:], tail[2:]))  # falls step by step
    assert tail[-1] < 0.01 * 1e-3 * 2 and learning_rate(cfg, 5, 0, 10) == pytest.approx(1e-3 * ANNEAL_FLOOR)
    assert learning_rate(cfg, 4, 0, 10) == pytest.approx(1e-3 * ANNEAL_FLOOR + (1e-3 - 1e-3 * ANNEAL_FLOOR) / 2)


@pytest.mark.slow
@pytest.mark.parametrize("anneal", [0, 1])
def test_interrupted_run_resumes_exactly(make_dataset, tmp_path, anneal):
    data = make_dataset("count", 28)
    straight = train(_cfg(tmp_path, data, out=tmp_path / "a.onnx", epochs=2, batch_size=8, anneal=anneal))

    def stop_after_two_steps(kind, **f):
        if kind == "step" and f["epoch"] == 1 and f["batch"] == 1:
            raise KeyboardInterrupt

    cfg = _cfg(tmp_path, data, out=tmp_path / "b.onnx", epochs=2, batch_size=8, anneal=anneal)
    with pytest.raises(KeyboardInterrupt):
        train(cfg, stop_after_two_steps)
    ck = torch.load(cfg.checkpoint_path(), weights_only=False)
    assert (ck["epoch"], ck["batch"]) == (1, 1)
    events = []
    resumed = train(cfg, lambda kind, **f: events.append((kind, f)))
    assert ("resume", {"epoch": 1, "batch": 1, "path": cfg.checkpoint_path()}) in events
    sa, sb = straight["net"].state_dict(), resumed["net"].state_dict()
    for k in sa:
        assert torch.allclose(sa[k].float(), sb[k].float(), atol=1e-6), k


def test_checkpoint_of_another_run_is_refused(make_dataset, tmp_path):
    data = make_dataset("count", 12)
    cfg = _cfg(tmp_path, data, epochs=1, batch_size=8)
    train(cfg)
    with pytest.raises(WallcliError, match="different run"):
        train(_cfg(tmp_path, data, epochs=1, batch_size=8, seed=7))


@pytest.mark.slow
def test_checkpoints_within_an_epoch_on_a_timer(make_dataset, tmp_path):
    data = make_dataset("count", 24)
    events = []
    train(_cfg(tmp_path, data, epochs=1, batch_size=8, checkpoint_minutes=1e-9),
          lambda kind, **f: events.append((kind, f)))
    mid = [f["batch"] for k, f in events if k == "checkpoint" and f["epoch"] == 0]
    assert mid == [1, 2, 3]  # after every step (21 training windows -> 3 batches of 8, 8, 5)
    assert ("checkpoint", {"path": tmp_path / "m.ckpt.pt", "epoch": 1, "batch": 0}) in events  # epoch end


def test_superpose_adds_windows_and_their_counts():
    from wallcli.train.augment import superpose

    rng = np.random.default_rng(0)
    b = {"horizontal": rng.normal(size=(40, 64, 256, 3)).astype(np.float32), "label": np.array([0, 1, 2, 1] * 10)}
    out = superpose(b, ["horizontal"], np.random.default_rng(3), p=0.5)
    again = superpose(b, ["horizontal"], np.random.default_rng(3), p=0.5)
    assert np.array_equal(out["horizontal"], again["horizontal"]) and np.array_equal(out["label"], again["label"])
    assert out["label"].max() <= 2 and np.all(out["label"] >= b["label"])
    changed = np.flatnonzero(np.any(out["horizontal"] != b["horizontal"], axis=(1, 2, 3)))
    assert 8 <= len(changed) <= 32  # about half, each partnered
    for i in changed:
        rest = out["horizontal"][i] - b["horizontal"][i]  # the scaled partner, possibly flipped/reversed
        cands = [j for j in range(40) if j != i and b["label"][i] + b["label"][j] == out["label"][i]]
        views = [b["horizontal"][j][::fs, ::ft] for j in cands for fs in (1, -1) for ft in (1, -1)]
        corr = max(abs(np.corrcoef(rest.ravel(), v.ravel())[0, 1]) for v in views)
        assert corr > 0.999
        ratio = np.std(rest) / np.std(b["horizontal"][i])
        assert 0.45 < ratio < 2.2
    # two-person windows take no partner but an empty one; nothing exceeds two people
    assert np.all(out["label"][b["label"] == 2] == 2)
    assert np.array_equal(superpose(b, ["horizontal"], np.random.default_rng(3), p=0.0)["label"], b["label"])


def test_train_refuses_a_device_it_cannot_use(tmp_path, run_cli):
    code, _, err = run_cli("train", "count", "--data", tmp_path, "--out", tmp_path / "m.onnx", "--device", "tpu")
    assert code == 2 and "--device must be cpu or cuda" in err
    import torch

    if not torch.cuda.is_available():
        code, _, err = run_cli("train", "count", "--data", tmp_path, "--out", tmp_path / "m.onnx", "--device", "cuda")
        assert code == 2 and "sees no CUDA GPU" in err
