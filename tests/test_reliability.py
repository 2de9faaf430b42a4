"""Issue 22's eight defects, one regression test (or a few) each: hostile option values, non-UTF-8
file names, a stdout that cannot be written, model cards with bad fields, signals during shut-down."""
import errno
import json
import os
import shutil
import signal
import subprocess
import sys
from pathlib import Path

import pytest
from clips import model_with, one_error, tiny_clip, write_plot

from wallcli.cli.common import MAX_THREADS


# the clip is 32x24 px: fewer pixels than 64 bins is warned about, and these tests count stderr lines
FEW_BINS = ("--bins", "16")


_one_error = one_error


@pytest.fixture
def clip(tmp_path):
    return tiny_clip(tmp_path / "c.mkv")


def _files(folder: Path) -> set[str]:
    return {p.name for p in folder.iterdir()}


# 1 ------------------------------------------------------------------------------ --threads bound
@pytest.mark.parametrize("command", ["stplot", "amplify", "snr", "count", "activity"])
def test_threads_beyond_four_per_core_is_a_usage_error(tmp_path, run_cli, clip, command):
    args = {"stplot": ["-o", tmp_path / "p.npz"], "amplify": [tmp_path / "a.mp4"]}.get(command, [])
    code, out, err = run_cli(command, clip, *args, "--threads", 100000)
    assert code == 2 and out == ""
    assert "--threads" in _one_error(err) and f"from 0 to {MAX_THREADS}" in err
    assert _files(tmp_path) == {"c.mkv"}


def test_threads_help_states_the_bound_and_the_bound_itself_works(tmp_path, run_cli, clip):
    code, out, _ = run_cli("stplot", "--help")
    assert code == 0 and "4 per CPU core" in " ".join(out.split())
    code, _, err = run_cli("stplot", clip, "-o", tmp_path / "p.npz", "--threads", MAX_THREADS)
    assert code == 0, err
    code, _, err = run_cli("stplot", clip, "-o", tmp_path / "q.npz", "--threads", MAX_THREADS + 1)
    assert code == 2 and not (tmp_path / "q.npz").exists()


# 2, 3 ------------------------------------------------------------------------------------ gains
@pytest.mark.parametrize("extra", [["--gain", "0"], ["--style", "diverging", "--gain", "-5"], ["--gain", "nan"],
                                   ["--gain", "1e308"], ["--gain", "inf"]])
def test_stplot_bad_gain_is_refused_before_any_output(tmp_path, run_cli, clip, extra):
    code, out, err = run_cli("stplot", clip, "-o", tmp_path / "p.npz", "--png", tmp_path / "p.png", *extra)
    assert code == 2 and out == "" and "--gain" in _one_error(err)
    assert _files(tmp_path) == {"c.mkv"}  # the .npz is not written either


@pytest.mark.parametrize("gain", ["inf", "nan", "0", "-1"])
def test_amplify_bad_gain_is_refused(tmp_path, run_cli, clip, gain):
    code, _, err = run_cli("amplify", clip, tmp_path / "a.mp4", "--gain", gain)
    assert code == 2 and "--gain" in _one_error(err)
    assert _files(tmp_path) == {"c.mkv"}


def test_stplot_png_failure_leaves_no_npz(tmp_path, run_cli, clip, monkeypatch):
    # the outputs of one command commit together: a PNG that fails takes the .npz with it
    import wallcli.plots.stplot as plots
    from wallcli.errors import WallcliError

    def broken(*a, **k):
        raise WallcliError("the PNG could not be drawn")

    monkeypatch.setattr(plots, "save_stplot_png", broken)
    code, _, err = run_cli("stplot", clip, "-o", tmp_path / "p.npz", "--png", tmp_path / "p.png", *FEW_BINS)
    assert code == 1 and "could not be drawn" in _one_error(err)
    assert _files(tmp_path) == {"c.mkv"}


def test_stplot_gain_at_its_bound_draws(tmp_path, run_cli, clip):
    code, _, err = run_cli("stplot", clip, "--png", tmp_path / "p.png", "--gain", "1e6", "--style", "diverging", *FEW_BINS)
    assert code == 0 and "Warning" not in err, err
    assert (tmp_path / "p.png").stat().st_size > 0


