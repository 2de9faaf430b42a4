#!/usr/bin/env bash
# The test command: a fresh virtual environment, wallcli installed as users install it
# (a real `pip install .`, not editable, so packaging and shipped models are tested too),
# then the whole suite. Extra arguments go to pytest.
set -euo pipefail
cd "$(dirname "$0")/.."
venv="${WALLCLI_TEST_VENV:-.venv-test}"
python3 -m venv "$venv"
"$venv/bin/python" -m pip install -q --upgrade pip
# torch first, pinned: its CPU build; the train extra's range then installs nothing more.
"$venv/bin/python" -m pip install -q torch==2.13.0
"$venv/bin/python" -m pip install -q ".[test,train]"
# Run from tests/ so the source tree's wallcli/ does not shadow the installed package.
cd tests && exec "../$venv/bin/python" -m pytest -q -p no:cacheprovider "$@"
