"""Decided or undetermined on real (simulated) clips: the shipped models' confident flag."""
import json

import pytest

STRONG = ["--people", "1", "--activity", "walking", "--seed", "11", "--size", "128x96", "--duration", "10.5",
          "--fps", "30", "--distance", "1,1.6", "--crf", "0", "--iso-gain", "0.02", "--read-noise", "0.5",
          "--sensor-pixels", "1000000"]
FAR = ["--people", "1", "--activity", "waving", "--seed", "12", "--size", "96x72", "--duration", "10.5",
       "--fps", "24", "--distance", "9,10", "--crf", "24", "--iso-gain", "1.0", "--read-noise", "3",
       "--sensor-pixels", "40000"]


@pytest.fixture(scope="module")
def clips(tmp_path_factory):
    from wallcli.cli.app import main

    d = tmp_path_factory.mktemp("confident")
    out = {}
    for name, opts in (("strong", STRONG), ("far", FAR)):
        path = d / f"{name}.mp4"
        with pytest.raises(SystemExit) as exc:
            main(["simulate", "-o", str(path), *opts])
        assert exc.value.code in (0, None)
        out[name] = path
    return out


@pytest.mark.parametrize("task", ["count", "activity"])
def test_a_strong_walker_is_decided_and_a_person_far_out_of_range_is_not(task, clips, run_cli):
    strong = json.loads(run_cli(task, clips["strong"], "--json")[1])
    far = json.loads(run_cli(task, clips["far"], "--json")[1])
    assert strong["label"] == (1 if task == "count" else "walking")
    assert strong["confident"] is True and strong["reason"] is None
    assert far["confident"] is False and isinstance(far["reason"], str) and far["reason"]
    for r in (strong, far):
        assert all(isinstance(w["confident"], bool) for w in r["windows"])
        assert all((w["reason"] is None) == w["confident"] for w in r["windows"])
    # the table shows the undecided answer as such, with its reason
    code, out, err = run_cli(task, clips["far"])
    assert code == 0 and "undetermined (" in out
