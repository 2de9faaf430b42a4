"""evaluate reads only the clips inside its folder (issue 62 points 11 and 14): a labels row that
leads out of it, by name or by a link, is refused naming its row; a labels.csv that is a FIFO or a
device is named as such, not "no labels"."""
from __future__ import annotations

import os

import pytest

from wallcli.errors import WallcliError
from wallcli.evaluate.labels import read_labels


def _folder(tmp_path, row: str):
    d = tmp_path / "set"
    d.mkdir()
    (d / "a.mp4").write_bytes(b"a: not decoded here")
    (tmp_path / "walking.mp4").write_bytes(b"outside: not decoded here")
    (d / "labels.csv").write_text(f"file,people,activity\na.mp4,1,walking\n{row},1,walking\n")
    return d


@pytest.mark.parametrize("row", ["../walking.mp4", "{outside}", "/dev/zero", "sub/../../walking.mp4"])
def test_a_row_leading_out_of_the_folder_is_refused_naming_it(tmp_path, row, run_cli):
    d = _folder(tmp_path, row.format(outside=tmp_path / "walking.mp4"))
    with pytest.raises(WallcliError, match=r"labels.csv line 3 names .* which is outside"):
        read_labels(d)
    code, out, err = run_cli("evaluate", d, "--task", "count")
    assert code == 1 and out == "" and err.startswith("Error:") and len(err.splitlines()) == 1
    assert "line 3" in err and "outside" in err


def test_a_link_out_of_the_folder_is_refused_but_one_inside_is_read(tmp_path):
    d = _folder(tmp_path, "b.mp4")
    os.symlink(tmp_path / "walking.mp4", d / "b.mp4")
    with pytest.raises(WallcliError, match=r"line 3 names 'b.mp4', which is outside .*walking.mp4"):
        read_labels(d)
    (d / "b.mp4").unlink()
    (d / "real").mkdir()
    (d / "real" / "b.mp4").write_bytes(b"b: not decoded here")
    os.symlink(d / "real" / "b.mp4", d / "b.mp4")
    assert [c.file for c in read_labels(d).clips] == ["a.mp4", "b.mp4"]
    (d / "labels.csv").write_text(f"file,people,activity\n{d / 'a.mp4'},1,walking\n")  # absolute, but inside
    assert [c.file for c in read_labels(d).clips] == [str(d / "a.mp4")]


def test_a_sidecars_video_linked_out_of_the_folder_is_refused(tmp_path):
    d = tmp_path / "sims"
    d.mkdir()
    (tmp_path / "walking.mp4").write_bytes(b"x")
    os.symlink(tmp_path / "walking.mp4", d / "w.mp4")
    (d / "w.json").write_text('{"people": 1, "activity": "walking"}')
    with pytest.raises(WallcliError, match=r"w.json names 'w.mp4', which is outside"):
        read_labels(d)


def test_a_fifo_row_is_refused_not_read(tmp_path):
    d = _folder(tmp_path, "pipe.mp4")
    os.mkfifo(d / "pipe.mp4")
    with pytest.raises(WallcliError, match=r"line 3 names 'pipe.mp4', which is a FIFO"):
        read_labels(d)


@pytest.mark.parametrize("kind", ["fifo", "device"])
def test_labels_csv_that_is_not_a_file_is_named_not_missing(tmp_path, kind, run_cli):
    d = _folder(tmp_path, "a.mp4")
    (d / "labels.csv").unlink()
    if kind == "fifo":
        os.mkfifo(d / "labels.csv")
    else:
        os.symlink("/dev/zero", d / "labels.csv")
    code, out, err = run_cli("evaluate", d, "--task", "count")
    assert code == 1 and out == "" and len(err.splitlines()) == 1
    assert "labels.csv is not a regular file" in err and ("FIFO" if kind == "fifo" else "device") in err
    assert "has no labels" not in err
