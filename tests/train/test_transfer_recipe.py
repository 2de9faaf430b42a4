"""The shipped models' recipe in miniature: a 'wide' count dataset trains both nets (activity
from its windows with at most one mover), the 'lite' nets read both plots, the loss can be
balanced, and --calibrate writes the decided/undetermined thresholds into the card."""
import json

import numpy as np
import pytest

torch = pytest.importorskip("torch")

from wallcli.infer.card import read_card  # noqa: E402
from wallcli.train.data import ShardDataset  # noqa: E402


def _as_wide(root):
    """Mark a test dataset as the simulator's 'wide' domain, with level offsets per window."""
    man = json.loads((root / "dataset.json").read_text())
    man["recipe"] = {**man["recipe"], "domain": "wide"}
    (root / "dataset.json").write_text(json.dumps(man))
    from wallcli.io.arrays import load_npz, save_npz

    for f in sorted(root.glob("shard-*.npz")):
        arrays, meta = load_npz(f, kind="wallcli.dataset-shard")
        n = len(arrays["label"])
        arrays["h_offset"] = np.full((n, 64, 3), 120.0, np.float32)
        arrays["v_offset"] = np.full((n, 64, 3), 120.0, np.float32)
        save_npz(f, arrays, meta, force=True)
    return root


def test_a_wide_count_dataset_serves_the_activity_net(make_dataset):
    data = _as_wide(make_dataset("count", 24))
    ds = ShardDataset(data, "activity", inputs=["horizontal", "vertical"])
    labels = ds.labels()
    usable = ds.usable(np.arange(ds.n))
    raw = np.concatenate([np.load(f)["label"] for f in sorted(data.glob("shard-*.npz"))])
    assert np.array_equal(usable, np.flatnonzero(raw <= 1))  # two movers: no activity label
    b = ds.gather(usable[:4])
    assert b["h_offset"].shape == (4, 64, 3) and np.array_equal(b["label"], labels[usable[:4]])
    with pytest.raises(Exception, match="count"):  # a base-domain count set is not an activity set
        make = make_dataset("count", 8, name="base")
        ShardDataset(make, "activity")


@pytest.mark.slow
def test_lite_nets_train_balanced_and_calibrated(make_dataset, tmp_path, cli_code):
    data = _as_wide(make_dataset("count", 24))
    val = _as_wide(make_dataset("count", 96, seed=9, shards=1, name="val", visibility=True))
    out = tmp_path / "count.onnx"
    assert cli_code(["train", "count", "--data", data, "--val", val, "--out", out, "--epochs", "2", "--batch-size", "4",
                    "--threads", "1", "--arch", "lite", "--balance", "--calibrate", val,
                    "--confidence-level", "0.9"]) == 0
    card = read_card(out)
    assert [i["name"] for i in card["inputs"]] == ["horizontal", "vertical"]
    assert card["training"]["arch"] == "lite" and "--arch lite --balance --calibrate" in card["training"]["command"]
    conf = card["confidence"]
    assert conf["level"] == 0.9 and len(conf["thresholds"]) == len(conf["signal_edges_db"]) + 1
    snr = np.load(next(val.glob("shard-*.npz")))["snr_db_weakest"]
    assert conf["calibrated_on"]["windows"] == int(np.sum(np.isnan(snr) | (snr >= -20)))  # people at -20 dB or more
    # the thresholds are met on the windows they were fitted on, wherever something is decided
    if conf["calibrated_on"]["coverage"] > 0:
        assert conf["calibrated_on"]["accuracy_decided"] >= 0.9
    assert cli_code(["train", "activity", "--data", data, "--out", tmp_path / "act.onnx", "--epochs", "1",
                    "--batch-size", "4", "--threads", "1", "--arch", "lite", "--val-fraction", "0.25"]) == 0
    assert read_card(tmp_path / "act.onnx")["classes"][0] == "none"
    assert cli_code(["train", "count", "--data", data, "--out", tmp_path / "x.onnx", "--arch", "huge"]) == 2
