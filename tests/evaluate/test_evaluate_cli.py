"""`wallcli evaluate` end to end on a small simulated labelled folder: the figures must be exactly
what the single-video commands answer on the same clips; bad clips are rows, not crashes."""
from __future__ import annotations

import json
import shutil
from pathlib import Path

import pytest
from scenes import SCENES

CONTRACT = ("task", "model", "dir", "clips", "scored", "errors", "accuracy", "ci95", "decided", "coverage",
            "accuracy_decided", "classes", "confusion", "rows")
ROW = ("file", "truth", "label", "confident", "probabilities", "snr_db", "detectable", "error")


@pytest.mark.slow
def test_count_with_labels_csv_is_what_the_single_command_answers(labelled, single, run_cli, tmp_path):
    code, out, err = run_cli("evaluate", labelled, "--task", "count", "--json", "--jobs", "2",
                             "--plot", tmp_path / "rel.png")
    assert code == 0, err
    res = json.loads(out)
    assert all(k in res for k in CONTRACT) and "all" in res
    assert res["task"] == "count" and res["classes"] == [0, 1, 2] and res["dir"] == str(labelled)
    rows = {r["file"]: r for r in res["rows"]}
    assert [r["file"] for r in res["rows"]] == [f"{s}.mp4" for s, *_ in SCENES] + ["corrupt.mp4", "short.mp4", "gone.mp4"]
    assert all(set(ROW) <= set(r) for r in res["rows"])
    truth = {"empty.mp4": 0, "walk.mp4": 1, "jump.mp4": 1, "crouch.mp4": 1, "stand.mp4": 0, "two.mp4": 2}
    for name, t in truth.items():
        one = single["count", name]
        r = rows[name]
        assert (r["truth"], r["label"], r["probabilities"], r["error"]) == (t, one["label"], one["probabilities"], None)
        assert r["confident"] is one.get("confident", True)
    assert res["model"] == single["count", "walk.mp4"]["model"]
    for name in ("corrupt.mp4", "short.mp4", "gone.mp4"):
        r = rows[name]
        assert r["error"] and "\n" not in r["error"] and r["label"] is None and r["correct"] is False
    assert "too short" in rows["short.mp4"]["error"] and "no such file" in rows["gone.mp4"]["error"]
    assert res["clips"] == 9 and res["errors"] == 3

    # headline on detectable clips (crouch.mp4 is labelled 0), errors counted wrong
    head = [n for n in rows if n != "crouch.mp4"]
    right = sum(n in truth and rows[n]["label"] == truth[n] for n in head)
    assert res["scored"] == 8 and res["accuracy"] == pytest.approx(right / 8)
    confusion = [[0] * 3 for _ in range(3)]
    for n in head:
        if n in truth:
            confusion[truth[n]][single["count", n]["label"]] += 1
    assert res["confusion"] == confusion
    lo, hi = res["ci95"]
    assert 0 <= lo <= res["accuracy"] <= hi <= 1
    decided = [n for n in head if rows[n]["confident"] is True]
    assert res["decided"] == len(decided) and res["coverage"] == pytest.approx(len(decided) / 8)
    every = sum(n in truth and rows[n]["label"] == truth[n] for n in rows)
    assert res["all"]["scored"] == 9 and res["all"]["accuracy"] == pytest.approx(every / 9)
    assert sum(map(sum, res["all"]["confusion"])) == 6
    assert (tmp_path / "rel.png").stat().st_size > 10_000

    # the row's SNR is what `wallcli snr` measures at the row's block size, green channel
    code, out, err = run_cli("snr", labelled / "walk.mp4", "--json")
    scale = next(s for s in json.loads(out)["scales"] if s["block"] == rows["walk.mp4"]["snr_block"])
    assert rows["walk.mp4"]["snr_block"] == 8  # a 64x48 frame's plot bin: 1 x 48 pixels
    assert rows["walk.mp4"]["snr_db"] == pytest.approx(scale["snr_db"][1], rel=1e-9)


def test_activity_from_sidecars_skips_two_people_and_prints_a_table(sims, single, run_cli):
    code, out, err = run_cli("evaluate", sims, "--task", "activity", "--jobs", "1")
    assert code == 0, err
    assert "two.mp4" not in out and "1 clip skipped: more than one person" in " ".join(out.split())
    code, out, err = run_cli("evaluate", sims, "--task", "activity", "--json", "--jobs", "2")
    res = json.loads(out)
    assert "all" not in res and res["skipped"] == ["two.mp4"] and res["labels"] == "sidecars"
    names = sorted(f"{s}.mp4" for s, *_ in SCENES if s != "two")
    assert sorted(r["file"] for r in res["rows"]) == names
    for r in res["rows"]:
        one = single["activity", r["file"]]
        assert (r["label"], r["probabilities"]) == (one["label"], one["probabilities"])
    right = sum(single["activity", r["file"]]["label"] == r["truth"] for r in res["rows"])
    assert res["accuracy"] == pytest.approx(right / len(names)) and res["errors"] == 0
    assert {r["file"]: r["truth"] for r in res["rows"]}["stand.mp4"] == "none"
    k = res["classes"]
    assert sum(res["confusion"][k.index("walking")]) == 1


