"""What a user sees in an 80-column terminal: tables that fit, words in the singular where they
should be, one dB figure written one way, and a line on stderr for every file written."""
import json
import os
import re
import subprocess
import sys

import pytest


def _wallcli(*args, cwd=None):
    env = dict(os.environ, COLUMNS="80", LINES="40")
    return subprocess.run([sys.executable, "-m", "wallcli", *map(str, args)], capture_output=True, text=True,
                          timeout=300, env=env, cwd=cwd)


@pytest.fixture(scope="module")
def clip(tmp_path_factory):
    d = tmp_path_factory.mktemp("terminal")
    res = _wallcli("simulate", "-o", d / "walk.mp4", "--people", "1", "--activity", "walking", "--seed", "4",
                   "--size", "96x72", "--duration", "10.5", "--fps", "24", "--preview", d / "walk-room.png")
    assert res.returncode == 0, res.stderr
    return d / "walk.mp4", res


@pytest.mark.slow
def test_simulate_says_what_it_wrote(clip):
    path, res = clip
    assert res.stdout == ""
    line = res.stderr.strip()
    assert line.startswith(f"wrote {path} (") and "1 person, walking" in line
    assert f"{path.with_suffix('.json')} (its ground truth)" in line and "walk-room.png" in line


def _table_lines(out: str) -> list[str]:
    # the title is one unwrapped line (scripts grep it); the table and its notes are the rest
    return out.splitlines()[1:]


@pytest.mark.parametrize("task", ["count", "activity"])
def test_tables_fit_80_columns_and_quote_the_json_figures(task, clip):
    path, _ = clip
    res = _wallcli(task, path)
    assert res.returncode == 0, res.stderr
    lines = _table_lines(res.stdout)
    assert all(len(line) <= 80 for line in lines), "\n".join(lines)
    assert "…" not in res.stdout  # nothing truncated
    header = lines[0]
    if task == "count":
        assert header.split()[-6:] == ["0", "people", "1", "person", "2", "people"]
    else:
        assert header.split()[-5:] == ["none", "walking", "crouching", "waving", "jumping"]
    data = json.loads(_wallcli(task, path, "--json").stdout)
    rows = [line.split() for line in lines[2:2 + len(data["windows"]) + 1]]
    # the signal column is the JSON's signal_db to one decimal, window by window and for the clip
    for row, obj in zip(rows, data["windows"] + [data]):
        assert row[2] == f"{obj['signal_db']:.1f}".replace("-0.0", "0.0")
        assert row[1] == (str(obj["label"]) if obj["confident"] else "undetermined")
    if not data["confident"]:
        # the reason is a note under the table, quoting the same figure where it is judged on one
        # (activity's "two people possible" is judged on the count, not on the signal)
        if not data["reason"].startswith("two people"):
            assert f"signal {data['signal_db']:.1f} dB" in data["reason"]
        assert "undetermined: " + data["reason"][:40] in " ".join(res.stdout.split())


def test_snr_table_fits_80_columns(clip):
    path, _ = clip
    res = _wallcli("snr", path)
    assert res.returncode == 0, res.stderr
    # the headline figure first (issue 61), the verdict, then the (unwrapped) title
    headline, verdict, _title, *rest = res.stdout.splitlines()
    assert headline.startswith("column SNR ") and verdict.startswith("Verdict: ")
    assert all(len(line) <= 80 for line in [headline, verdict, *rest])
    assert "block SNR dB" in res.stdout and "-0.0" not in res.stdout


def test_amplify_names_its_grid_as_its_json_does(clip, tmp_path):
    path, _ = clip
    res = _wallcli("amplify", path, tmp_path / "amp.mp4", "--json", "--cells", "32")
    assert res.returncode == 0, res.stderr
    rows, cols = json.loads(res.stdout)["grid"]
    assert rows != cols and f"{rows} rows x {cols} columns" in res.stderr
    # the headline figure first (issue 61), then what was written
    assert res.stderr.startswith("column SNR ") and f"\nwrote {tmp_path / 'amp.mp4'} (" in res.stderr


def test_format_db_never_writes_minus_zero():
    from wallcli.wording import format_db

    assert [format_db(x) for x in (-0.04, -0.0, 0.04, 12.345, -3.96, None, float("nan"))] == \
        ["0.0", "0.0", "0.0", "12.3", "-4.0", "-", "-"]


def test_a_reason_quotes_the_figure_it_was_judged_on():
    from wallcli.infer.confidence import judge

    block = {"level": 0.97, "signal_edges_db": [0.0], "thresholds": [[None, None, None], [0.9, None, None]]}
    ok, reason = judge(block, [0.2, 0.7, 0.1], -0.04, [0, 1, 2])
    assert not ok and reason.startswith("'1 person' at signal 0.0 dB:") and not re.search(r"-0(\.0)? dB", reason)


