"""Issue #54, as a new user meets it: the README's and --help's lines, and what the tool prints."""

import re
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from clips import write_clip

ROOT = Path(__file__).resolve().parent.parent


def _wall(i, _base=np.random.default_rng(0).uniform(80, 160, (64, 80, 3))):
    return _base + 3 * np.sin(i / 3)


@pytest.mark.parametrize("codec,warned", [("mpeg4", True), ("ffv1", False)])
def test_a_reencoded_stream_on_stdin_is_warned_of_once(tmp_path, codec, warned):
    """`ffmpeg -i SRC -f nut -` re-encodes to MPEG-4 Part 2 and the answers change: a stream on
    stdin in such a codec gets one warning saying to copy it; a lossless one gets none."""
    path = write_clip(tmp_path / f"{codec}.nut", _wall, 60, codec=codec, fmt="nut", options={})
    with open(path, "rb") as fh:
        out = subprocess.run([sys.executable, "-m", "wallcli", "snr", "-", "--json"], stdin=fh,
                             capture_output=True, text=True, timeout=120)
    assert out.returncode == 0, out.stderr
    said = [line for line in out.stderr.splitlines() if "-c copy" in line]
    assert len(said) == (1 if warned else 0), out.stderr
    if warned:
        assert said[0].startswith("Warning: -: ") and "mpeg4" in said[0]


def test_every_ffmpeg_pipe_line_copies_the_stream(run_cli):
    """Every `ffmpeg ... -f nut -` line a user reads (README, docs, --help) copies the stream."""
    texts = {p.name: p.read_text() for p in [ROOT / "README.md", *(ROOT / "docs").glob("*.md"),
                                             *(ROOT / "examples").glob("*.sh")]}
    for command in ("count", "activity", "stplot", "scan"):
        code, out, err = run_cli(command, "--help")
        assert code == 0
        texts[f"{command} --help"] = out + err
    lines = [(name, line) for name, text in texts.items() for line in text.splitlines()
             if re.search(r"ffmpeg .*-f (nut|mpegts|matroska) -", line)]
    assert len(lines) >= 4  # the README's two and count's, activity's and stplot's
    assert [(n, line) for n, line in lines if "-c copy" not in line] == []


@pytest.mark.parametrize("k,n", [(6, 6), (0, 6), (3, 4), (1, 2), (128, 179), (47, 60)])
def test_the_exact_interval_is_clopper_pearsons(k, n):
    """The beta quantiles Clopper and Pearson defined, which scipy gives (a test need only)."""
    beta = pytest.importorskip("scipy.stats").beta
    from wallcli.evaluate.score import exact_ci

    lo = 0.0 if k == 0 else beta.ppf(0.025, k, n - k + 1)
    hi = 1.0 if k == n else beta.ppf(0.975, k + 1, n - k)
    assert exact_ci(k, n) == pytest.approx([lo, hi], abs=1e-9)


def _right(file, label, snr):
    return {"file": file, "truth": label, "label": label, "confident": True, "probabilities": [0.05, 0.9, 0.05],
            "snr_db": snr, "detectable": None, "error": None, "reason": None}


def test_six_of_six_right_is_not_a_100_to_100_interval(capsys):
    """evaluate's JSON and table: 6 right of 6 is 54-100 %, in the headline, decided and bands."""
    from wallcli.cli._evaluate_table import print_evaluation
    from wallcli.evaluate.run import report

    rows = [_right(f"{i}.mp4", 1, 3.0 + i) for i in range(6)]
    res = report(rows, task="count", model={"name": "m", "version": "1", "sha256": "0"}, classes=[0, 1, 2],
                 folder="d", labels="labels.csv", skipped=[], stride=64, roi=None)
    assert res["ci95"] == pytest.approx([0.025 ** (1 / 6), 1.0])
    assert res["ci95_decided"] == res["ci95"] and res["interval"]["method"] == "clopper-pearson"
    one = next(c for c in res["per_class"] if c["class"] == 1)
    assert one["ci95"] == res["ci95"]
    print_evaluation(res)
    out = " ".join(capsys.readouterr().out.split())
    assert "54-100 %" in out and "100-100 %" not in out


