"""The one implementation behind ``wallcli count`` and ``wallcli activity``.

Both commands differ only in the task name (which selects the shipped model and the
classes), so each is a thin typer function calling :func:`run`.
"""
from __future__ import annotations

from pathlib import Path
from typing import Optional

import typer

from wallcli.cli.common import (PNG_NAME, ROI_HELP, check_png_names, corrections_of, deflicker_option, exposure_option, force_help, input_argument,
                                shake_option,
                                number_option, parse_roi, refuse_view, strict_option, threads_option)

INPUT_HELP = "Video (file, http(s)/rtsp URL, '-' for a stream on stdin) or a .npz from 'wallcli stplot'."
STRIDE_OPT = number_option(None, "--stride", lo=1, hi=65536, integer=True,
                           help="Frames (at 30 fps) between window starts. Default: the model card's (64, 2.13 s). "
                                "The last window ends at the clip's end, so its start is off the stride.")
JSON_OPT = typer.Option(False, "--json", help="Print one JSON object on stdout (see docs/contract.md).")
PLOT_OPT = typer.Option(None, "--plot", help="Draw class probabilities over time above the space-time plot to this PNG "
                        "(for a video, the plot drawn is averaged down to at most 2048 time columns). " + PNG_NAME)
MODEL_OPT = typer.Option(None, "--model", help="Your own .onnx model; its card (same name, .json) must be beside it.")
ACTIVITY_MODEL_OPT = typer.Option(None, "--activity-model", help="The activity model of the two-stage count's "
                                  "presence stage (default: the shipped one). Answers are decided only with the "
                                  "pair the count card was calibrated with.")
SINGLE_STAGE_OPT = typer.Option(False, "--single-stage", help="Count with the count net alone (the paper's "
                                "design: the horizontal plot only), not in two stages.")
THREADS_OPT = threads_option("onnxruntime intra-op threads (0: onnxruntime chooses).")
VERBOSE_OPT = typer.Option(False, "--verbose", "-v", help="Also print, on stderr, how often the model was right in "
                           "validation (its card's figures, on simulated and independently rendered clips) and where "
                           "each window's reason is. Without it: the table and one line saying why the answer is "
                           "decided or not.")
FOLLOW_OPT = typer.Option(False, "--follow", help="Live or growing input: print one JSON line per window as soon as it is complete (JSON Lines, with or without --json).")
# 15 s: three times the 5 s many recorders flush at (at 5 s a recorder flushing every 5 s was taken
# for finished after its second flush)
IDLE_OPT = number_option(15.0, "--idle-timeout", lo=0, hi=1e6,
                         help="With --follow on a file: keep reading it as a recorder writes it, and end when it "
                              "has not grown for this many seconds (or for 3 times its longest pause so far).")
ROI_OPT = typer.Option(None, "--roi", help=ROI_HELP)
FORCE_OPT = typer.Option(False, "--force", help=force_help("the --plot file"))
INPUT_ARG = input_argument(INPUT_HELP)
STRICT_OPT = strict_option()
NO_DEFLICKER_OPT = deflicker_option()
NO_EXPOSURE_OPT = exposure_option()
NO_SHAKE_OPT = shake_option()


def run(task: str, input: str, *, stride: Optional[int], json_out: bool, plot: Optional[Path],
        model_path: Optional[Path], threads: int, follow: bool, roi: Optional[str], force: bool,
        strict: bool = False, no_deflicker: bool = False, no_exposure: bool = False,
        no_shake: bool = False, stream: Optional[int] = None, activity_model: Optional[Path] = None,
        single_stage: bool = False, verbose: bool = False, stall_timeout: Optional[float] = None,
        idle_timeout: float = 15.0) -> None:
    from wallcli.cli.common import use_stream
    from wallcli.errors import UsageError

    use_stream(stream, stall_timeout, live=follow)
    if follow:
        from wallcli.io.video import FOLLOW_IDLE

        FOLLOW_IDLE.set(float(idle_timeout))
    roi_t = parse_roi(roi)
    fixes = corrections_of(no_deflicker, no_exposure, no_shake)
    if follow and plot is not None:
        raise UsageError("--plot needs the whole clip; it cannot be combined with --follow")
    if follow and str(input).lower().endswith(".npz"):
        raise UsageError("--follow reads live video; a .npz space-time plot is already complete")

    from wallcli.cli.output import emit_json, progress
    from wallcli.io.writer import check_outputs, committed_together

    from wallcli.api import classify, load_model
    from wallcli.infer.model import shipped_model_path

    # the models and their cards are inputs too: --plot over any must not replace it (a two-stage
    # count reads the activity model as well)
    reads = [input, model_path or shipped_model_path(task)]
    if task == "count" and not single_stage:
        reads.append(activity_model or shipped_model_path("activity"))
    check_png_names(("--plot", plot))
    if task == "activity":  # its answers are checked by the count net for two people
        reads.append(shipped_model_path("count"))
    check_outputs([plot], force=force, inputs=reads)
    model = load_model(task, model_path, threads=threads, activity_model=activity_model, single_stage=single_stage)
    stride = int(stride or model.card["stride"])

    if follow:
        from wallcli.infer.classify import follow as follow_windows

        for rec in follow_windows(model, input, stride=stride, roi=roi_t, corrections=fixes):
            if strict:
                refuse_view(input, rec.get("view"))
            emit_json(rec)
        return

    # the Python API's own path (wallcli.api.classify); a video shows progress, a .npz is read at once
    if str(input).lower().endswith(".npz"):
        result, st = classify(model, input, stride=stride, roi=roi_t, corrections=fixes)
    else:
        with progress(task, None) as advance:
            result, st = classify(model, input, stride=stride, roi=roi_t, progress=advance,
                                  keep_plot=plot is not None, corrections=fixes)
    if strict:
        refuse_view(input, result.get("view"))
    with committed_together():  # the figure and the data on stdout: all or none
        _report(task, input, model, result, st, plot, json_out, force, verbose=verbose)
    from wallcli.cli.output import wrote

    wrote((plot, "class probabilities over time above the horizontal space-time plot"))


