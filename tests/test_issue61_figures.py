"""Issue 61 (1, 3, 8): one headline figure, printed first under its name by count, activity and
snr, on the labels' scale; stplot's PNG with a short title, a colour scale and its seams explained,
positions in fractions of the view as track's."""
from __future__ import annotations

import json
from types import SimpleNamespace

import numpy as np
import pytest

from clips import write_clip
from wallcli.snr import column


def _planes(img):
    return SimpleNamespace(y=img, u=None, v=None, kind="gray", width=img.shape[1], height=img.shape[0])


def _shade(T, W, H, amp):
    x = np.arange(W)[None, :]
    centre = W * (0.5 + 0.35 * np.sin(2 * np.pi * 0.3 * np.arange(T) / 30.0))[:, None]
    return 120.0 - amp * np.exp(-0.5 * ((x - centre) / (0.15 * W)) ** 2)  # (T, W)


@pytest.mark.parametrize("amp,sigma,W", [(0.6, 2.0, 64), (2.0, 2.0, 64), (1.5, 4.0, 64), (0.6, 2.0, 1100)])
def test_column_snr_is_the_labels_definition(amp, sigma, W):
    # the labels' snr_db: the clean column profile's change over the noise of one column's mean
    # (1100 columns: measured in groups of 3, as a wide frame is)
    T, H = 512, 48
    clean = _shade(T, W, H, amp)
    g = clean - clean.mean(axis=0, keepdims=True)
    g = g - g.mean(axis=1, keepdims=True)
    truth = 10 * np.log10(np.mean(g * g) / (sigma ** 2 / H)) + column.CALIBRATION_DB
    rng = np.random.default_rng(1)
    tap = column.ColumnSnr(fps=30.0)
    for t in range(T):
        tap.push(_planes(clean[t][None, :] + sigma * rng.standard_normal((H, W))))
    assert tap.db() == pytest.approx(truth, abs=1.0)


def test_column_snr_of_noise_alone_is_under_zero():
    rng = np.random.default_rng(2)
    tap = column.ColumnSnr(fps=30.0)
    for _ in range(300):
        tap.push(_planes(100.0 + 3.0 * rng.standard_normal((40, 64))))
    assert tap.db() < 0


def test_column_text_names_its_figure_and_band():
    assert column.column_text(16.9) == "column SNR 16.9 dB (labels' scale): plain in the plot"
    assert column.column_text(-3.0).endswith("under the noise")
    assert column.column_text(5.0).endswith("faint in the plot")


@pytest.fixture(scope="module")
def walker(tmp_path_factory):
    path = tmp_path_factory.mktemp("c") / "walker.mp4"
    shade = _shade(330, 48, 36, 6.0)
    rng = np.random.default_rng(3)

    def frame(i):
        img = np.repeat(shade[i][None, :, None], 36, 0) + 1.5 * rng.standard_normal((36, 48, 1))
        return np.repeat(img, 3, axis=2)

    return write_clip(path, frame, 330)


def test_count_prints_the_headline_first(run_cli, walker):
    code, out, _ = run_cli("count", walker, "--json")
    assert code == 0
    db = json.loads(out)["column_snr_db"]
    assert isinstance(db, float) and db > 10  # a plain shade
    code, out, _ = run_cli("count", walker)
    assert code == 0
    title, header = out.splitlines()[:2]  # the title stays first (scripts grep it)
    assert "; column SNR " in title and title.index("column SNR") < title.index(" dB")  # the first figure
    assert "signal_db" in header.split()  # the table's figure says which one it is


def test_snr_prints_the_headline_first(run_cli, walker):
    code, out, _ = run_cli("snr", walker, "--json")
    assert code == 0
    obj = json.loads(out)
    assert obj["column_snr_db"] > 10 and "snr_db" in obj  # added, none renamed
    code, out, _ = run_cli("snr", walker)
    lines = out.splitlines()
    assert lines[0].startswith("column SNR ") and lines[1].startswith("Verdict: ") and "block SNR" in lines[1]


