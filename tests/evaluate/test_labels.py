"""Reading a folder's labels: one clip named two ways, the snr_db column, damaged sidecars."""
from __future__ import annotations

import json

import pytest

from wallcli.errors import WallcliError
from wallcli.evaluate.labels import read_labels


def _folder(tmp_path, csv_text: str, videos=("a.mp4", "b.mp4")):
    for v in videos:
        (tmp_path / v).write_bytes(f"{v}: not decoded here".encode())  # two copies of one are one clip
    (tmp_path / "labels.csv").write_text(csv_text)
    return tmp_path


@pytest.mark.parametrize("other", ["./a.mp4", "sub/../a.mp4", "{dir}/a.mp4"])
def test_one_clip_named_two_ways_is_a_duplicate(tmp_path, other, run_cli):
    d = _folder(tmp_path, f"file,people,activity\na.mp4,1,walking\nb.mp4,0,none\n{other.format(dir=tmp_path)},1,walking\n")
    with pytest.raises(WallcliError, match="twice: line 2 .'a.mp4'. and line 4"):
        read_labels(d)
    code, out, err = run_cli("evaluate", d, "--task", "count")
    assert code == 1 and out == "" and err.startswith("Error:") and len(err.splitlines()) == 1


def test_snr_db_column_is_read_and_an_empty_cell_is_an_empty_room(tmp_path):
    d = _folder(tmp_path, "file,people,activity,snr_db\na.mp4,1,walking,-3.5\nb.mp4,0,none,\n")
    labels = read_labels(d)
    assert labels.has_snr and [c.snr_db for c in labels.clips] == [-3.5, None]
    assert [c.empty("count") for c in labels.clips] == [False, True]
    (d / "labels.csv").write_text("file,people,activity\na.mp4,1,walking\n")
    assert not read_labels(d).has_snr and read_labels(d).clips[0].snr_db is None


@pytest.mark.parametrize("cell,message", [("", "empty 'snr_db' where people = 2"), ("nan", "'snr_db' must be a number"),
                                          ("inf", "'snr_db' must be"), ("loud", "'snr_db' must be")])
def test_bad_snr_cells_name_the_line(tmp_path, cell, message):
    d = _folder(tmp_path, f"file,people,activity,snr_db\nb.mp4,0,none,\na.mp4,2,mixed,{cell}\n")
    with pytest.raises(WallcliError, match=f"line 3: {message}"):
        read_labels(d)


def test_a_damaged_sidecar_beside_its_video_is_reported_not_dropped(tmp_path):
    for stem in ("a", "b", "c"):
        (tmp_path / f"{stem}.mp4").write_bytes(b"x")
    (tmp_path / "a.json").write_text("{bad")
    (tmp_path / "b.json").write_text(json.dumps({"people": 1, "activity": "walking", "activities": ["walking"]}))
    (tmp_path / "c.json").write_text(json.dumps({"people": 1}))
    (tmp_path / "notes.json").write_text("{also bad, but no video of that name: not a sidecar")
    labels = read_labels(tmp_path)
    assert [c.file for c in labels.clips] == ["b.mp4"]
    assert [f for f, _ in labels.damaged] == ["a.mp4", "c.mp4"]
    assert "a.json" in labels.damaged[0][1] and "'activity'" in labels.damaged[1][1]
    (tmp_path / "b.json").write_text("[")
    with pytest.raises(WallcliError, match="3 damaged"):
        read_labels(tmp_path)