@pytest.mark.parametrize("name", ["empty", "walking", "jumping"])
def test_snr_verdict_text_quotes_the_figure_its_json_gives(run_cli, name):
    """jumping.mp4's JSON gave snr_db 5.02 (at 2x2) while its text said "green 6.5 dB" (1x1)."""
    import json

    from wallcli.wording import format_db

    code, out, err = run_cli("snr", ROOT / "examples" / f"{name}.mp4", "--json")
    assert code == 0, err
    verdict = json.loads(out)["verdict"]
    block = verdict["block"]
    assert f"green {format_db(verdict['snr_db'])} dB" in verdict["text"] and f"{block}x{block}" in verdict["text"]
    assert "dB" not in verdict["text"].replace(f"{format_db(verdict['snr_db'])} dB", "")  # no other figure


def test_the_rendered_clips_are_never_called_plain_recordings():
    """"The recordings are 220 labelled clips of an independent path-traced renderer" read as camera
    footage beside the report's "never from real recordings"; docs/outputs.md said 120 clips."""
    import json

    free_text = []
    for card in ("count", "activity"):
        def strings(x):
            if isinstance(x, str):
                free_text.append(x)
            elif isinstance(x, dict):
                [strings(v) for v in x.values()]
            elif isinstance(x, list):
                [strings(v) for v in x]
        strings(json.loads((ROOT / "models" / f"{card}.json").read_text()))
    texts = {"cards": "\n".join(free_text),
             **{str(p.relative_to(ROOT)): p.read_text() for p in [
                 ROOT / "README.md", ROOT / "models" / "README.md", *(ROOT / "docs").glob("*.md"),
                 *(ROOT / "wallcli" / "report" / "templates").glob("*.j2")]}}
    plain = re.compile(r"(?<![/`._\w-])(?:the|\d+) recordings(?![/`._\w-])|labelled recordings of", re.I)
    said = {name: plain.findall(" ".join(text.split())) for name, text in texts.items()}
    assert {name: found for name, found in said.items() if found} == {}
    assert "real recordings" not in texts["wallcli/report/templates/clip.html.j2"]
    assert "120 clips" not in texts["docs/outputs.md"]
    assert re.search(r"\(\d{3} clips from an independent path-traced renderer", texts["docs/outputs.md"])


def test_install_hints_name_what_pip_can_find(monkeypatch, run_cli, tmp_path):
    """`pip install 'wallcli[train]'` fails (wallcli is not on the index): the error without torch,
    train --help, simulate --help and the docs say what works: the extra's own packages (as
    pyproject.toml lists them), or '.[extra]' from the checkout's top folder."""
    tomllib = pytest.importorskip("tomllib")  # Python 3.11+
    extras = tomllib.loads((ROOT / "pyproject.toml").read_text())["project"]["optional-dependencies"]
    monkeypatch.setitem(sys.modules, "torch", None)  # import torch -> ImportError, torch or not
    code, _, err = run_cli("train", "count", "--data", tmp_path, "--out", tmp_path / "m.onnx")
    assert code == 1 and err.startswith("Error:") and err.count("\n") == 1
    assert "pip install torch==2.13.0 && pip install '.[train]'" in err and "checkout" in err
    said = [err, run_cli("train", "--help")[1], run_cli("simulate", "--help")[1],
            *(p.read_text() for p in [ROOT / "README.md", *(ROOT / "docs").glob("*.md")])]
    assert not [t for t in said if "wallcli[" in t]
    from wallcli import extras as hints

    for hint, extra in ((hints.TRAIN, "train"), (hints.ONNX, "train"), (hints.PT, "pt")):
        assert f"'.[{extra}]'" in hint
        named = set(re.findall(r"([a-z]+)(?:==|>=)[\d.]+", hint))
        assert named and named <= {re.match(r"[a-z]+", d).group(0) for d in extras[extra]}


def _jq_lines(text: str) -> list[str]:
    """jq commands as a reader copies them: from `jq` to the line that ends with the results file."""
    lines, out = text.splitlines(), []
    for i, line in enumerate(lines):
        if line.strip().startswith("jq "):
            cmd = [line.strip()]
            while not cmd[-1].endswith("results.jsonl"):
                i += 1
                cmd.append(lines[i].strip())
            out.append(" ".join(cmd))
    return out


