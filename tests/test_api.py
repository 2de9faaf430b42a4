"""The Python API (wallcli/api.py, docs/api.md): its functions give what the commands print, the
commands go through them, docs/api.md's examples run as written, and ``import wallcli`` stays cheap."""
from __future__ import annotations

import doctest
import json
import re
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

ROOT = Path(__file__).resolve().parents[1]
CLIP = ROOT / "examples" / "walking.mp4"


def test_import_wallcli_loads_nothing_heavy():
    code = ("import sys, wallcli; "
            "print(sorted(m for m in ('numpy', 'av', 'onnxruntime', 'matplotlib', 'wallcli.api', 'wallcli.snr') "
            "if m in sys.modules)); print(sorted(set(wallcli.API) & set(dir(wallcli))))")
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=60, cwd=ROOT / "tests")
    assert out.returncode == 0, out.stderr
    assert out.stdout.split("\n")[:2] == ["[]", str(sorted(["count", "activity", "track", "stplot", "snr"]))]


def test_snr_is_the_function_and_the_subpackage():
    import wallcli
    import wallcli.snr.estimate as estimate  # the subpackage imported by name still works

    assert callable(wallcli.snr) and wallcli.snr.estimate is estimate
    from wallcli import count, snr, track

    assert callable(snr) and count is wallcli.count and track.__module__ == "wallcli.api"


def _spy(monkeypatch, name):
    """Record the calls the CLI makes to wallcli.api.NAME (and let them through)."""
    import wallcli.api as api

    calls = []
    real = getattr(api, name)

    def spy(*args, **kwargs):
        calls.append(args)
        return real(*args, **kwargs)

    monkeypatch.setattr(api, name, spy)
    return calls


@pytest.mark.parametrize("task,through,kw,args", [
    ("count", "classify", {}, []),
    ("activity", "classify", {"stride": 128}, ["--stride", "128"]),
    ("track", "track_clip", {}, []),
    ("snr", "measure_snr", {}, []),
    ("snr", "measure_snr", {"roi": "auto"}, ["--roi", "auto"]),
])
def test_api_equals_the_commands_json(run_cli, monkeypatch, task, through, kw, args):
    import wallcli

    code, out, err = run_cli(task, CLIP, "--json", *args)
    assert code == 0, err
    mine = getattr(wallcli, task)(str(CLIP), **kw)
    assert mine == json.loads(out)
    assert json.loads(json.dumps(mine)) == mine  # plain JSON types, no NaN
    calls = _spy(monkeypatch, through)  # the command is a layer over the same function
    code, out2, _ = run_cli(task, CLIP, "--json", *args)
    assert code == 0 and len(calls) == 1 and json.loads(out2) == mine


def test_api_stplot_equals_the_npz_and_count_reads_it_alike(run_cli, monkeypatch, tmp_path):
    import wallcli

    calls = _spy(monkeypatch, "compute_plot")
    npz = tmp_path / "p.npz"
    code, _, err = run_cli("stplot", CLIP, "--roi", "90,40,70,70", "-o", npz)
    assert code == 0 and len(calls) == 1, err
    mine = wallcli.stplot(str(CLIP), roi=(90, 40, 70, 70))
    with np.load(npz, allow_pickle=False) as z:
        assert set(z.files) == set(mine)
        for k in set(z.files) - {"meta"}:
            assert mine[k].dtype == z[k].dtype and np.array_equal(mine[k], z[k]), k
        assert json.loads(str(z["meta"])) == mine["meta"]
    code, out, err = run_cli("count", npz, "--json")
    assert code == 0 and wallcli.count(str(npz)) == json.loads(out)


def test_api_bad_input_raises_the_command_s_error(tmp_path):
    import wallcli
    from wallcli.errors import WallcliError

    with pytest.raises(WallcliError, match="no such file") as e:
        wallcli.track(str(tmp_path / "none.mp4"))
    assert e.value.exit_code == 1
    with pytest.raises(ValueError, match="four integers"):
        wallcli.stplot(str(CLIP), roi=(1, 2, 3))


def _examples(text: str) -> str:
    """The ```pycon blocks of a Markdown page, one after another."""
    return "\n".join(re.findall(r"^```pycon\n(.*?)^```", text, flags=re.S | re.M))


def test_docs_api_examples_run_as_written(monkeypatch):
    page = (ROOT / "docs" / "api.md").read_text(encoding="utf-8")
    source = _examples(page)
    assert source.count(">>>") >= 15 and "wallcli.snr(" in source and "wallcli.stplot(" in source
    monkeypatch.chdir(ROOT)  # the page's paths are the checkout's, as its readers run them
    parser = doctest.DocTestParser()
    test = parser.get_doctest(source, {}, "docs/api.md", str(ROOT / "docs" / "api.md"), 0)
    runner = doctest.DocTestRunner(optionflags=doctest.ELLIPSIS | doctest.NORMALIZE_WHITESPACE)
    runner.run(test)
    res = runner.summarize(verbose=False)
    assert res.attempted == source.count(">>>") and res.failed == 0


def test_readme_links_the_api_page():
    readme = (ROOT / "README.md").read_text(encoding="utf-8")
    assert "(docs/api.md)" in readme
