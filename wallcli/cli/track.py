"""``wallcli track INPUT``: where along the wall each moving person was, over time."""
from __future__ import annotations

from pathlib import Path
from typing import Optional

import typer

from wallcli.cli.common import (PNG_NAME, ROI_HELP, check_png_names, corrections_of, force_help, input_argument,
                                number_option, parse_roi, refuse_view, stall_option, strict_option, stream_option,
                                threads_option)

from wallcli.cli._classify import IDLE_OPT

INPUT_HELP = "Video (file, http(s)/rtsp URL, '-' for a stream on stdin) or a .npz from 'wallcli stplot'."


def track(
    input: str = input_argument(INPUT_HELP),
    json_out: bool = typer.Option(False, "--json", help="Print one JSON object on stdout (see docs/contract.md)."),
    csv: Optional[Path] = typer.Option(None, "--csv", help="Write the tracks' samples as CSV (track,t,x,sigma[,x_m]); "
                                       "'-' prints them on stdout."),
    png: Optional[Path] = typer.Option(None, "--png", help="Draw the tracks over the horizontal space-time plot "
                                       "(for a video, averaged down to at most 2048 time columns). " + PNG_NAME),
    view_width: Optional[float] = number_option(None, "--view-width", lo=0, hi=1e4, lo_open=True,
                                                help="The view's width on the wall at its mid-height, in metres: "
                                                     "adds x_m (metres from the view's centre) to every sample."),
    roi: Optional[str] = typer.Option(None, "--roi", help=ROI_HELP),
    force: bool = typer.Option(False, "--force", help=force_help("the --csv and --png files")),
    strict: bool = strict_option(),
    follow: bool = typer.Option(False, "--follow", help="Live or growing input: print each track's new samples as "
                                "JSON Lines as soon as they are found (the video is read in 16 s chunks, one every 12 s: "
                                "chunks overlap by 4 s), then the whole result."),
    idle_timeout: float = IDLE_OPT,
    threads: int = threads_option("Decoder threads (0: FFmpeg chooses)."),
    stream: Optional[int] = stream_option(),
    stall_timeout: Optional[float] = stall_option(),
) -> None:
    """Track each moving person along the wall: where their shade falls, over time.

    A person out of view shades part of the wall from the room's light; as they walk, the
    shade travels and draws a dark streak in the horizontal space-time plot. track follows
    the streaks: each track is a list of samples (10 a second) with t (seconds from the first
    frame), x (a fraction of the view's width: 0 = the view's left edge, 1 = its right edge),
    sigma_shade (the streak's half width: where the shade is) and sigma (where the person
    is, same unit). A person moving in place (crouching, waving, jumping) is a track whose x
    stays. A person standing still draws no streak, but one who shifts their weight can draw
    a short track that stays (count counts them as nobody moving); a clip where nobody
    moves at all has no tracks, and says so. Frames lost end a track: no sample lies where
    no frame is.

    x is where the shade is, which the light's direction sets: it can lead or trail the
    person, and a window beside the wall mirrors it; a shade reaching past the view's edge
    sits at x = 0 or 1. sigma is the shade's half width combined with geometry_sigma, how
    far a shade that strong fell from the person on the rendered recordings'
    motion-capture truth (68th percentile: 0.34 of the width for a faint shade to 0.57 for
    a strong one, which a person near a lamp or window casts far and magnified); sigma
    covers the true place on 66 % of those samples out of fold. There the longest track of
    a single walker follows the person (Pearson r >= 0.8) on 17 of the 28 clips (61 %); see
    research/track/README.md before reading x as a person's place.

    \b
    Examples:
      wallcli track clip.mp4
      wallcli track clip.mp4 --json | jq '.tracks | length'
      wallcli track clip.mp4 --png tracks.png --csv tracks.csv
      wallcli track plots.npz --view-width 2.3 --csv -
      ffmpeg -i rtsp://cam/stream -c copy -f nut - | wallcli track - --follow
    """
    from wallcli.cli.common import use_stream
    from wallcli.errors import UsageError

    use_stream(stream, stall_timeout, live=follow)
    roi_t = parse_roi(roi)
    if follow:
        if csv is not None or png is not None:
            raise UsageError("--csv and --png need the whole clip; they cannot be combined with --follow")
        if str(input).lower().endswith(".npz"):
            raise UsageError("--follow reads live video; a .npz space-time plot is already complete")
        from wallcli.cli.output import emit_json
        from wallcli.infer.track import follow_tracks
        from wallcli.io.video import FOLLOW_IDLE

        FOLLOW_IDLE.set(float(idle_timeout))
        for rec in follow_tracks(input, roi=roi_t, threads=threads, view_width=view_width,
                                 corrections=corrections_of(False, False, False)):
            if strict and "view" in rec:
                refuse_view(input, rec.get("view"))
            emit_json(rec)
        return
    if json_out and csv is not None and str(csv) == "-":
        raise UsageError("--json and --csv - both print on stdout: give --csv a file name")
    check_png_names(("--png", png))
    from wallcli.io.writer import check_outputs, committed_together

    files = [p for p in (csv, png) if p is not None and str(p) != "-"]
    check_outputs(files, force=force, inputs=[input])
    from wallcli.cli.output import progress, wrote
    from wallcli.api import track_clip

    # the Python API's own path (wallcli.api.track_clip); a video shows progress, a .npz is read at once
    if str(input).lower().endswith(".npz"):
        result, st = track_clip(input, roi=roi_t, view_width=view_width)
    else:
        with progress("track", None) as advance:
            result, st = track_clip(input, roi=roi_t, threads=threads, progress=advance, keep_plot=png is not None,
                                    view_width=view_width)
    if strict:
        refuse_view(input, result.get("view"))
    with committed_together():
        _report(result, st, json_out=json_out, csv=csv, png=png, force=force)
    wrote((csv if csv is not None and str(csv) != "-" else None, "the tracks' samples"),
          (png, "the tracks over the horizontal plot"))


def _report(result, st, *, json_out: bool, csv, png, force: bool) -> None:
    from wallcli.cli.output import emit_json, print_table, log
    from wallcli.infer.track import track_csv

    if png is not None:
        from wallcli.plots.track import save_track_png

        save_track_png(png, st, result, force=force)
    if csv is not None:
        text = track_csv(result)
        if str(csv) == "-":
            import sys

            sys.stdout.write(text)
            sys.stdout.flush()
        else:
            from wallcli.io.writer import write_text_atomic

            write_text_atomic(csv, text, force=force)
    if json_out:
        emit_json(result)
        return
    if csv is not None and str(csv) == "-":
        return
    tracks = result["tracks"]
    if not tracks:
        log(f"{result['input']}: no tracks: {result['reason']}")
        return
    rows = []
    for tr in tracks:
        xs = [s["x"] for s in tr["samples"]]
        rows.append([tr["id"], f"{tr['start']:.1f}", f"{tr['end']:.1f}", f"{xs[0]:.2f}", f"{xs[-1]:.2f}",
                     f"{min(xs):.2f}-{max(xs):.2f}", "moves" if tr["moving"] else "stays", f"{tr['strength']:.1f}"])
    print_table(f"{result['input']}: {len(tracks)} track{'s' if len(tracks) != 1 else ''}",
                ["track", "from (s)", "to (s)", "x first", "x last", "x range", "", "strength"], rows)
    sim = result["simultaneous"]
    if sim["seconds"]:
        log(f"two tracks at once, apart, for {sim['seconds']:.1f} s")
    if result.get("reason"):
        log(result["reason"])