def test_scans_documented_jq_lines_print_the_best_guess(tmp_path, run_cli):
    """docs/scan.md's line printed `? ?` and scan --help's `undetermined` for every bundled clip (the
    models decide nothing): each now prints the answer, or the most likely one marked undetermined."""
    import json
    import shutil

    if shutil.which("jq") is None:
        pytest.skip("jq is not installed here")
    folder = tmp_path / "clips"
    folder.mkdir()
    for name in ("empty", "walking"):
        (folder / f"{name}.mp4").symlink_to(ROOT / "examples" / f"{name}.mp4")
    code, _, err = run_cli("scan", folder, "-o", tmp_path / "results.jsonl", "--task", "count,activity",
                           "--workers", "1")
    assert code == 0, err
    results = [json.loads(line) for line in (tmp_path / "results.jsonl").read_text().splitlines()]
    lines = _jq_lines((ROOT / "docs" / "scan.md").read_text()) + _jq_lines(run_cli("scan", "--help")[1])
    assert len(lines) == 2
    for line in lines:
        p = subprocess.run(["bash", "-o", "pipefail", "-c", line], cwd=tmp_path, capture_output=True, text=True,
                           timeout=60)
        assert p.returncode == 0, (line, p.stderr)
        rows = {r.split("\t")[0]: r.split("\t")[1:] for r in p.stdout.splitlines()}
        for res in results:
            for cell, task in zip(rows[res["input"]], ("count", "activity")):
                label = str(res[task]["label"])
                assert cell == label if res[task]["confident"] else cell == f"undetermined, most likely {label}"


def test_scans_csv_keeps_the_snr_verdict_and_the_views_notes(tmp_path, run_cli):
    """The CSV's columns ended `snr.scales,view.usable,view.issues,view.reason`: the verdict line snr
    leads with and the view's notes (crouching.mp4: a sharp shadow in view) were JSON-only."""
    import csv
    import json

    folder = tmp_path / "clips"
    folder.mkdir()
    for name in ("crouching", "jumping"):
        (folder / f"{name}.mp4").symlink_to(ROOT / "examples" / f"{name}.mp4")
    for out in ("r.jsonl", "r.csv"):
        code, _, err = run_cli("scan", folder, "-o", tmp_path / out, "--task", "snr", "--workers", "1")
        assert code == 0, err
    lines = {d["input"]: d for d in map(json.loads, (tmp_path / "r.jsonl").read_text().splitlines())}
    rows = {r["input"]: r for r in csv.DictReader(open(tmp_path / "r.csv", newline=""))}
    assert rows.keys() == lines.keys()
    for name, line in lines.items():
        row, verdict = rows[name], line["snr"]["verdict"]
        assert row["snr.verdict.text"] == verdict["text"] and row["snr.verdict.block"] == str(verdict["block"])
        assert row["snr.verdict.signal"] == str(verdict["signal"]).lower()
        assert float(row["snr.verdict.snr_db"]) == pytest.approx(verdict["snr_db"])
        assert json.loads(row["view.notes"]) == line["view"]["notes"]
    assert any(json.loads(r["view.notes"]) for r in rows.values())  # crouching's shadow, at least


@pytest.mark.parametrize("command", ["count", "activity", "snr"])
def test_the_terminal_says_the_views_notes_the_json_has(run_cli, command):
    """crouching.mp4's view notes a sharp shadow ("sharp shadow or light in view ...") in the JSON and
    the report; the terminal's table said nothing of it."""
    import json

    clip = ROOT / "examples" / "crouching.mp4"
    code, out, err = run_cli(command, clip, "--json")
    assert code == 0, err
    notes = json.loads(out)["view"]["notes"]
    assert notes and notes[0].startswith("sharp shadow or light in view")
    code, out, err = run_cli(command, clip)
    assert code == 0, err
    flat = " ".join(out.split())
    assert all(" ".join(n.split()) in flat for n in notes) and "no fault of the view" in flat


def test_the_report_leads_its_snr_section_with_snrs_verdict(tmp_path, run_cli):
    """`wallcli snr` leads with its verdict; the single-clip report's table had no such line."""
    import html
    import json

    clip = ROOT / "examples" / "jumping.mp4"
    code, out, err = run_cli("snr", clip, "--json")
    assert code == 0, err
    verdict = json.loads(out)["verdict"]
    code, _, err = run_cli("report", clip, "-o", tmp_path / "r.html")
    assert code == 0, err
    page = (tmp_path / "r.html").read_text(encoding="utf-8")
    said = re.search(r'<p class="verdict" id="snr-verdict">(.*?)</p>', page, re.S)
    assert said and f"Block SNR verdict: {verdict['text']}." in html.unescape(said.group(1))