def _report(task, input, model, result, st, plot, json_out, force, *, verbose: bool = False) -> None:
    from wallcli.cli.output import emit_json, log, print_lines, print_table

    if plot is not None:
        from wallcli.plots.timeline import save_timeline_png

        save_timeline_png(plot, result, st, force=force)
    # the model card's figures are for a reader who asks (-v), on stderr: not on every call
    note = accuracy_note(model.card, single_stage=task == "count" and model.single,
                         unvalidated=getattr(model, "unvalidated", None)) if verbose else None
    if json_out:
        emit_json(result)
        if note:
            log(note)
        return
    # one row per window (each lasts window/fps seconds from its start) and the clip's answer;
    # no 'end' column, and reasons under the table, so that five classes fit 80 columns
    from wallcli.wording import answer_text, decided_text, format_db, label_text, view_note_lines

    def shown(r):  # an answer that may not be relied upon is not shown as one
        return str(r["label"]) if r.get("confident", True) else "undetermined"

    def row(first, r):
        return [first, shown(r), format_db(r.get("signal_db")), *(f"{p:.3f}" for p in r["probabilities"])]

    # the headline figure is the title's first figure (the title stays the first line, for grep);
    # the table's figure is the models' own, headed by its JSON name
    from wallcli.snr.column import column_text

    headline = f"; {column_text(result['column_snr_db'])}" if "column_snr_db" in result else ""

    rows = [row(f"{w['start']:.2f}", w) for w in result["windows"]] + [row("clip", result)]
    span = result["window"] / result.get("window_fps", result["fps"])  # fps: the video's rate
    n = len(result["windows"])
    print_table(f"{input}: {task} = {answer_text(result)}; {n} window{'' if n == 1 else 's'} of {span:.2f} s{headline}",
                ["start (s)", "answer", "signal_db", *map(label_text, result["classes"])], rows)
    # one line under the table: why the clip's answer is decided or not
    if result.get("confident") is True:
        level = (model.card.get("confidence") or {}).get("level")
        print_lines([f"{decided_text(level)}."])
    elif result.get("confident") is False:
        print_lines([f"undetermined: {result.get('reason') or 'no reason given'}."])
    # what the view check saw but did not refuse (a sharp shadow in view): the JSON's view.notes
    print_lines(view_note_lines(result.get("view")))
    if note:
        if any(not w.get("confident", True) for w in result["windows"]):
            log("Each window's reason: --json (windows[].reason).")
        log(note)


def decides_nothing(card: dict, single_stage: bool = False) -> bool:
    """True while no cell of the card's trust thresholds holds a threshold (every one null, or no
    thresholds at all): then no answer can be decided, whatever the clip."""
    two = card.get("two_stage") if isinstance(card.get("two_stage"), dict) else {}
    block = card.get("confidence") if single_stage or not two else two.get("confidence")
    rows = block.get("thresholds") if isinstance(block, dict) else None
    if not isinstance(rows, list):
        return True
    return all(t is None for row in rows for t in (row if isinstance(row, list) else [row]))


NOTHING_DECIDED = ("Today no answer is decided: the shipped model's card sets no threshold that its "
                   "validation backs, so every answer is undetermined (\"confident\": false), its label the "
                   "model's best guess; read that as a guess, not a finding (README, 'What the answers "
                   "mean'; docs/adapt.md earns decided answers on recordings of your own site).")


