"""`wallcli simulate` at HD sizes and a chosen CRF (issue 27, point 3).

Short clips (a few frames) at 1280x720 and 1920x1080: the file decodes to that size and frame
count, x264 was run at the CRF asked for (it records its settings in the stream), the sidecar
says so, and a stronger CRF gives a smaller file of the same scene.
"""

import json
import re

import pytest

from wallcli.io.video import open_video

SHORT = ["--duration", "0.4", "--fps", "15", "--grid", "16x16", "--people", "1", "--seed", "5"]


def _decoded(path):
    with open_video(path) as r:
        shapes = [f.planes.rgb().shape for f in r.frames()]
        return r.info, shapes


def _x264_crf(path) -> float:
    """The rate factor x264 wrote into the stream's settings SEI (``... crf=23.0 ...``)."""
    m = re.search(rb"x264 - core .*? crf=([0-9.]+)", path.read_bytes())
    assert m, "no x264 settings in the stream"
    return float(m.group(1))


@pytest.mark.parametrize("w,h,crf", [(1280, 720, 28), (1920, 1080, 18)])
def test_simulate_hd_sizes_at_a_chosen_crf(tmp_path, run_cli, w, h, crf):
    out = tmp_path / f"hd{h}.mp4"
    code, _, err = run_cli("simulate", "-o", out, "--size", f"{w}x{h}", "--crf", str(crf), *SHORT)
    assert code == 0, err
    info, shapes = _decoded(out)
    assert (info.width, info.height) == (w, h)
    assert shapes == [(h, w, 3)] * 6  # 0.4 s at 15 fps
    assert _x264_crf(out) == crf
    truth = json.loads(out.with_suffix(".json").read_text())
    assert {k: truth[k] for k in ("people", "fps", "frames", "seed", "width", "height", "codec", "crf", "video")} == {
        "people": 1, "fps": 15.0, "frames": 6, "seed": 5, "width": w, "height": h, "codec": "libx264", "crf": crf,
        "video": out.name}
    assert (truth["camera"]["width"], truth["camera"]["height"], truth["camera"]["crf"]) == (w, h, crf)
    assert len(truth["persons"][0]["positions"]) == 6


def test_simulate_crf_changes_the_encoding_not_the_scene(tmp_path, run_cli):
    """The same seed at CRF 0 (lossless) and 28: same truth, and CRF 28 is the far smaller file."""
    paths = {}
    for crf in (0, 28):
        paths[crf] = tmp_path / f"c{crf}.mp4"
        code, _, err = run_cli("simulate", "-o", paths[crf], "--size", "1280x720", "--crf", str(crf), *SHORT)
        assert code == 0, err
    t0, t28 = (json.loads(p.with_suffix(".json").read_text()) for p in paths.values())
    assert {k: v for k, v in t0.items() if k != "crf"} | {"camera": None, "video": None} == \
        {k: v for k, v in t28.items() if k != "crf"} | {"camera": None, "video": None}
    assert paths[28].stat().st_size * 5 < paths[0].stat().st_size
    info, shapes = _decoded(paths[0])
    assert (info.width, info.height, len(shapes)) == (1280, 720, 6)


def test_simulate_refuses_odd_hd_size_for_h264(tmp_path, run_cli):
    code, _, err = run_cli("simulate", "-o", tmp_path / "x.mp4", "--size", "1281x720", *SHORT)
    assert code == 2 and "even" in err
