"""Every option of every command, read from the typer app itself, with hostile values.

A new command or option is swept the day it is added: the list comes from
``typer.main.get_command(app)``, not from this file. Each call must end with exit code 0, 1 or 2;
a failure is exactly one ``Error:`` line on stderr, nothing on stdout, no traceback, no "internal
error", and no file left behind; ``--json`` output parses; inputs are untouched; and no call runs
longer than CALL_LIMIT seconds. Calls run in-process (wallcli.cli.app.main, as the CLI does), a
sample again as real processes. BASES holds a working command line per command so that values the
parser accepts reach the work behind them; a command without one gets a generic line built from its
required parameters (add it to BASES for deeper coverage).
"""
from __future__ import annotations

import enum
import inspect
import json
import os
import random
import signal
import subprocess
import sys
import typing
from pathlib import Path

import numpy as np
import pytest
import typer
from clips import write_clip, write_plot

from wallcli.cli.app import app
from wallcli.cli.common import Number

CALL_LIMIT = 30  # seconds; the slowest accepted call here takes about one on a busy 2-core machine
COMMAND = typer.main.get_command(app)
NAMES = sorted(COMMAND.commands)

NUMBERS = ["0", "-1", "nan", "-inf", "inf", "1e308", "-1e308", str(2**64), "9" * 5000, "", "abc", "1,5", "0x1f",
           "1e-320"]
TEXTS = ["", "0", "-1", "nan", "inf", "1e308", "abc", ",", "0,0,0,0", "-1,-1,-1,-1", "nan,nan,nan,nan",
         "inf,inf,inf,inf", "1e308,1e308,1e308,1e308", "99999999999999999999,0,8,8", "0x0",
         "99999999999x99999999999", "nan,inf", "0,1e308", "distance=nan:inf:0", "distance=0:1e308:1e-300",
         "[/x]", os.fsdecode(b"\xff")]
PATHS = ["", ".", "/", "nowhere/x.png", "0", "x.png", "[/x].png", os.fsdecode(b"\xff.png"), "{input}"]
CHOICES = ["", "abc", "0", "COUNT"]

# A command line that works, per command; {clip}, {plot} are inputs, other paths land in the work folder.
BASES = {
    "stplot": [["{clip}", "-o", "out.npz", "--png", "out.png", "--json"]],
    "amplify": [["{clip}", "out.mp4"]],
    "snr": [["{clip}", "--json"], ["--predict", "--json"]],
    "count": [["{plot}", "--json", "--plot", "out.png"], ["{clip}"]],
    "activity": [["{plot}", "--json"], ["{clip}"]],
    "track": [["{plot}", "--json", "--csv", "out.csv", "--png", "out.png"], ["{clip}"]],
    "simulate": [["-o", "out.y4m", "--size", "16x16", "--duration", "0.2", "--fps", "15", "--grid", "4x4"]],
    "train": [["count", "--data", "nodata", "--out", "out.onnx"]],
    "evaluate": [["{labelled}", "--task", "count", "--json", "--jobs", "1"]],
    "scan": [["{clip}", "-o", "out.jsonl", "--workers", "1", "--task", "snr"]],
    "report": [["{clip}", "-o", "out.html"]],
}


class _CallTimeout(BaseException):
    """Raised by SIGALRM in the main thread: not an Exception, so wallcli's handlers let it through."""


def _leaf(annotation):
    """int for Optional[int], Path for List[Path], ..."""
    for _ in range(3):
        args = [a for a in typing.get_args(annotation) if a is not type(None)]
        if not args:
            break
        annotation = args[0]
    return annotation


def _signature(name: str) -> dict[str, tuple[object, object]]:
    """param name -> (annotation, typer OptionInfo/ArgumentInfo) from the command's function."""
    callback = next(c.callback for c in app.registered_commands if (c.name or c.callback.__name__) == name)
    hints = typing.get_type_hints(callback)
    return {p: (_leaf(hints.get(p)), info.default) for p, info in inspect.signature(callback).parameters.items()}


def _kind(name: str, param) -> str:
    annotation, info = _signature(name)[param.name]
    if getattr(param, "is_flag", False) or annotation is bool:
        return "flag"
    if isinstance(annotation, type) and issubclass(annotation, enum.Enum):
        return "choice"
    if annotation in (int, float) or isinstance(getattr(info, "parser", None), Number):
        return "number"
    if isinstance(annotation, type) and issubclass(annotation, Path):
        return "path"
    return "text"