def test_activitys_reason_is_the_one_that_decided(run_cli):
    """crouching.mp4 (one person) said only "two people possible (p=0.05 ...)", while the card's
    thresholds leave every answer undetermined anyway: their reason comes first, the check after."""
    import json

    from wallcli.wording import format_db

    code, out, err = run_cli("activity", ROOT / "examples" / "crouching.mp4", "--json")
    assert code == 0, err
    res = json.loads(out)
    for r in [res, *res["windows"]]:
        assert r["confident"] is False and not r["reason"].startswith("two people")
        assert f"signal {format_db(r['signal_db'])} dB" in r["reason"] and "validation" in r["reason"]
        assert r["reason"].endswith(f"two people possible too (p={r['two_people']:.2f} of two among people moving)")


def test_the_two_people_check_alone_is_the_reason_where_the_card_would_decide():
    """Where the card's thresholds would decide, the two-people check is what leaves the answer
    undetermined, and its reason stands alone; where it passes, the card's verdict stands."""
    from wallcli.infer.judge import _gate
    from wallcli.infer.twostage import two_people_reason

    class Gated:  # the shape of OnePersonActivity, as far as _gate reads it
        classes = ["none", "walking"]

        def __init__(self, p_two):
            self.p_two = p_two

        def gate(self, raw, label):
            return self.p_two, (two_people_reason(self.p_two, 0.97) if self.p_two >= 0.03 else None)

    probs = np.array([0.01, 0.99])
    assert _gate(Gated(0.2), None, probs, True, None) == (False, two_people_reason(0.2, 0.97))
    assert _gate(Gated(0.01), None, probs, True, None) == (True, None)
    assert _gate(Gated(0.01), None, probs, False, "card's reason") == (False, "card's reason")
    assert _gate(Gated(0.6), None, probs, False, "card's reason") == \
        (False, "card's reason; two people likely too (p=0.60 of two among people moving)")


def test_evaluates_measured_bands_are_on_the_column_snr(tmp_path, capsys):
    """walking.mp4: block SNR 6.8 dB, the answer's signal_db -3.4 dB and the headline column SNR
    19.1 dB. Without an snr_db column the bands are on the column SNR (issue 61.1: the figure every
    command prints first, on the labels' scale), neither of the other two."""
    from wallcli.cli._evaluate_table import print_evaluation
    from wallcli.evaluate.labels import Clip
    from wallcli.evaluate.run import _row, report

    clip = Clip("walking.mp4", tmp_path / "walking.mp4", 1, "walking", None, 1)
    answer = {"label": 1, "confident": False, "probabilities": [0.0, 1.0, 0.0], "signal_db": -3.41,
              "reason": "'1 person' at signal -3.4 dB: ... (97 % needed; under 0 dB)", "column_snr_db": 19.12}
    row = _row(clip, {"result": answer, "snr_db": 6.8, "snr_block": 8}, "count", has_snr=False)
    assert (row["band"], row["column_snr_db"], row["signal_db"], row["snr_db"]) == (">=10 dB", 19.12, -3.41, 6.8)
    labelled = Clip("walking.mp4", tmp_path / "walking.mp4", 1, "walking", None, 1, snr_db=12.0)
    assert _row(labelled, {"result": answer, "snr_db": 6.8}, "count", has_snr=True)["band"] == ">=10 dB"
    res = report([row], task="count", model={"name": "m", "version": "1", "sha256": "0"}, classes=[0, 1, 2],
                 folder="d", labels="labels.csv", skipped=[], stride=64, roi=None)
    assert [b["clips"] for b in res["by_band"]] == [0, 0, 0, 1] and res["band_measure"].startswith("column_snr_db")
    assert (res["snr_source"], res["snr_figure"]) == ("measured", "column_snr_db")
    print_evaluation(res)
    out = " ".join(capsys.readouterr().out.split())
    assert "By column SNR band" in out and "walking.mp4 1 1 ? 100 yes 19.1" in out and "column SNR dB" in out


def test_amplify_names_its_own_snr(tmp_path, run_cli):
    """amplify's snr_db is the display's blocks' SNR, a fourth figure: it is also given under a name
    that says so, with what it measures."""
    import json

    clip = write_clip(tmp_path / "w.mkv", _wall, 90, codec="ffv1", options={})
    code, out, err = run_cli("amplify", clip, tmp_path / "a.mp4", "--cells", "8", "--json")
    assert code == 0, err
    res = json.loads(out)
    assert res["display_snr_db"] == res["snr_db"] is not None
    assert res["snr_measure"].startswith("display SNR") and "signal_db" in res["snr_measure"]