# 4 ------------------------------------------------------------------------- non-UTF-8 file names
def test_json_of_a_non_utf8_file_name_parses(tmp_path, run_cli, clip):
    name = os.fsdecode(b"b\xff.mkv")  # how Python holds an undecodable byte of a file name
    if name == "b\ufffd.mkv":
        pytest.skip("this file system encoding cannot hold undecodable bytes")
    weird = tmp_path / name
    shutil.copy(clip, weird)
    for args in (["snr", weird, "--json"], ["stplot", weird, "--json", "-o", tmp_path / os.fsdecode(b"p\xfe.npz")]):
        code, out, err = run_cli(*args)
        assert code == 0, err
        out.encode("utf-8")  # strict: no lone surrogate reaches stdout
        assert json.loads(out)["input"] == str(weird)  # and the name comes back exactly
    code, out, err = run_cli("count", tmp_path / os.fsdecode(b"p\xfe.npz"), "--json")
    assert code == 1 and out == ""  # too short, but the error line holds the name without crashing
    assert "p\\xfe.npz" in _one_error(err)


def test_json_on_stdout_is_utf8_for_a_non_utf8_name_in_a_real_process(tmp_path, clip):
    weird = os.path.join(os.fsencode(tmp_path), b"b\xff.mkv")
    shutil.copy(clip, weird)
    out = subprocess.run([sys.executable, "-m", "wallcli", "snr", weird, "--json"], capture_output=True, timeout=120)
    assert out.returncode == 0, out.stderr
    doc = json.loads(out.stdout.decode("utf-8"))  # strict UTF-8 bytes
    assert os.fsencode(doc["input"]) == weird


# 5 ---------------------------------------------------------------------------- stdout failures
class _FullStdout:
    """A stdout on a full disk: writes are buffered, flush fails (as with `> /dev/full`)."""

    encoding = "utf-8"

    def write(self, text):
        return len(text)

    def flush(self):
        raise OSError(errno.ENOSPC, os.strerror(errno.ENOSPC))

    def isatty(self):
        return False


def _run_with_stdout(stdout, argv):
    from wallcli.cli.app import main

    real = sys.stdout
    sys.stdout = stdout
    try:
        main([str(a) for a in argv])
        return 0
    except SystemExit as exc:
        return exc.code
    finally:
        sys.stdout = real


@pytest.mark.parametrize("stdout", [_FullStdout(), None], ids=["full", "closed"])
def test_stdout_that_fails_is_one_error_line_and_no_output_file(tmp_path, capsys, clip, stdout):
    code = _run_with_stdout(stdout, ["stplot", clip, "-o", tmp_path / "p.npz", "--json", *FEW_BINS])
    err = capsys.readouterr().err
    reason = "no space left on device" if stdout is not None else "it is closed"
    assert code == 1 and _one_error(err) == f"Error: cannot write to stdout: {reason}"
    assert _files(tmp_path) == {"c.mkv"}  # p.npz went with the JSON that could not be written


def test_count_table_to_a_full_stdout(tmp_path, capsys):
    plot = write_plot(tmp_path / "p.npz")
    code = _run_with_stdout(_FullStdout(), ["count", plot, "--plot", tmp_path / "t.png"])
    assert code == 1 and "no space left on device" in _one_error(capsys.readouterr().err)
    assert _files(tmp_path) == {"p.npz"}


@pytest.mark.skipif(not os.path.exists("/dev/full"), reason="needs /dev/full")
def test_real_full_and_closed_stdout(tmp_path, clip):
    cmd = [sys.executable, "-m", "wallcli", "stplot", str(clip), "-o", str(tmp_path / "p.npz"), "--json", *FEW_BINS]
    with open("/dev/full", "w") as full:
        res = subprocess.run(cmd, stdout=full, stderr=subprocess.PIPE, text=True, timeout=120)
    assert res.returncode == 1 and res.stderr == "Error: cannot write to stdout: no space left on device\n"
    assert not (tmp_path / "p.npz").exists()
    res = subprocess.run([sys.executable, "-m", "wallcli", "snr", "--predict", "--json"], stderr=subprocess.PIPE,
                         text=True, timeout=120, preexec_fn=lambda: os.close(1))  # `>&-`
    assert res.returncode == 1 and res.stderr == "Error: cannot write to stdout: it is closed\n"


# 6 ------------------------------------------------------------------------------- model cards


@pytest.mark.parametrize("field,value", [
    ("fps", 0), ("fps", "abc"), ("fps", 1e9), ("fps", -30), ("fps", True), ("window", 0), ("window", 256.5),
    ("bins", "64"), ("stride", -1), ("classes", [0, 0, 1]), ("classes", [0]), ("name", ""), ("version", 3),
    ("sha256", "z" * 64), ("output", "probabilities"), ("validation.accuracy", "high"),
    ("validation.visible.accuracy_95ci", ["a", "b"]), ("validation.other_sets", {"x": 1}),
])
def test_card_fields_are_validated_with_a_message_naming_the_field(tmp_path, field, value):
    from wallcli.errors import WallcliError
    from wallcli.infer.card import read_card

    with pytest.raises(WallcliError) as info:
        read_card(model_with(tmp_path, **{field: value}))
    assert field.split(".")[-1] in str(info.value)


