"""Models for inference tests: the seed's nets with a fixed random initialisation, exported
with cards exactly as ``wallcli train`` does (trained weights are not needed to test the
plumbing), and space-time plot files."""
from __future__ import annotations

import pytest

from wallcli.io.arrays import save_npz
from wallcli.signal.stplot import FORMAT
from stplot_fixtures import streak_plot


@pytest.fixture(scope="session")
def models(tmp_path_factory):
    torch = pytest.importorskip("torch")
    from wallcli.train.export import export_model
    from wallcli.train.nets import build

    root = tmp_path_factory.mktemp("models")
    out = {}
    for task in ("count", "activity"):
        torch.manual_seed(1)
        net = build(task).eval()
        path = root / f"{task}.onnx"
        export_model(net, list(net.input_names), path, dict(
            name=f"test-{task}", version="0.0.1", task=task, classes=net.classes,
            training_data={"recipe": None}, training={"seed": 1}, validation=None))
        out[task] = path
    return out


@pytest.fixture
def plot_file(tmp_path):
    def make(fps: float = 30.0, seconds: float = 12.0, bins: int = 64, name: str = "p.npz"):
        h, v, t = streak_plot(fps, seconds, bins)
        path = tmp_path / name
        save_npz(path, {"horizontal": h, "vertical": v, "time": t}, {"format": FORMAT, "format_version": 1,
                                                                    "bins": bins, "fps": fps, "roi": [0, 0, 64, 48]})
        return path
    return make
