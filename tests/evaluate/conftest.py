"""Small simulated labelled folders for the evaluate tests, made once per session (simulating
them is most of these tests' time)."""
from __future__ import annotations

import json
import shutil

import pytest

from scenes import SCENES, SMALL, cli


@pytest.fixture(scope="session")
def sims(tmp_path_factory):
    """Simulated clips with their sidecars (the sidecar mode's folder)."""
    d = tmp_path_factory.mktemp("sims")
    for stem, people, act, seed in SCENES:
        code, _ = cli("simulate", "-o", d / f"{stem}.mp4", "--people", people, "--activity", act,
                       "--seed", seed, *SMALL)
        assert code == 0
    return d


@pytest.fixture(scope="session")
def single(sims):
    """What `wallcli count/activity CLIP --json` answer on each clip."""
    out = {}
    for task in ("count", "activity"):
        for stem, *_ in SCENES:
            code, text = cli(task, sims / f"{stem}.mp4", "--json")
            assert code == 0
            out[task, f"{stem}.mp4"] = json.loads(text)
    return out


@pytest.fixture(scope="session")
def labelled(sims, tmp_path_factory):
    """The same clips with a labels.csv, plus a corrupt clip, a too-short one and a missing one."""
    d = tmp_path_factory.mktemp("labelled")
    lines = ["file,people,activity,detectable,lighting"]
    for stem, people, act, _ in SCENES:
        shutil.copy(sims / f"{stem}.mp4", d / f"{stem}.mp4")
        moving = sum(a != "none" for a in act.split(","))
        det = 0 if stem == "crouch" else 1
        lines.append(f"{stem}.mp4,{moving},{'mixed' if people == 2 else act},{det},lamp")
    data = (sims / "walk.mp4").read_bytes()
    (d / "corrupt.mp4").write_bytes(data[: len(data) // 3])  # cut short: the index (moov) at the end is lost
    code, _ = cli("simulate", "-o", d / "short.mp4", "--duration", "3", "--size", "64x48", "--grid", "8x8")
    assert code == 0
    lines += ["corrupt.mp4,1,walking,1,lamp", "short.mp4,1,walking,1,lamp", "gone.mp4,0,none,1,lamp"]
    (d / "labels.csv").write_text("\n".join(lines) + "\n")
    return d
