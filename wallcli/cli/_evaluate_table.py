"""The table view of ``wallcli evaluate``: per-clip rows, then the figures (all via output.py)."""
from __future__ import annotations

from typing import Any

from wallcli.cli.output import print_lines, print_table

BAND_NAMES = {"empty": "empty rooms", "<0 dB": "under 0 dB", "0-10 dB": "0-10 dB", ">=10 dB": "10 dB and over",
              "not measured": "SNR unknown"}


def plural(n: int, noun: str) -> str:
    """'1 clip', '2 clips', '1 person', '2 people'."""
    return f"{n} {noun if n == 1 else {'person': 'people'}.get(noun, noun + 's')}"


def _pct(x: float | None, digits: int = 0) -> str:
    return "-" if x is None else f"{100 * x:.{digits}f} %"


def _ci(iv) -> str:
    return "" if not iv else f" ({100 * iv[0]:.0f}-{100 * iv[1]:.0f})"


def _of(k: int, n: int, digits: int = 0) -> str:
    """'3 (75 %)': k and its share of n."""
    return f"{k} ({_pct(k / n, digits)})" if n else "-"


def _answer(r: dict) -> str:
    if r["error"] is not None:
        return "error (below)"
    if r["confident"] is False:
        return f"undetermined ({r.get('reason') or 'no reason given'})"
    return str(r["label"])


def _snr(r: dict) -> str:
    return "-" if r["snr_db"] is None else f"{r['snr_db']:.1f}"


def _bands(res: dict) -> None:
    rows = [[BAND_NAMES.get(b["band"], b["band"]), str(b["clips"]), _of(b["correct"], b["clips"]), str(b["decided"]),
             _of(b["correct_decided"], b["decided"])] for b in res["by_band"]]
    labels = res["snr_source"] == "labels"
    print_table(f"By SNR band, all {plural(sum(b['clips'] for b in res['by_band']), 'scored clip')} "
                f"(SNR: {'labels.csv snr_db' if labels else 'measured'})",
                ["band", "clips", "right", "decided", "right of decided"], rows)
    lines = [] if labels else ["The labels give no snr_db: bands are on the measured SNR (see the SNR column)."]
    if res.get("min_snr") is not None:
        lines.append(f"--min-snr {res['min_snr']:g}: {plural(res['excluded'], 'clip')} under {res['min_snr']:g} dB "
                     "left out of every figure")
    print_lines(lines)


def print_evaluation(res: dict) -> None:
    classes = res["classes"]
    given = "all" in res
    m = res["model"]
    # a detectable column only where it tells the rows apart; probabilities in % to fit 80 columns
    show_det = any(r["detectable"] is False for r in res["rows"])
    cols = ["file", "truth", "answer", "p %", "SNR dB", "ok"]
    if show_det:
        cols.insert(1, "det.")
    rows = []
    for r in res["rows"]:
        p = "-" if not r["probabilities"] else " ".join(f"{100 * x:.0f}" for x in r["probabilities"])
        row = [r["file"], str(r["truth"]), _answer(r), p, _snr(r), "yes" if r["correct"] else "no"]
        if show_det:
            row.insert(1, {True: "yes", False: "no", None: "?"}[r["detectable"]])
        rows.append(row)
    print_table(f"{res['dir']}: {res['task']} by {m['name']} {m['version']}, {res['clips']} clips "
                f"(labels: {res['labels']}); p % of " + ", ".join(map(str, classes)), cols, rows)

    failed = [[r["file"], r["error"]] for r in res["rows"] if r["error"] is not None]
    if failed:
        print_table("Clips that failed (each counts as a wrong answer)", ["file", "error"], failed)

    on = res["scored_on"]
    errs = any(res["errors_by_class"])
    conf = [[str(c), *(str(n) for n in res["confusion"][i]), *([str(res["errors_by_class"][i])] if errs else []),
             f"{pc['correct']}/{pc['clips']} {_pct(pc['accuracy'])}{_ci(pc['ci95'])}"]
            for i, (c, pc) in enumerate(zip(classes, res["per_class"]))]
    print_table(f"Confusion on {on} (rows: truth, columns: answer; accuracy with its 95 % Wilson interval)",
                ["truth", *map(str, classes), *(["error"] if errs else []), "accuracy"], conf)

    _bands(res)

    def figures(block: dict, ci: Any) -> list[str]:
        return [str(block["scored"]), f"{block['correct']}/{block['scored']} {_pct(block['accuracy'], 1)}{_ci(ci)}",
                f"{block['decided']} ({_pct(block['coverage'])})", _pct(block["accuracy_decided"], 1),
                str(block["errors"])]

    head = {"scored": res["scored"], "correct": res["correct"], "accuracy": res["accuracy"],
            "decided": res["decided"], "coverage": res["coverage"], "accuracy_decided": res["accuracy_decided"],
            "errors": sum(res["errors_by_class"])}
    lines = [[on, *figures(head, res["ci95"])]]
    if show_det:
        lines.append(["all clips", *figures(res["all"], res["all"]["ci95"])])
    title = "Summary (accuracy: 95 % bootstrap interval over clips; decided: answers not undetermined)"
    two = sum(s["reason"].startswith("more than one person") for s in res["skipped_reasons"])
    if two:
        title += f"; {two} clips of more than one person skipped"
    if len(res["skipped"]) > two:
        title += f"; {len(res['skipped']) - two} clips with a damaged sidecar skipped"
    print_table(title, ["clips", "scored", "right", "decided", "right of decided", "errors"], lines)