def trust_help(task: str) -> str:
    """The help's sentence on what may be relied upon, read from the shipped card at help time, so
    that it says 'nothing is decided' exactly as long as that is true."""
    import json
    from importlib import resources

    # as wallcli.infer.model.shipped_model_path finds it, without importing numpy at every start
    try:
        res = resources.files("wallcli.models") / f"{task}.json"
        path = Path(str(res)) if res.is_file() else Path(__file__).resolve().parents[2] / "models" / f"{task}.json"
        card = json.loads(path.read_text(encoding="utf-8"))
    except (OSError, ValueError, ModuleNotFoundError, TypeError):
        return "Rely on decided answers only (\"confident\": true)."
    return NOTHING_DECIDED if decides_nothing(card) else "Rely on decided answers only (\"confident\": true)."


def accuracy_note(card: dict, single_stage: bool = False, unvalidated: str | None = None) -> str | None:
    """One line saying how far the model's answers can be trusted, from its card's validation.

    Printed with -v (to stderr, for the reader, not for scripts; not on every call, where it was
    six lines under every table): a probability of 0.9 from a model that is right on 64 % of
    windows is not a 90 % answer. An unvalidated card (``unvalidated``: why, infer/trust.py) has
    no figure worth quoting: the line says so instead.
    """
    if unvalidated:
        return (f"{card.get('name', 'model')} {card.get('version', '')}: {unvalidated}; none of its "
                "validation figures are quoted and no answer is decided.")
    tr = card.get("transfer") or {}
    if single_stage and tr.get("stages"):  # the card's headline is the two-stage count's, not this net's alone
        tr = card.get("transfer_single_stage") or {}
    if isinstance(tr.get("accuracy"), (int, float)) and isinstance(tr.get("scored"), int):
        # what users meet first: clips from a renderer the model never saw
        iv = tr.get("ci95")
        ci = f" (95 % CI {iv[0]:.0%}-{iv[1]:.0%})" if isinstance(iv, list) and len(iv) == 2 else ""
        dec = ""
        if isinstance(tr.get("coverage"), (int, float)) and isinstance(tr.get("accuracy_decided"), (int, float)):
            dec = f"; it decided {tr['coverage']:.0%} of them and was right on {tr['accuracy_decided']:.0%} of those"
        st = tr.get("stages") if isinstance(tr.get("stages"), dict) else None
        act = st.get("activity_model", {}) if st else {}
        how = f" in two stages (with {act.get('name', 'activity')} {act.get('version', '')})" if st else ""
        head = (f"{card.get('name', 'model')} {card.get('version', '')}{how}: right on {tr['accuracy']:.0%}{ci} of "
                f"{tr['scored']} clips from an independent renderer{dec}. "
                + ("No answer is decided today (its thresholds decide none): every label is a best guess."
                   if decides_nothing(card, single_stage) else "Rely on decided answers only."))
        sim = _simulated_note(card)
        return head + (f" On simulated validation: {sim}" if sim else " See the model card.")
    sim = _simulated_note(card)
    return f"{card.get('name', 'model')} {card.get('version', '')}: {sim}" if sim else None


def _simulated_note(card: dict) -> str | None:
    v = card.get("validation") or {}
    vis = v.get("visible") or {}
    if not isinstance(v.get("accuracy"), (int, float)) or not isinstance(vis.get("accuracy"), (int, float)):
        return None

    def ci(block):
        iv = block.get("accuracy_95ci")
        return f" (95 % CI {iv[0]:.0%}-{iv[1]:.0%})" if isinstance(iv, list) and len(iv) == 2 else ""

    # one set of a few hundred scenes can sit several points on the lucky side: name the others too
    others = [o.get("visible") or {} for o in v.get("other_sets") or [] if isinstance(o, dict)]
    others = [o for o in others if isinstance(o.get("accuracy"), (int, float))]
    more = "".join(f"; {o['accuracy']:.0%}{ci(o)} of visible windows on another set" for o in others)
    split = card.get("validation_with_split") if isinstance(card.get("validation_with_split"), dict) else {}
    sv = split.get("visible") if isinstance(split.get("visible"), dict) else {}
    if isinstance(sv.get("with_split"), (int, float)):  # the shipped answers are the net's with the split
        more += (f"; with the waving/jumping split, {sv['with_split']:.0%} of visible windows on a fresh set "
                 f"(the net alone: {sv.get('net_alone', float('nan')):.0%})")
    return (f"right on {vis['accuracy']:.0%}{ci(vis)} of "
            f"simulated windows where the people are visible (their signal >= {vis.get('min_snr_db', -10):g} dB), {v['accuracy']:.0%}"
            f"{ci(v)} of all{more}; a faint or distant mover reads as nobody. See the model card.")
