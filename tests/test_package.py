"""What ships: the models folder installs as ``wallcli.models``, so any .py left there would be
installed too. Only the models, their cards, their README and the package marker may ship;
experiments live in research/ (issue 19)."""
from __future__ import annotations

import fnmatch
import shutil
import subprocess
import sys
import zipfile
from importlib import resources
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
SHIPPED_GLOBS = ("__init__.py", "*.onnx", "*.json", "*.md")


def _allowed(name: str) -> bool:
    return any(fnmatch.fnmatch(name, g) for g in SHIPPED_GLOBS)


def test_models_folder_holds_no_script_and_ships_only_models_and_cards():
    tomllib = pytest.importorskip("tomllib")  # Python >= 3.11
    cfg = tomllib.loads((ROOT / "pyproject.toml").read_text())["tool"]["setuptools"]
    assert cfg["package-dir"]["wallcli.models"] == "models"
    assert not any(p == "research" or p.startswith("research.") for p in cfg["packages"])
    scripts = sorted(p.name for p in (ROOT / "models").glob("*.py") if p.name != "__init__.py")
    assert scripts == [], f"experiment scripts in models/ would be installed: {scripts} (move them to research/)"
    assert all(_allowed(g) for g in cfg["package-data"]["wallcli.models"])
    assert (ROOT / "research" / "README.md").is_file()


def test_every_folder_of_the_package_is_declared():
    """setuptools treats any folder under a package as a package; one missing from `packages`
    (templates/, a folder of data) made every install print a 40-line warning."""
    tomllib = pytest.importorskip("tomllib")
    packages = set(tomllib.loads((ROOT / "pyproject.toml").read_text())["tool"]["setuptools"]["packages"])
    folders = {".".join(d.relative_to(ROOT).parts) for d in (ROOT / "wallcli").rglob("*")
               if d.is_dir() and d.name != "__pycache__" and any(f.is_file() for f in d.iterdir())}
    assert sorted(folders - packages) == []


def test_installed_models_package_holds_models_cards_and_nothing_else():
    pkg = Path(str(resources.files("wallcli.models")))
    if pkg.resolve() == (ROOT / "models").resolve():
        pytest.skip("editable install: the package is the source folder (the wheel test covers it)")
    names = {p.name for p in pkg.iterdir() if p.name != "__pycache__"}
    assert {"__init__.py", "count.onnx", "count.json", "activity.onnx", "activity.json"} <= names
    assert sorted(n for n in names if not _allowed(n)) == []


def _setuptools_can_build() -> bool:
    try:
        import setuptools
    except ImportError:
        return False
    return int(setuptools.__version__.split(".")[0]) >= 77  # pyproject's build requirement


@pytest.mark.skipif(not _setuptools_can_build(), reason="needs setuptools >= 77 to build offline")
def test_built_wheel_ships_no_experiment_scripts(tmp_path):
    # build from a copy: a build in place would leave build/ and egg-info in the checkout
    src = tmp_path / "src"
    src.mkdir()
    for name in ("pyproject.toml", "README.md"):
        shutil.copy(ROOT / name, src / name)
    ignore = shutil.ignore_patterns("__pycache__", "*.egg-info")
    for name in ("wallcli", "models", "research"):
        shutil.copytree(ROOT / name, src / name, ignore=ignore)
    subprocess.run([sys.executable, "-m", "pip", "wheel", "-q", "--no-deps", "--no-build-isolation",
                    "-w", str(tmp_path / "dist"), str(src)], check=True, capture_output=True)
    (wheel,) = (tmp_path / "dist").glob("wallcli-*.whl")
    files = zipfile.ZipFile(wheel).namelist()
    models = sorted(f.split("/", 2)[2] for f in files if f.startswith("wallcli/models/"))
    assert {"count.onnx", "count.json", "activity.onnx", "activity.json", "__init__.py"} <= set(models)
    assert [m for m in models if not _allowed(m)] == []
    assert not [f for f in files if f.startswith("research/")]
    py = [f for f in files if f.endswith(".py")]
    assert all(f.startswith("wallcli/") for f in py), py
