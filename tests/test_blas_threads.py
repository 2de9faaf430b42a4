"""The CLI holds OpenBLAS to one thread before numpy loads (issue 60): its helper threads spun on the small
matrices numpy hands it here (activity: 1.2 CPU s of a 900-frame 1080p clip). A user's own setting is kept."""
from __future__ import annotations

import os
import subprocess
import sys

PROBE = ("import os, sys; from wallcli.cli import entry; loaded = 'numpy' in sys.modules; entry._one_blas_thread(); "
         "import numpy; print(loaded, os.environ.get('OPENBLAS_NUM_THREADS'))")


def _run(**env) -> str:
    base = {k: v for k, v in os.environ.items() if k not in ("OPENBLAS_NUM_THREADS", "OMP_NUM_THREADS")}
    out = subprocess.run([sys.executable, "-c", PROBE], env=base | env, capture_output=True, text=True, check=True)
    return out.stdout.strip()


def test_one_thread_set_before_numpy_loads():
    # numpy reads the variable once, when it loads: the entry module must not have loaded it yet
    assert _run() == "False 1"


def test_the_users_setting_is_kept():
    assert _run(OPENBLAS_NUM_THREADS="3") == "False 3"
    assert _run(OMP_NUM_THREADS="2") == "False None"


def test_the_console_script_path_sets_it(tmp_path):
    # python -m wallcli goes through the same entry: a command runs with the variable in its environment
    code = ("import os, runpy, sys; sys.argv = ['wallcli', '--version']\n"
            "try:\n    runpy.run_module('wallcli', run_name='__main__')\nexcept SystemExit:\n    pass\n"
            "print(os.environ.get('OPENBLAS_NUM_THREADS'))")
    base = {k: v for k, v in os.environ.items() if k not in ("OPENBLAS_NUM_THREADS", "OMP_NUM_THREADS")}
    out = subprocess.run([sys.executable, "-c", code], env=base, capture_output=True, text=True, check=True)
    assert out.stdout.strip().splitlines()[-1] == "1"
