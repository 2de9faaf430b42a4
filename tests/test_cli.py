"""The CLI's shape: version, help for every command, python -m, usage errors."""

import subprocess
import sys

import pytest

from wallcli import __version__

COMMANDS = ["stplot", "amplify", "snr", "count", "activity", "track", "simulate", "train", "evaluate", "report", "scan"]


def test_version_and_module_entry_point():
    out = subprocess.run([sys.executable, "-m", "wallcli", "--version"], capture_output=True, text=True, timeout=60)
    assert out.returncode == 0 and out.stdout.strip() == f"wallcli {__version__}"


def test_help_lists_every_command(run_cli):
    code, out, _ = run_cli("--help")
    assert code == 0
    for name in COMMANDS:
        assert name in out


@pytest.mark.parametrize("name", COMMANDS)
def test_command_help(run_cli, name):
    code, out, err = run_cli(name, "--help")
    assert code == 0, err
    assert "Usage:" in out and "--help" in out


@pytest.mark.parametrize("name", COMMANDS)
def test_help_names_every_value_in_one_style(run_cli, name):
    """Usage reads `wallcli CMD [OPTIONS] INPUT` ([INPUT] when optional, INPUT... when repeated),
    and every option that takes a value names it in capitals (PATH, TEXT, INTEGER, NUMBER, X,Y,W,H),
    never typer's {input}, [input] or <list[str]>; help cites files a user has (docs/contract.md)."""
    import re

    code, out, _ = run_cli(name, "--help")
    usage = next(line for line in out.splitlines() if line.startswith("Usage:"))
    assert re.fullmatch(rf"Usage: wallcli {name} \[OPTIONS\]( (\[[A-Z]+\]|[A-Z]+(\.\.\.)?))*", usage), usage
    assert not re.search(r"<[a-z\[\]]+>|\{[A-Za-z]+\}", out)
    entries = re.findall(r"^  (-[-\w]+(?:, -[-\w]+)?)(?: (\S+))?  ", out, re.M)
    assert entries
    for flags, value in entries:
        shape = re.sub(r"(?<=[A-Z])x(?=[A-Z])|\|[a-z]+", "", value)  # WxH, X,Y,W,H|auto: literal parts
        assert shape == shape.upper(), (flags, value)
    assert "CONTRACT.md" not in out and "seed §" not in out and "seed notes" not in out
    if name == "snr":  # the estimator is the paper's supplementary §3.2 (help once said §4)
        assert "Staring at a Blank Wall, ICCV 2021, supplementary §3.2" in " ".join(out.split())


def test_help_does_not_import_heavy_modules():
    code = (
        "import sys; from wallcli.cli.app import app; "
        "heavy = [m for m in ('numpy', 'av', 'cv2', 'onnxruntime', 'matplotlib', 'torch') if m in sys.modules]; "
        "print(','.join(heavy))"
    )
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=60)
    assert out.returncode == 0 and out.stdout.strip() == "", out.stdout


def test_unknown_option_is_a_one_line_usage_error(run_cli):
    code, out, err = run_cli("stplot", "x.mp4", "--no-such-option")
    assert code == 2 and out == ""
    assert len(err.strip().splitlines()) == 1 and err.startswith("Error:")


@pytest.mark.parametrize("name", [None, *COMMANDS])
def test_help_fits_80_columns(run_cli, name, monkeypatch):
    """Examples are kept as written (click's \\b): none may run past an 80-column terminal."""
    monkeypatch.setenv("COLUMNS", "80")
    code, out, _ = run_cli(*([name] if name else []), "--help")
    assert code == 0
    long = [line for line in out.splitlines() if len(line) > 80]
    assert not long, long


@pytest.mark.parametrize("n,fps", [(2, 30), (100, 25)])
def test_too_short_quotes_the_files_own_frames(tmp_path, run_cli, n, fps):
    """Issue 38 item 10: count quoted its resampled samples (1 where snr said 2 decoded)."""
    import json
    import re

    import numpy as np
    from clips import write_clip

    clip = write_clip(tmp_path / "s.mkv", lambda i: np.full((32, 32, 3), 100.0) + i % 3, n, fps=fps,
                      codec="ffv1", pix_fmt="yuv444p", options={})
    code, _, err = run_cli("count", clip)
    assert code == 1 and f"{n} frame(s) decoded" in err, err
    code, _, err = run_cli("count", clip, "--follow")
    assert code == 1 and f"{n} frame(s) decoded" in err, err
    if n >= 3:
        code, out, _ = run_cli("snr", clip, "--json")
        assert code == 0 and json.loads(out)["frames"] == n
    else:
        code, _, err = run_cli("snr", clip)
        assert code == 1 and re.search(rf"\b{n} frame\(s\) decoded", err)
    code, _, err = run_cli("stplot", clip, "-o", tmp_path / "p.npz")
    if code == 0:
        code, _, err = run_cli("count", tmp_path / "p.npz")
        assert code == 1 and f"{n} frame(s) decoded" in err, err


def test_follow_on_a_file_gives_the_whole_runs_windows_and_ends_with_the_clip(run_cli):
    """--follow on a finite file: the windows of the whole run (the end-aligned last one too),
    then the clip's answer, the object --json prints."""
    import json
    from pathlib import Path

    clip = Path(__file__).resolve().parents[1] / "examples" / "walking.mp4"
    code, out, _ = run_cli("activity", clip, "--json")
    whole = json.loads(out)
    code2, out, _ = run_cli("activity", clip, "--follow")
    lines = [json.loads(x) for x in out.splitlines()]
    assert code == code2 == 0 and len(whole["windows"]) == 3
    *windows, last = lines
    assert [w["start"] for w in windows] == [w["start"] for w in whole["windows"]]
    assert [w["probabilities"] for w in windows] == [w["probabilities"] for w in whole["windows"]]
    assert "windows" in last and not any("windows" in w for w in windows)
    assert {k: last[k] for k in ("label", "probabilities", "confident", "reason", "signal_db")} == \
        {k: whole[k] for k in ("label", "probabilities", "confident", "reason", "signal_db")}
