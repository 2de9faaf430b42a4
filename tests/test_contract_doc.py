"""docs/contract.md, the output contract shipped with wallcli, against what the commands print.

Every field the document names for count, activity, snr, simulate and a scan's results line must
be in the real output of a clip made here (evaluate's fields: tests/evaluate). Fields the contract
already promises but no code writes yet are listed in PENDING; once one is written, the test asks
for it to leave the list, so the list only shrinks.
"""
import json
import re
from pathlib import Path

import pytest

DOC = Path(__file__).resolve().parents[1] / "docs" / "contract.md"
# promised by the contract, not written by this version (the nuisance corrections)
PENDING: set[str] = set()


def _sections() -> dict[str, str]:
    text = DOC.read_text(encoding="utf-8")
    parts = re.split(r"^## (.+)$", text, flags=re.M)
    return {title.strip(): body for title, body in zip(parts[1::2], parts[2::2])}


def _named_fields(body: str) -> set[str]:
    """Field names in a section: JSON keys of its examples and `"quoted"` names in its prose."""
    return set(re.findall(r'"([a-z_][a-z0-9_]*)"\s*:', body)) | set(re.findall(r'`"([a-z_][a-z0-9_]*)"', body))


def _keys(obj) -> set[str]:
    if isinstance(obj, dict):
        return set(obj) | set().union(*(_keys(v) for v in obj.values()))
    if isinstance(obj, list):
        return set().union(*(_keys(v) for v in obj)) if obj else set()
    return set()


@pytest.fixture(scope="module")
def outputs(tmp_path_factory):
    from wallcli.batch.task import ScanConfig, scan_video
    from wallcli.cli.app import main

    d = tmp_path_factory.mktemp("contract")
    clip = d / "clip.mp4"

    def run(*args):
        import contextlib
        import io

        buf = io.StringIO()
        with contextlib.redirect_stdout(buf), pytest.raises(SystemExit) as exc:
            main([str(a) for a in args])
        assert exc.value.code in (0, None), args
        return buf.getvalue()

    run("simulate", "-o", clip, "--people", "1", "--activity", "walking", "--seed", "5", "--size", "96x72",
        "--duration", "10.5", "--fps", "24", "--flicker", "0.01")  # 100 Hz at 24 fps: a 4 Hz line to correct
    out = {"simulate": json.loads(clip.with_suffix(".json").read_text())}
    for cmd in ("count", "activity", "snr"):
        out[cmd] = json.loads(run(cmd, clip, "--json"))
    out["track"] = json.loads(run("track", clip, "--json", "--view-width", "2.2"))
    out["scan"] = scan_video(str(clip), ScanConfig(tasks=("count", "activity", "snr")))
    return out


SECTIONS = {"count": "`wallcli count INPUT --json`", "activity": "`wallcli activity INPUT --json`",
            "snr": "`wallcli snr INPUT --json`", "track": "`wallcli track INPUT --json`", "simulate": "`wallcli simulate ... -o OUT`",
            "scan": "`wallcli scan INPUT... -o results.jsonl`",
            # count's own section, which activity ("As count") does not inherit
            "count_stages": "`wallcli count INPUT --json`: the two stages"}


@pytest.mark.slow
@pytest.mark.parametrize("name", list(SECTIONS))
def test_every_field_the_shipped_contract_names_is_written(name, outputs):
    sections = _sections()
    assert SECTIONS[name] in sections, f"docs/contract.md has no section {SECTIONS[name]}"
    named = _named_fields(sections[SECTIONS[name]])
    if name == "activity":  # "As count, with ...": count's fields too
        named |= _named_fields(sections[SECTIONS["count"]])
    written = _keys(outputs["count" if name == "count_stages" else name])
    missing = named - written - PENDING
    assert not missing, f"docs/contract.md names fields that `{name}` does not write: {sorted(missing)}"
    assert not (PENDING & written), f"now written, drop from PENDING: {sorted(PENDING & written)}"


def test_a_csv_row_holds_each_answer_with_the_signal_it_was_judged_on(outputs):
    """README: the CSV holds per row what the JSON line holds for each task's answer."""
    from wallcli.batch.results import csv_columns, flatten

    line = outputs["scan"]
    classes = {t: line[t]["classes"] for t in ("count", "activity")}
    cols = csv_columns(("count", "activity", "snr"), classes)
    row = dict(zip(cols, flatten(line, cols)))
    for task in ("count", "activity"):
        for field in ("label", "confident", "reason", "signal_db"):
            assert f"{task}.{field}" in cols
        assert float(row[f"{task}.signal_db"]) == line[task]["signal_db"]
        assert row[f"{task}.label"] == str(line[task]["label"])
