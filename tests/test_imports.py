"""The house has no circles: no two modules of wallcli import each other, directly or round a
loop, counting imports inside functions too (sim/pathtrace.py and sim/scene.py once did: a scene
describes, a world renders it), and the method's folders stand on each other in one order: none
imports a folder above it, and only the CLI knows the CLI."""
from __future__ import annotations

import ast
from pathlib import Path

PACKAGE = Path(__file__).resolve().parents[1] / "wallcli"


def _imports() -> dict[str, set[str]]:
    """{module: the wallcli modules it imports anywhere in its file}."""
    files = {}
    for p in PACKAGE.rglob("*.py"):
        parts = p.relative_to(PACKAGE.parent).with_suffix("").parts
        files[".".join(parts[:-1] if parts[-1] == "__init__" else parts)] = p
    edges: dict[str, set[str]] = {m: set() for m in files}
    for m, p in files.items():
        package = m if p.name == "__init__.py" else m.rpartition(".")[0]
        for node in ast.walk(ast.parse(p.read_text(encoding="utf-8"))):
            if isinstance(node, ast.Import):
                names = [a.name for a in node.names]
            elif isinstance(node, ast.ImportFrom):
                base = node.module or ""
                if node.level:
                    up = package.split(".")[: len(package.split(".")) - node.level + 1]
                    base = ".".join(up + ([base] if base else []))
                names = [base] + [f"{base}.{a.name}" for a in node.names]
            else:
                continue
            for name in names:
                while name and name not in files:
                    name = name.rpartition(".")[0]
                if name and name != m and not m.startswith(name + "."):  # a package's own __init__ is no loop
                    edges[m].add(name)
    return edges


def _loops(edges: dict[str, set[str]]) -> list[list[str]]:
    """Strongly connected groups of more than one module (Tarjan)."""
    index: dict[str, int] = {}
    low: dict[str, int] = {}
    stack: list[str] = []
    loops: list[list[str]] = []

    def visit(v: str) -> None:
        index[v] = low[v] = len(index)
        stack.append(v)
        for w in edges[v]:
            if w not in index:
                visit(w)
                low[v] = min(low[v], low[w])
            elif w in stack:
                low[v] = min(low[v], index[w])
        if low[v] == index[v]:
            group = []
            while True:
                w = stack.pop()
                group.append(w)
                if w == v:
                    break
            if len(group) > 1:
                loops.append(sorted(group))

    for v in edges:
        if v not in index:
            visit(v)
    return loops


def test_no_module_imports_itself_round_a_loop():
    edges = _imports()
    assert "wallcli.sim.pathtrace" in edges and edges["wallcli.cli.app"]  # the walk sees the package
    assert _loops(edges) == []


def test_the_scene_does_not_know_the_path_tracer():
    edges = _imports()
    assert "wallcli.sim.pathtrace" not in edges["wallcli.sim.scene"]
    assert "wallcli.sim.scene" not in edges["wallcli.sim.pathtrace"]


# The method's folders, ground floor first: each may import only the ones named (and itself), so a
# frame's way runs one way: decode (io) -> the camera's artefacts out (camera) -> is the view usable
# (view) / how strong is the signal (snr) -> plots and windows (signal) above them all.
# signal/ is the ground of the method (block sums, Roi) that camera/, view/ and snr/ stand on.
MAY_IMPORT = {
    "errors": set(),
    "wording": set(),
    "io": {"errors"},
    "signal": {"errors", "wording"},
    "camera": {"errors", "wording", "signal"},
    "view": {"errors", "wording", "signal", "camera"},
    "snr": {"errors", "wording", "signal", "camera"},
}


def _folder(module: str) -> str:
    """wallcli.view.check -> 'view'; wallcli.errors -> 'errors'; the package itself -> ''."""
    return module.split(".")[1] if "." in module else ""


def test_the_method_s_folders_never_climb():
    edges = _imports()
    climbs = sorted(f"{m} -> {t}" for m, targets in edges.items() for t in targets
                    if _folder(m) in MAY_IMPORT and _folder(t) not in MAY_IMPORT[_folder(m)] | {_folder(m), ""})
    assert climbs == []


def test_only_the_cli_knows_the_cli():
    edges = _imports()
    assert sorted(f"{m} -> {t}" for m, targets in edges.items() for t in targets
                  if _folder(t) == "cli" and _folder(m) not in {"cli", "__main__"}) == []


# Start-up (issue 60 point 3): a command imports only what it uses. The heavy optional packages
# never load on the analysis commands' path, the models' runtime stays off the commands that run
# no net, and each net's session is built once.
_PROBE = r"""
import contextlib, importlib.abc, importlib.util, io, json, sys
built = []


class _Watch(importlib.abc.MetaPathFinder):
    # counts the sessions built, without importing onnxruntime before the command does
    def find_spec(self, name, path, target=None):
        if name != "onnxruntime":
            return None
        sys.meta_path.remove(self)
        spec = importlib.util.find_spec(name)
        run = spec.loader.exec_module

        def exec_module(module):
            run(module)
            init = module.InferenceSession.__init__

            def counted(self, *a, **k):
                built.append(1)
                init(self, *a, **k)
            module.InferenceSession.__init__ = counted
        spec.loader.exec_module = exec_module
        return spec


sys.meta_path.insert(0, _Watch())
from wallcli.cli.app import main
with contextlib.redirect_stdout(io.StringIO()), contextlib.redirect_stderr(io.StringIO()):
    try:
        main(sys.argv[1:])
    except SystemExit as exc:
        assert not exc.code, exc.code
print(json.dumps({"modules": sorted({m.split(".")[0] for m in sys.modules}), "sessions": len(built)}))
"""
HEAVY = {"matplotlib", "dask", "distributed", "jinja2", "torch", "pandas", "scipy", "sklearn"}
EXAMPLE = PACKAGE.parent / "examples" / "walking.mp4"


def _loaded(*args: str) -> dict:
    import json
    import subprocess
    import sys

    out = subprocess.run([sys.executable, "-c", _PROBE, *args], capture_output=True, text=True, timeout=300)
    assert out.returncode == 0, out.stderr
    return json.loads(out.stdout.strip().splitlines()[-1])


def test_the_analysis_commands_import_only_what_they_use(tmp_path):
    for cmd, nets in (("count", 2), ("activity", 2), ("track", 0), ("stplot", 0)):
        args = [cmd, str(EXAMPLE)] + (["-o", str(tmp_path / "p.npz"), "--force"] if cmd == "stplot" else ["--json"])
        got = _loaded(*args)
        assert HEAVY & set(got["modules"]) == set(), cmd
        assert ("onnxruntime" in got["modules"]) == bool(nets), cmd
        assert got["sessions"] == nets, cmd  # count's two-stage rule: the count net and the activity net, once each


def test_the_import_probe_sees_a_heavy_import(tmp_path):
    # the probe must be able to fail: a plot's PNG is drawn with matplotlib, and the probe sees it
    got = _loaded("stplot", str(EXAMPLE), "-o", str(tmp_path / "p.npz"), "--png", str(tmp_path / "p.png"), "--force")
    assert "matplotlib" in got["modules"]
