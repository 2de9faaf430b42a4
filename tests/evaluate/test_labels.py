"""Reading a folder's labels: one clip named two ways."""
from __future__ import annotations

import pytest

from wallcli.errors import WallcliError
from wallcli.evaluate.labels import read_labels


def _folder(tmp_path, csv_text: str, videos=("a.mp4", "b.mp4")):
    for v in videos:
        (tmp_path / v).write_bytes(b"not decoded here")
    (tmp_path / "labels.csv").write_text(csv_text)
    return tmp_path


@pytest.mark.parametrize("other", ["./a.mp4", "sub/../a.mp4", "{dir}/a.mp4"])
def test_one_clip_named_two_ways_is_a_duplicate(tmp_path, other, run_cli):
    d = _folder(tmp_path, f"file,people,activity\na.mp4,1,walking\nb.mp4,0,none\n{other.format(dir=tmp_path)},1,walking\n")
    with pytest.raises(WallcliError, match="twice: line 2 .'a.mp4'. and line 4"):
        read_labels(d)
    code, out, err = run_cli("evaluate", d, "--task", "count")
    assert code == 1 and out == "" and err.startswith("Error:") and len(err.splitlines()) == 1