def test_stplot_png_title_scale_and_units(tmp_path, walker):
    from PIL import Image

    from wallcli.infer.classify import load_plot
    from wallcli.plots import stplot

    plot = load_plot(walker)
    plot.meta["source"] = "a/rather/long/folder/name/of/the/kind/people/keep/their/recordings/in/" + "x" * 40 + ".mp4"
    png = tmp_path / "p.png"
    stplot.save_stplot_png(png, plot)
    w, h = Image.open(png).size
    assert w <= 1260  # the title no longer widens the figure (it was over 1500 px)
    assert "gain" not in stplot.stplot_title("a.mp4", 2.0)
    assert "code values" in stplot.scale_label(2.0)
    assert "key frames" in stplot.SEAMS
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, axes = plt.subplots(2, 1)
    stplot.draw_stplot(axes, plot)
    assert axes[0].get_ylim() == (1.0, 0.0)  # fractions of the view, as track's x
    assert "0 = view's left" in axes[0].get_ylabel()
    plt.close(fig)


def _capture(monkeypatch, module):
    figs = []
    monkeypatch.setattr(module, "save_figure", lambda fig, path, **kw: figs.append(fig))
    return figs


def test_snr_plot_draws_snr_in_db(monkeypatch, run_cli, walker, tmp_path):
    # the tables give dB; the figure drew signal/noise as a ratio on a log axis (10^0-10^4)
    from wallcli.plots import snr as plots

    figs = _capture(monkeypatch, plots)
    code, out, err = run_cli("snr", walker, "--json")
    plots.save_scales_png(tmp_path / "s.png", json.loads(out))
    ax = figs[0].axes[0]
    assert ax.get_ylabel() == "block SNR (dB)" and ax.get_yscale() == "linear"
    green = json.loads(out)["scales"]
    assert list(ax.lines[2].get_ydata()) == pytest.approx([s["snr_db"][1] for s in green])
    rows = [{"distance": d, "snr": v} for d, v in ((1.0, 100.0), (2.0, 0.1))]
    plots.save_sweep_png(tmp_path / "w.png", "distance", rows)
    sweep = figs[1].axes[0]
    assert sweep.get_ylabel() == "predicted SNR (dB)"
    assert list(sweep.lines[0].get_ydata()) == pytest.approx([20.0, -10.0])


def test_count_plot_says_what_its_band_is_and_positions_are_fractions(monkeypatch, run_cli, walker, tmp_path):
    from wallcli.plots import timeline

    figs = _capture(monkeypatch, timeline)
    code, _, err = run_cli("count", walker, "--plot", tmp_path / "t.png")
    assert code == 0, err
    ax_p, ax_h = figs[0].axes[:2]
    labels = ax_p.get_legend_handles_labels()[1]
    assert "one window" not in labels and any("each dot is the answer" in t for t in labels)
    assert ax_h.get_ylim() == (1.0, 0.0) and "0 = view's left" in ax_h.get_ylabel()


def test_gallery_titles_follow_counts_rule():
    # the gallery said "1 people" and "1 people (none)" for a person standing still
    import importlib.util
    from pathlib import Path

    path = Path(__file__).resolve().parents[1] / "examples" / "gallery.py"
    spec = importlib.util.spec_from_file_location("gallery", path)
    gallery = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(gallery)
    assert gallery.who({"activities": ["none"]}) == "0 moving (one standing still)"
    assert gallery.who({"activities": ["walking"]}) == "1 person (walking)"
    assert gallery.who({"activities": ["walking", "crouching"]}) == "2 people (walking, crouching)"
    assert gallery.who({"activities": []}) == "0 people (empty room)"


def test_stplot_help_explains_the_seams_and_units(run_cli):
    code, out, _ = run_cli("stplot", "--help")
    said = " ".join(out.split())
    assert code == 0 and "key frames" in said and "fractions of the view" in said


def test_stplot_says_the_headline_first(run_cli, walker, tmp_path):
    code, out, err = run_cli("stplot", walker, "-o", tmp_path / "p.npz", "--json")
    assert code == 0, err
    said = [line for line in err.splitlines() if line.startswith(("column SNR", "wrote"))]  # warnings aside
    assert said[0].startswith("column SNR ") and json.loads(out)["column_snr_db"] > 10


def test_scan_carries_the_headline_of_count_and_snr(run_cli, walker, tmp_path):
    code, _, err = run_cli("scan", walker, "-o", tmp_path / "r.jsonl", "--task", "count,snr")
    assert code == 0, err
    line = json.loads((tmp_path / "r.jsonl").read_text().splitlines()[0])
    assert line["count"]["column_snr_db"] == line["snr"]["column_snr_db"] > 10