def _values(kind: str) -> list[str]:
    return {"number": NUMBERS, "text": TEXTS, "path": PATHS, "choice": CHOICES}[kind]


def _generic_base(name: str) -> list[list[str]]:
    """A command line from the command's required parameters, for commands not in BASES."""
    line = []
    for param in COMMAND.commands[name].params:
        if not param.required:
            continue
        kind = _kind(name, param)
        annotation = _signature(name)[param.name][0]
        value = (str(next(iter(annotation)).value) if kind == "choice" else
                 "1" if kind == "number" else
                 "out.json" if {"-o", "--output", "--out"} & set(getattr(param, "opts", [])) else "{clip}")
        line += ([param.opts[0]] if param.param_type_name == "option" else []) + [value]
    return [line]


def _cases(name: str):
    """(base, option string, value or None for a flag) for every option of the command."""
    cmd = COMMAND.commands[name]
    for base in BASES.get(name) or _generic_base(name):
        for param in cmd.params:
            if param.param_type_name != "option" or param.name == "help":
                continue
            kind = _kind(name, param)
            if kind == "flag":
                for opt in list(param.opts) + list(getattr(param, "secondary_opts", [])):
                    yield base, param, opt, None
            else:
                for value in _values(kind):
                    yield base, param, param.opts[0], value


def _argv(base, param, opt, value, inputs):
    names = set(param.opts) | set(getattr(param, "secondary_opts", []))
    line, skip = [], False
    for i, tok in enumerate(base):  # drop the base's own value of the option being swept
        if skip:
            skip = False
            continue
        if tok in names:
            skip = not getattr(param, "is_flag", False)
            continue
        line.append(tok)
    line += [opt] if value is None else [opt, value]
    return [inputs.get(tok[1:-1], tok) if tok.startswith("{") and tok.endswith("}") else tok for tok in line]


def _snapshot(folder: Path) -> dict[str, tuple[int, int]]:
    return {str(p.relative_to(folder)): (p.stat().st_size, p.stat().st_mtime_ns)
            for p in folder.rglob("*") if p.is_file()}


def _check(argv, code, out, err, work, inputs_before, inputs_dir):
    where = f"wallcli {' '.join(map(repr, argv))}\n--- stderr:\n{err}"
    assert code in (0, 1, 2), where
    assert "Traceback" not in err and "internal error" not in err, where
    errors = [line for line in err.splitlines() if line.startswith("Error:")]
    if code == 0:
        assert not errors, where
        if "--json" in argv and "--follow" not in argv:
            json.loads(out)
    else:
        assert len(errors) == 1 and out == "", where
        assert _snapshot(work) == {}, f"left behind: {where}"
    assert not [p for p in work.rglob(".*.tmp*")], f"temporary left: {where}"
    assert _snapshot(inputs_dir) == inputs_before, f"an input changed: {where}"


@pytest.fixture(scope="module")
def inputs(tmp_path_factory):
    folder = tmp_path_factory.mktemp("inputs")
    # 48x40: the smallest frames the camera-motion check can judge are 33 samples a side (a smaller
    # one is 'too small to check', which --strict rightly refuses)
    clip = write_clip(folder / "c.mkv", lambda i: np.full((40, 48, 3), 120.0)
                      + np.random.default_rng(i).normal(0, 1.0, (40, 48, 3)), 12, fps=30, codec="ffv1",
                      pix_fmt="bgr0", options={})
    plot = write_plot(folder / "p.npz")
    labelled = folder / "labelled"  # a folder of clips with labels (wallcli evaluate)
    labelled.mkdir()
    write_clip(labelled / "long.mkv", lambda i: np.full((40, 48, 3), 120.0), 270, fps=30, codec="ffv1",
               pix_fmt="bgr0", options={})
    (labelled / "labels.csv").write_text("file,people,activity\nlong.mkv,0,none\n")
    return folder, {"clip": str(clip), "plot": str(plot), "input": str(clip), "labelled": str(labelled)}