def test_card_nan_is_not_json(tmp_path):
    from wallcli.errors import WallcliError
    from wallcli.infer.card import read_card

    model = model_with(tmp_path)
    card = model.with_suffix(".json")
    card.write_text(card.read_text().replace('"fps": 30', '"fps": NaN'))
    with pytest.raises(WallcliError, match="NaN"):
        read_card(model)


def test_bad_card_through_the_cli_and_new_fields_are_welcome(tmp_path, run_cli):
    plot = write_plot(tmp_path / "p.npz")
    model = model_with(tmp_path, fps=0)
    code, out, err = run_cli("count", plot, "--model", model, "--json")
    assert code == 1 and out == "" and "'fps'" in _one_error(err)
    # fields a newer model owner adds (a transfer block, anything not read yet) are not refused
    model = model_with(tmp_path, transfer={"accuracy": 0.8, "renderer": "other"}, owner_notes={"x": [1, None]})
    code, out, err = run_cli("count", plot, "--model", model, "--json")
    assert code == 0, err
    assert json.loads(out)["model"]["name"] == "wallcli-count"


# 7 -------------------------------------------------------------------------- snr --predict ranges
@pytest.mark.parametrize("args", [
    ["--distance", "nan"], ["--albedo", "-3"], ["--pixels", "inf", "--mean-code", "100", "--gain", "4"],
    ["--frames", "-inf"], ["--gain", "0", "--mean-code", "100"], ["--bits", "99999999999999999999"],
    ["--sweep", "distance=nan:1:0.1"], ["--sweep", "distance=-1:1:0.5"], ["--sweep", "albedo=0:2:0.5"],
    ["--sweep", "distance=1:2:1e-300"], ["--sweep", "distance=-1e308:1e308:1"],
])
def test_predict_parameters_are_checked(run_cli, args):
    code, out, err = run_cli("snr", "--predict", "--json", *args)
    assert code == 2 and out == "", (args, err)
    _one_error(err)


def test_predict_sweep_values_obey_the_option_range(run_cli):
    code, out, err = run_cli("snr", "--predict", "--json", "--sweep", "albedo=0:1:0.25")
    assert code == 0, err
    assert json.loads(out)["sweep"]["values"] == [0.0, 0.25, 0.5, 0.75, 1.0]


# 8 ------------------------------------------------------------------------ signals at the end
LATE_SIGNAL = """
import os, signal, sys, time

class Late:  # destroyed with __main__'s globals, after Python has disabled its own signal handling
    def __del__(self, kill=os.kill, pid=os.getpid(), sig=signal.{sig}, sleep=time.sleep):
        kill(pid, sig)
        sleep(0.2)

late = Late()
sys.argv = ["wallcli", "snr", "--predict", "--json"]
from wallcli.cli.entry import main
main()
"""


@pytest.mark.parametrize("sig", ["SIGINT", "SIGTERM"])
def test_a_signal_during_shutdown_does_not_change_the_exit_code(sig):
    # before: Python had restored the default action, so the process died of the signal (130)
    res = subprocess.run([sys.executable, "-c", LATE_SIGNAL.format(sig=sig)], capture_output=True, text=True,
                         timeout=120)
    assert res.returncode == 0 and res.stderr == ""
    assert json.loads(res.stdout)["mode"] == "predict"


EARLY_SIGNAL = """
import builtins, os, signal

real = builtins.__import__

def hook(name, *args, **kwargs):  # Ctrl-C while the console script loads typer and the commands
    if name == "wallcli.cli.app":
        builtins.__import__ = real
        os.kill(os.getpid(), signal.SIGINT)
    return real(name, *args, **kwargs)

builtins.__import__ = hook
from wallcli.cli.entry import main
main()
"""


def test_a_signal_while_the_command_loads_exits_1_with_one_line():
    res = subprocess.run([sys.executable, "-c", EARLY_SIGNAL, "snr", "--predict"], capture_output=True, text=True,
                         timeout=120)
    assert res.returncode == 1 and res.stderr == "Error: interrupted\n" and res.stdout == ""


def test_main_gives_back_the_signal_handlers_it_found(run_cli):
    before = signal.getsignal(signal.SIGINT), signal.getsignal(signal.SIGTERM)
    run_cli("snr", "--predict", "--json")
    assert (signal.getsignal(signal.SIGINT), signal.getsignal(signal.SIGTERM)) == before