def test_the_timeline_figure_is_titled_with_the_answer_the_table_gives(monkeypatch):
    """An undetermined answer was titled 'count = 1 (p=0.66 …)' in the report's figure."""
    import numpy as np

    import wallcli.plots.timeline as timeline
    from wallcli.signal.stplot import StPlot

    titles = []
    monkeypatch.setattr(timeline, "save_figure", lambda fig, path, force=False: titles.append(fig.axes[0].get_title("left")))
    t = np.arange(300) / 30
    plot = StPlot(np.zeros((64, 300, 3), np.float32), np.zeros((64, 300, 3), np.float32), t,
                  np.full((64, 3), 100, np.float32), np.full((64, 3), 100, np.float32), {"roi": [0, 0, 64, 48]})
    win = {"start": 0.0, "end": 8.53, "label": 1, "probabilities": [0.1, 0.66, 0.24], "confident": False}
    result = {"input": "a.mp4", "task": "count", "classes": [0, 1, 2], "label": 1, "probabilities": [0.1, 0.66, 0.24],
              "confident": False, "reason": "why", "windows": [win]}
    timeline.save_timeline_png("unused.png", result, plot)
    assert titles == ["a.mp4: count = undetermined (most likely 1 person, p=0.66), mean of 1 window"]


# the -v blurb: "No answer is decided today" while the shipped cards decide nothing (issue 61.2)
BLURB = ("independent renderer", "No answer is decided today", "simulated validation", "See the model card")


@pytest.mark.parametrize("task", ["count", "activity"])
def test_a_plain_call_prints_the_table_and_one_reason_and_v_adds_the_model_card(task, run_cli):
    # the model card's accuracy blurb (6 lines at 80 columns) was printed on every call
    clip = os.path.join(os.path.dirname(__file__), "..", "examples", "two-mixed.mp4")
    code, out, err = run_cli(task, clip)
    assert code == 0, err
    assert not any(b in out or b in err for b in BLURB) and "Each window's reason" not in out + err
    title, *rest = out.splitlines()
    assert title.startswith(f"{clip}: {task} = undetermined (most likely ")
    under = " ".join(out.split("clip ")[-1].splitlines()[1:])  # what follows the table's clip row
    assert under.startswith("undetermined: ") and under.count("undetermined: ") == 1
    assert err == ""
    for flag in ("-v", "--verbose"):
        code, out_v, err_v = run_cli(task, clip, flag)
        assert code == 0 and out_v == out  # stdout is the same data; the blurb goes to stderr
        said = " ".join(err_v.split())
        assert all(b in said for b in BLURB) and "Each window's reason: --json" in said
    code, out_j, err_j = run_cli(task, clip, "--json", "-v")  # --json stays one object on stdout
    assert code == 0 and json.loads(out_j)["task"] == task and "independent renderer" in " ".join(err_j.split())
    assert "--verbose" in run_cli(task, "--help")[1]


def test_a_decided_answer_says_so_in_words_in_the_title_and_under_the_table(capsys):
    from wallcli.cli._classify import _report

    class Model:
        card = {"name": "m", "version": "1", "confidence": {"level": 0.97}}
        single = False

    win = {"start": 0.0, "end": 8.53, "label": 1, "probabilities": [0.01, 0.97, 0.02], "confident": True,
           "signal_db": 12.0}
    result = {"input": "a.mp4", "task": "count", "classes": [0, 1, 2], "label": 1, "probabilities": [0.01, 0.97, 0.02],
              "confident": True, "reason": None, "signal_db": 12.0, "window": 256, "fps": 30.0, "windows": [win]}
    _report("count", "a.mp4", Model(), result, None, None, False, False)
    out, err = capsys.readouterr()
    lines = out.splitlines()
    assert lines[0] == "a.mp4: count = 1 person (decided, p=0.97); 1 window of 8.53 s"
    assert lines[-1] == "decided: answers like this were right at least 97 % of the time in validation."
    assert err == ""
    result = dict(result, label="walking", classes=["none", "walking", "crouching", "waving", "jumping"],
                  probabilities=[0.0, 0.99, 0.01, 0.0, 0.0], windows=[dict(win, label="walking",
                                                                           probabilities=[0.0, 0.99, 0.01, 0.0, 0.0])])
    _report("activity", "a.mp4", Model(), result, None, None, False, False)
    assert capsys.readouterr()[0].startswith("a.mp4: activity = walking (decided, p=0.99); ")