def test_count_from_sidecars_counts_only_movers(sims, single, run_cli):
    from wallcli.infer.model import shipped_model_path

    code, out, err = run_cli("evaluate", sims, "--task", "count", "--json", "--model", shipped_model_path("count"))
    assert code == 0, err
    rows = {r["file"]: r for r in json.loads(out)["rows"]}
    assert (rows["stand.mp4"]["truth"], rows["two.mp4"]["truth"], rows["walk.mp4"]["truth"]) == (0, 2, 1)
    assert all(r["label"] == single["count", n]["label"] for n, r in rows.items())


def test_a_folder_without_labels_fails_naming_what_it_looked_for(tmp_path, run_cli):
    shutil.copy(Path(__file__).resolve().parents[2] / "examples" / "walking.mp4", tmp_path / "a.mp4")
    (tmp_path / "notes.json").write_text('{"kind": "not a sidecar"}')
    code, out, err = run_cli("evaluate", tmp_path, "--task", "count")
    assert code == 1 and out == ""
    assert err.startswith("Error:") and "labels.csv" in err and "*.json" in err and len(err.splitlines()) == 1
    code, _, err = run_cli("evaluate", tmp_path / "nowhere", "--task", "count")
    assert code == 1 and "no such folder" in err


def test_bad_labels_and_usage(tmp_path, run_cli):
    (tmp_path / "labels.csv").write_text("file,people\na.mp4,1\n")
    code, _, err = run_cli("evaluate", tmp_path, "--task", "count")
    assert code == 1 and "activity" in err and "labels.csv" in err
    (tmp_path / "labels.csv").write_text("file,people,activity\na.mp4,one,walking\n")
    code, _, err = run_cli("evaluate", tmp_path, "--task", "count")
    assert code == 1 and "line 2" in err
    (tmp_path / "labels.csv").write_text("file,people,activity\na.mp4,1,running\n")
    code, _, err = run_cli("evaluate", tmp_path, "--task", "activity")
    assert code == 1 and "running" in err
    code, _, err = run_cli("evaluate", tmp_path, "--task", "age")
    assert code == 2


def test_one_decode_per_clip_gives_both_the_answer_and_the_snr(sims, single, monkeypatch):
    import wallcli.io.video as video
    from wallcli.evaluate.clip import measure_clip
    from wallcli.infer.twostage import load_classifier

    opened = []
    real = video.open_video
    monkeypatch.setattr(video, "open_video", lambda src, **kw: opened.append(src) or real(src, **kw))
    model = load_classifier("count")  # the two-stage count, as `wallcli count` answers
    out = measure_clip(model, sims / "walk.mp4", stride=int(model.card["stride"]))
    assert opened == [str(sims / "walk.mp4")]
    assert out["result"]["probabilities"] == single["count", "walk.mp4"]["probabilities"]
    assert out["snr_db"] > -99 and out["snr_block"] == 8


def test_an_roi_outside_every_frame_fails_the_run(sims, run_cli):
    code, out, err = run_cli("evaluate", sims, "--task", "count", "--roi", "0,0,500,500", "--jobs", "1")
    assert code == 1 and out == "" and "none of the 6 clips" in err and "64x48" in err


def test_a_damaged_sidecar_skips_its_clip_with_a_warning(sims, run_cli, tmp_path):
    for stem in ("empty", "walk"):
        for ext in (".mp4", ".json"):
            shutil.copy(sims / f"{stem}{ext}", tmp_path / f"{stem}{ext}")
    (tmp_path / "walk.json").write_text("{bad")
    code, out, err = run_cli("evaluate", tmp_path, "--task", "count", "--json", "--jobs", "1")
    assert code == 0, err
    res = json.loads(out)
    assert res["clips"] == 1 and [r["file"] for r in res["rows"]] == ["empty.mp4"] and res["skipped"] == ["walk.mp4"]
    (why,) = res["skipped_reasons"]
    assert why["file"] == "walk.mp4" and why["reason"].startswith("damaged sidecar: walk.json")
    assert "Warning: walk.mp4 skipped: damaged sidecar: walk.json" in " ".join(err.split())
