"""The table view of ``wallcli evaluate``: per-clip rows, then the figures (all via output.py).

Every table fits 80 columns: the figures on top (bands, decided, confusion), then one line a clip
(the answer, '?' when undetermined, the truth, right or not, the SNR); what is long (why an
answer is undetermined) is in the JSON only.
"""
from __future__ import annotations

from wallcli.cli.output import print_lines, print_table

from wallcli.wording import BAND_TEXT as BAND_NAMES  # the figure's words too (plots/reliability.py)


def plural(n: int, noun: str) -> str:
    """'1 clip', '2 clips', '1 person', '2 people'."""
    return f"{n} {noun if n == 1 else {'person': 'people'}.get(noun, noun + 's')}"


def _pct(x: float | None, digits: int = 0) -> str:
    return "-" if x is None else f"{100 * x:.{digits}f} %"


def _of(k: int, n: int, digits: int = 0) -> str:
    """'3 (75 %)': k and its share of n."""
    return f"{k} ({_pct(k / n, digits)})" if n else "-"


def _snr(r: dict, labels: bool) -> str:
    # the figure the bands are on: labels.csv's SNR where it has the column, else the measured
    # column SNR (column_snr_db, the headline figure every command prints first)
    from wallcli.wording import format_db

    value = r.get("snr_db_labels", r["snr_db"]) if labels else r.get("column_snr_db")
    return "-" if value is None else format_db(value)


def _clips(res: dict, show_det: bool) -> None:
    """One line a clip: the answer ('?' after it when undetermined: most likely that), the truth,
    right or not, and the SNR its band is on. Reasons and errors are in the JSON, not here: a
    footnote a row made 265 lines of 120 clips."""
    labels = res["snr_source"] == "labels"
    figure = "SNR dB" if labels else "column SNR dB"  # each figure by its own name
    cols = ["file", "truth", "answer", "p %", "right", figure]
    if show_det:
        cols.insert(1, "det")
    rows = []
    for r in res["rows"]:
        if r["error"] is not None:
            answer = "error"
        else:
            answer = str(r["label"]) + ("" if r["confident"] is not False else " ?")
        p = "-" if not r["probabilities"] else f"{100 * max(r['probabilities']):.0f}"
        row = [r["file"], str(r["truth"]), answer, p, "yes" if r["correct"] else "no", _snr(r, labels)]
        if show_det:
            row.insert(1, {True: "yes", False: "no", None: "?"}[r["detectable"]])
        rows.append(row)
    m = res["model"]
    what = ("labels.csv snr_db (the bands' SNR)" if labels else
            "the measured column SNR, the figure every command prints first (column_snr_db; the bands are on it)")
    # what the columns mean above them, the title last: it is one unwrapped line right over its table
    print_lines(["?: undetermined, the most likely answer shown (why: --json, rows[].reason); "
                 f"p %: its probability; {figure}: {what}" + ("; det: labelled detectable" if show_det else "")])
    print_table(f"{res['task']} by {m['name']} {m['version']}, per clip", cols, rows, pad_edge=False)
    failed: dict[str, int] = {}
    for r in res["rows"]:
        if r["error"] is not None:
            failed[r["error"]] = failed.get(r["error"], 0) + 1
    print_lines([f"{plural(n, 'clip')} failed: {why}" for why, n in failed.items()], hang=2)


def _confusion(res: dict) -> None:
    classes = res["classes"]
    errs = any(res["errors_by_class"])
    rows = [[str(c), *(str(n) for n in res["confusion"][i]), *([str(res["errors_by_class"][i])] if errs else []),
             f"{pc['correct']}/{pc['clips']} {_pct(pc['accuracy'])}"]
            for i, (c, pc) in enumerate(zip(classes, res["per_class"]))]
    print_table(f"Confusion on {res['scored_on']} (rows: truth, columns: answer)",
                ["truth", *map(str, classes), *(["err"] if errs else []), "right"], rows)


def _bands(res: dict) -> None:
    rows = [[BAND_NAMES.get(b["band"], b["band"]), str(b["clips"]), _of(b["correct"], b["clips"]), str(b["decided"]),
             _of(b["correct_decided"], b["decided"])] for b in res["by_band"]]
    labels = res["snr_source"] == "labels"
    scored = plural(sum(b["clips"] for b in res["by_band"]), "scored clip")
    print_table(f"By {'SNR' if labels else 'column SNR'} band, all {scored} "
                f"({'SNR: labels.csv snr_db' if labels else 'measured column_snr_db'})",
                ["band", "clips", "right", "decided", "right of decided"], rows)
    lines = [] if labels else ["The labels give no snr_db: bands are on the measured column SNR (column_snr_db, the "
                               "figure every command prints first, on the labels' scale; see the column SNR column)."]
    if res.get("min_snr") is not None:
        lines.append(f"--min-snr {res['min_snr']:g}: {plural(res['excluded'], 'clip')} under {res['min_snr']:g} dB "
                     "left out of every figure")
    print_lines(lines)


def _summary(res: dict, show_det: bool) -> None:
    # one column per set of clips (narrow whatever the figures), one row per figure
    head = {k: res[k] for k in ("scored", "correct", "accuracy", "ci95", "decided", "correct_decided")}
    blocks = {res["scored_on"].split()[0]: dict(head, errors=sum(res["errors_by_class"]))}
    if show_det:
        blocks["all"] = res["all"]
    figures = [
        ("scored", lambda b: str(b["scored"])),
        ("right", lambda b: f"{b['correct']} ({_pct(b['accuracy'], 1)})"),
        ("95 % interval", lambda b: "-" if not b["ci95"] else f"{100 * b['ci95'][0]:.0f}-{100 * b['ci95'][1]:.0f} %"),
        ("decided", lambda b: _of(b["decided"], b["scored"])),
        ("right of decided", lambda b: _of(b["correct_decided"], b["decided"], 1)),
        ("errors", lambda b: str(b["errors"])),
    ]
    print_table("Summary (95 % interval: Clopper-Pearson; decided: not undetermined)",
                ["clips", *blocks], [[name, *(f(b) for b in blocks.values())] for name, f in figures])
    by_reason: dict[str, int] = {}
    for s in res.get("skipped_reasons", []):
        by_reason[s["reason"]] = by_reason.get(s["reason"], 0) + 1
    print_lines([f"{plural(n, 'clip')} skipped: {why}" for why, n in by_reason.items()])


def print_evaluation(res: dict) -> None:
    # the figures first (bands, then decided and right), the clips under them, one line each
    show_det = any(r["detectable"] is False for r in res["rows"])
    m = res["model"]
    # the folder on a line of its own, which may wrap: the title line never does (it is grepped)
    print_lines([f"{res['dir']} (labels: {res['labels']})"])
    print_lines([f"{res['task']} by {m['name']} {m['version']}, {plural(res['clips'], 'clip')}"])
    _bands(res)
    _summary(res, show_det)
    _confusion(res)
    _clips(res, show_det)