def _run_in_process(argv, capsys):
    from wallcli.cli.app import main

    def alarm(signum, frame):
        raise _CallTimeout

    previous = signal.signal(signal.SIGALRM, alarm)
    signal.setitimer(signal.ITIMER_REAL, CALL_LIMIT)
    try:
        main(argv)
        code = 0
    except SystemExit as exc:
        code = exc.code
    except _CallTimeout:
        pytest.fail(f"wallcli {' '.join(map(repr, argv))} ran past {CALL_LIMIT} s")
    finally:
        signal.setitimer(signal.ITIMER_REAL, 0)
        signal.signal(signal.SIGALRM, previous)
    out, err = capsys.readouterr()
    return code, out, err


def _clear(work: Path) -> None:
    for p in sorted(work.rglob("*"), key=lambda p: len(p.parts), reverse=True):
        p.rmdir() if p.is_dir() and not p.is_symlink() else p.unlink()


@pytest.mark.slow
@pytest.mark.parametrize("name", NAMES)
def test_every_option_with_hostile_values(name, inputs, tmp_path, monkeypatch, capsys):
    folder, paths = inputs
    before_inputs = _snapshot(folder)
    work = tmp_path / "work"
    work.mkdir()
    monkeypatch.chdir(work)
    if name in BASES:  # the first base works, or the sweep would stop at a usage error every time
        argv = [name] + [paths.get(t[1:-1], t) if t.startswith("{") else t for t in BASES[name][0]]
        code, _, err = _run_in_process(argv, capsys)
        assert code == (1 if name == "train" else 0), err
        _clear(work)
    for base, param, opt, value in _cases(name):
        argv = [name] + _argv(base, param, opt, value, paths)
        code, out, err = _run_in_process(argv, capsys)
        _check(argv, code, out, err, work, before_inputs, folder)
        _clear(work)


def test_every_numeric_option_is_finite_and_bounded():
    """Through common.Number (NaN, +-inf and out-of-range values refused, exit 2), with both ends set."""
    loose = []
    for name in NAMES:
        for param in COMMAND.commands[name].params:
            annotation, info = _signature(name)[param.name]
            if annotation in (int, float):
                parser = getattr(info, "parser", None)
                if not isinstance(parser, Number) or parser.lo is None or parser.hi is None:
                    loose.append(f"{name} {param.opts}")
    assert not loose, f"numeric options not built with common.number_option: {loose}"


def test_sweep_covers_every_command_and_option():
    # the sweep's own bookkeeping: each command has a base line and every option yields calls
    for name in NAMES:
        options = {p.name for p in COMMAND.commands[name].params if p.param_type_name == "option"} - {"help"}
        swept = {param.name for _, param, _, _ in _cases(name)}
        assert swept == options, (name, options - swept)


def _sample(k: int = 10, seed: int = 22):
    rng = random.Random(seed)
    cases = [(name, *case) for name in NAMES if name != "train" for case in _cases(name)]  # (torch loads slowly)
    return [pytest.param(*case, id=f"{case[0]} {case[3]} {case[4]!r:.30}") for case in rng.sample(cases, k)]


@pytest.mark.parametrize("name,base,param,opt,value", _sample())
def test_a_sample_as_real_processes(name, base, param, opt, value, inputs, tmp_path):
    folder, paths = inputs
    before_inputs = _snapshot(folder)
    argv = [name] + _argv(base, param, opt, value, paths)
    res = subprocess.run([sys.executable, "-m", "wallcli", *[os.fsencode(a) for a in argv]], cwd=tmp_path,
                         stdin=subprocess.DEVNULL, capture_output=True, timeout=CALL_LIMIT + 60)
    out, err = res.stdout.decode("utf-8"), res.stderr.decode("utf-8", "backslashreplace")
    _check(argv, res.returncode, out, err, tmp_path, before_inputs, folder)


def test_standard_input_as_a_hostile_input(tmp_path):
    # '-' reads a stream on stdin; an empty one is a clean failure
    res = subprocess.run([sys.executable, "-m", "wallcli", "stplot", "-", "-o", "p.npz"], cwd=tmp_path,
                         stdin=subprocess.DEVNULL, capture_output=True, text=True, timeout=CALL_LIMIT + 60)
    assert res.returncode == 1 and len(res.stderr.strip().splitlines()) == 1 and res.stderr.startswith("Error:")
    assert list(tmp_path.iterdir()) == []
