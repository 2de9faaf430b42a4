"""``wallcli snr``: how much wall signal a video carries, where, and how it grows with averaging;
or, with ``--predict``, what the physics of the paper (supplementary §3.1) expects for a scene and camera."""

from __future__ import annotations

from pathlib import Path
from typing import Optional

import typer

from wallcli.cli.common import (stream_option, stall_option, PNG_NAME, THREADS_HELP, check_png_names, Number, corrections_of, deflicker_option, exposure_option, shake_option, force_help,
                                number_option, strict_option, threads_option)

# Parameters of --predict, by the name --sweep uses: (option, default, help, range). The range
# checks the option and every value of a --sweep alike.
PREDICT_PARAMS = {
    "distance": ("--distance", 2.0, "Person-to-wall distance d (m).", dict(lo=0.01, hi=1000)),
    "radius": ("--radius", 0.25, "Person radius r (m); the person is a disk of area A = pi r^2 facing the wall.",
               dict(lo=0, hi=100, lo_open=True)),
    "area": ("--area", None, "Person area A (m^2), instead of --radius.", dict(lo=0, hi=1e4, lo_open=True)),
    "albedo": ("--albedo", 0.7, "Wall albedo alpha.", dict(lo=0, hi=1)),
    "person_radiance": ("--person-radiance", 20.0, "Person radiance L_p, in code values (what a white wall lit by it "
                        "alone would record).", dict(lo=0, hi=1e6)),
    "background_radiance": ("--background-radiance", 200.0, "Surroundings' radiance L_s, same units.", dict(lo=0, hi=1e6)),
    "contrast": ("--contrast", None, "L_p - L_s directly, instead of the two radiances.", dict(lo=-1e6, hi=1e6)),
    "occupancy": ("--occupancy", 1.0, "Fraction q of the time the person is there.", dict(lo=0, hi=1)),
    "mean_code": ("--mean-code", None, "Camera model: the wall's mean code value (8-bit scale). With --gain, also "
                  "predicts noise and SNR.", dict(lo=0, hi=255)),
    # a millionth of an electron per code value and less is no camera, and squared overflows a float
    "gain": ("--gain", None, "Camera model: electrons per 8-bit code value.", dict(lo=1e-6, hi=1e6)),
    "read_noise": ("--read-noise", 2.0, "Camera model: read noise (electrons RMS).", dict(lo=0, hi=1e6)),
    "bits": ("--bits", 8, "Camera model: bit depth (quantisation step 2^(8-bits) on the 8-bit scale).",
             dict(lo=1, hi=16, integer=True)),
    "pixels": ("--pixels", 1.0, "Camera model: pixels averaged.", dict(lo=1, hi=1e15)),
    "frames": ("--frames", 1.0, "Camera model: frames averaged.", dict(lo=1, hi=1e9)),
}
MAX_SWEEP = 10000
from wallcli.api import AUTO_MIN_PX  # noqa: E402  (the one figure, for the help text)


def _predict_option(name: str):
    flag, default, text, rng = PREDICT_PARAMS[name]
    return number_option(default, flag, help=text, **rng)


def snr(
    input: Optional[str] = typer.Argument(None, help="Video file, http(s)/rtsp URL, or '-' (not needed with --predict).", show_default=False),
    roi: Optional[str] = typer.Option(None, "--roi", metavar="X,Y,W,H|auto", help="x,y,w,h in source pixels (at least 2x2), or 'auto': the rectangle of whole grid cells "
                                      "(up to 16x16 cells over the frame) whose spatially averaged grey level has the highest SNR "
                                      "(signal power / noise power of the rectangle's mean, computed exactly from the cells' temporal "
                                      "covariances), leaving out cells where the view check saw a moving object, clipping or black. "
                                      f"'auto' reads the file twice and is at least {AUTO_MIN_PX} px on each side (the "
                                      "frame's side if smaller), so the plots' 64 bins hold a pixel each. Default: whole frame."),
    json_out: bool = typer.Option(False, "--json", help="Print one JSON object (docs/contract.md fields, plus extras) on stdout."),
    heatmap: Optional[Path] = typer.Option(None, "--heatmap", help="Draw signal power (or SNR, --heatmap-of) per grid cell over the mean frame to this PNG. " + PNG_NAME),
    heatmap_of: str = typer.Option("signal", "--heatmap-of", help="What the heatmap shows: 'signal' (power, code values^2) or 'snr' (dB)."),
    plot: Optional[Path] = typer.Option(None, "--plot", help="Draw SNR and noise power against block size (log-log) beside the white-noise law; "
                                        "with --predict --sweep, SNR against the swept parameter (signal power without --mean-code and --gain). " + PNG_NAME),
    max_pixels: int = number_option(32768, "--max-pixels", lo=0, hi=2**31, integer=True, help="Pixels measured per frame: a larger ROI is sampled by a regular "
                                   "lattice of 32x32 tiles (an unbiased estimate of the per-pixel averages, and what keeps 1080p at "
                                   "decode speed). 0 = every pixel of the ROI (exact, slower)."),
    predict_mode: bool = typer.Option(False, "--predict", help="Predict from the scene's physics (the paper's supplementary §3.1) instead of measuring a video."),
    approx: bool = typer.Option(False, "--approx", help="--predict: far-field coverage A/(pi d^2) instead of the exact r^2/(r^2+d^2)."),
    sweep: Optional[str] = typer.Option(None, "--sweep", help="--predict: NAME=start:stop:step over any parameter, e.g. distance=1:4:0.25 "
                                        "(names: " + ", ".join(k.replace("_", "-") for k in PREDICT_PARAMS) + ")."),
    distance: float = _predict_option("distance"),
    radius: float = _predict_option("radius"),
    area: Optional[float] = _predict_option("area"),
    albedo: float = _predict_option("albedo"),
    person_radiance: float = _predict_option("person_radiance"),
    background_radiance: float = _predict_option("background_radiance"),
    contrast: Optional[float] = _predict_option("contrast"),
    occupancy: float = _predict_option("occupancy"),
    mean_code: Optional[float] = _predict_option("mean_code"),
    gain: Optional[float] = _predict_option("gain"),
    read_noise: float = _predict_option("read_noise"),
    bits: int = _predict_option("bits"),
    pixels: float = _predict_option("pixels"),
    frames: float = _predict_option("frames"),
    force: bool = typer.Option(False, "--force", help=force_help("the --heatmap and --plot files")),
    threads: int = threads_option(THREADS_HELP),
    stream: Optional[int] = stream_option(),
    stall_timeout: Optional[float] = stall_option(follow=False),
    strict: bool = strict_option(),
    no_deflicker: bool = deflicker_option(),
    no_exposure: bool = exposure_option(),
    no_shake: bool = shake_option(),
) -> None:
    """Measure the wall signal and the noise in a video, per colour channel (Sharma et al., What
    You Can Learn by Staring at a Blank Wall, ICCV 2021, supplementary §3.2).

    V is the video with each pixel's temporal mean removed and T(V) is V one frame later. The
    signal is slow and frame noise independent, so noise power = 1/2 Var(V - T(V)), signal power
    = Var V - 1/2 Var(V - T(V)), SNR = signal / noise (dB). Powers are per pixel in squared 8-bit
    code values, then again after averaging blocks of 2, 4, 8, 16 and 32 pixels square: white
    noise falls as 1/pixels averaged, a wall signal much less. One streaming pass.

    \b
    Examples:
      wallcli snr clip.mp4 --roi 100,50,640,360 --plot snr.png
      wallcli snr clip.mp4 --roi auto --heatmap where.png --json
      wallcli snr --predict --distance 2.5 --mean-code 120 --gain 4 --pixels 10000
      wallcli snr --predict --sweep distance=1:4:0.25 --plot fade.png
    """
    from wallcli.cli.common import use_stream

    use_stream(stream, stall_timeout)
    from wallcli.errors import UsageError
    from wallcli.io.writer import committed_together

    check_png_names(("--heatmap", heatmap), ("--plot", plot))
    if heatmap_of not in ("signal", "snr"):
        raise UsageError(f"--heatmap-of must be signal or snr (got {heatmap_of!r})")
    if predict_mode:
        if roi is not None or heatmap is not None:
            raise UsageError("--roi and --heatmap measure a video; --predict reads none")
        params = {k: v for k, v in locals().items() if k in PREDICT_PARAMS}
        with committed_together():  # the figure and the data on stdout: all or none
            return _predict(params, approx=approx, sweep=sweep, plot=plot, json_out=json_out, force=force)
    if input is None:
        raise UsageError("give a video (INPUT), or --predict for the physics alone")
    if sweep is not None:
        raise UsageError("--sweep goes with --predict")
    with committed_together():
        _measure(input, roi=roi, json_out=json_out, heatmap=heatmap, heatmap_of=heatmap_of, plot=plot,
                 max_pixels=max_pixels, force=force, threads=threads, strict=strict,
                 corrections=corrections_of(no_deflicker, no_exposure, no_shake))


# ------------------------------------------------------------------------------------- measure
def _measure(input, *, roi, json_out, heatmap, heatmap_of, plot, max_pixels, force, threads, strict=False,
             corrections=None) -> None:
    from wallcli.api import measure_snr
    from wallcli.cli.common import parse_roi
    from wallcli.cli.output import emit_json, print_lines, print_table, progress, warn, wrote
    from wallcli.io.writer import check_outputs
    from wallcli.wording import format_db

    auto = roi is not None and roi.strip().lower() == "auto"
    roi_t = "auto" if auto else parse_roi(roi)
    check_outputs([heatmap, plot], force=force, inputs=[input])
    # the Python API's own path (wallcli.api.measure_snr)
    m = measure_snr(input, roi=roi_t, max_pixels=max_pixels, threads=threads, corrections=corrections,
                    heatmap=heatmap is not None, progress=progress)
    result, res, grid, avoid = m.result, m.res, m.grid, m.avoid
    if strict:
        from wallcli.cli.common import refuse_view

        refuse_view(input, result["view"])
    notes = result["warnings"]
    if heatmap is not None:
        from wallcli.plots.snr import save_heatmap_png

        save_heatmap_png(heatmap, grid, of=heatmap_of, chosen=res.roi if auto else None,
                         avoid=avoid if auto else None, title=input, force=force)
    if plot is not None:
        from wallcli.plots.snr import save_scales_png

        save_scales_png(plot, result, force=force)
    wrote((heatmap, f"{heatmap_of} per cell of the wall"), (plot, "SNR and noise against block size"))
    if json_out:
        emit_json(result)
        return
    for n in notes:
        warn(n)
    if not result["view"]["usable"]:  # the figures below then measure more than a wall's light
        warn(result["view"]["reason"])
    from wallcli.snr.column import column_text
    from wallcli.wording import frames_text

    # the headline figure first, by its name; the verdict's and the table's are block SNRs
    print_lines([f"{column_text(result.get('column_snr_db'))}.", f"Verdict: {result['verdict']['text']}."])
    how = "every pixel" if res.exact else f"{res.sampled_pixels} pixels (32x32 tile lattice; --max-pixels 0 for all)"
    print_table(
        f"{input}: ROI {','.join(map(str, res.roi))} ({result['roi_mode']}), "
        f"{frames_text(result['frames'], result.get('corrections'))}, {how}; "
        "powers in 8-bit code values^2",
        ["block", "signal R G B", "noise R G B", "block SNR dB R G B"],
        [[f"{s['block']}x{s['block']}", _triple(s["signal_power"]), _triple(s["noise_power"]),
          _triple(s["snr_db"], format_db, 5)] for s in result["scales"]],
    )
    print_lines([f"Why the verdict: {result['verdict']['why']}."])
    from wallcli.wording import view_note_lines

    print_lines(view_note_lines(result.get("view")))  # as count and activity say them


def _triple(v, fmt=None, width: int = 7) -> str:
    # three significant digits in fixed-width fields keep three channels of three quantities in
    # aligned columns within 80 characters; the JSON has every digit
    fmt = fmt or (lambda x: "-" if x is None or x != x else f"{x:.3g}")
    return " ".join(fmt(x).rjust(width) for x in v)


# ------------------------------------------------------------------------------------- predict
def _parse_sweep(text: str) -> tuple[str, list[float]]:
    import math

    import numpy as np

    from wallcli.errors import UsageError

    name, _, rng = text.partition("=")
    key = name.strip().replace("-", "_")
    if key not in PREDICT_PARAMS:
        raise UsageError(f"--sweep: unknown parameter {name!r} (one of "
                         + ", ".join(k.replace("_", "-") for k in PREDICT_PARAMS) + ")")
    try:
        start, stop, step = (float(p) for p in rng.split(":"))
    except ValueError:
        raise UsageError(f"--sweep must be NAME=start:stop:step (got {text!r})") from None
    if not all(math.isfinite(x) for x in (start, stop, step)):
        raise UsageError(f"--sweep needs finite numbers (got {text!r})")
    if step <= 0 or stop < start:
        raise UsageError("--sweep needs step > 0 and stop >= start")
    span = (stop - start) / step  # counted before np.arange, which would allocate them all
    if not span < MAX_SWEEP:
        raise UsageError(f"--sweep: more than {MAX_SWEEP} values; use a larger step")
    count = math.floor(span + 1e-9) + 1
    flag, _, _, limits = PREDICT_PARAMS[key]
    check = Number(f"--sweep {flag[2:]}", **limits)  # each swept value obeys the option's own range
    values = [check(float(v)) for v in np.arange(start, stop + step * 1e-9, step)[:count]]
    return key, values


def _one(p: dict, approx: bool) -> dict:
    import math

    from wallcli.snr.predict import predict

    radius = math.sqrt(p["area"] / math.pi) if p["area"] is not None else p["radius"]
    contrast = p["contrast"] if p["contrast"] is not None else p["person_radiance"] - p["background_radiance"]
    return predict(distance=p["distance"], radius=radius, albedo=p["albedo"], contrast=contrast,
                   occupancy=p["occupancy"], approx=approx, mean_code=p["mean_code"], gain=p["gain"],
                   read_noise=p["read_noise"], bits=int(p["bits"]), pixels=p["pixels"], frames=p["frames"])


def _predict(params: dict, *, approx: bool, sweep, plot, json_out, force) -> None:
    from wallcli.cli.output import emit_json, print_table, warn
    from wallcli.errors import UsageError
    from wallcli.io.writer import check_output

    if (params["mean_code"] is None) != (params["gain"] is None):
        raise UsageError("the camera model needs both --mean-code and --gain")
    if plot is not None:
        if sweep is None:
            raise UsageError("with --predict, --plot draws a --sweep")
        check_output(plot, force=force)
    settings = dict(params, approx=approx)
    if sweep is None:
        out = _one(params, approx)
        if json_out:
            emit_json({"mode": "predict", "parameters": settings, **out, "units": {k: UNITS[k] for k in out}})
            return
        print_table("snr --predict (Sharma et al., ICCV 2021, supplementary §3.1)" + (", far-field approximation" if approx else ""),
                    ["quantity", "value", "unit"], [[k, _shown(k, v), UNITS.get(k, "")] for k, v in out.items()])
        if params["mean_code"] is None:
            warn("no camera model: give --mean-code and --gain for noise power and SNR")
        return
    key, values = _parse_sweep(sweep)
    if key in ("mean_code", "gain") and (params["mean_code"] is None or params["gain"] is None):
        params = dict(params, mean_code=params["mean_code"] or 128.0, gain=params["gain"] or 4.0)
    if key == "radius" and params["area"] is not None:
        raise UsageError("--sweep radius conflicts with --area")
    if key in ("person_radiance", "background_radiance") and params["contrast"] is not None:
        raise UsageError(f"--sweep {key.replace('_', '-')} conflicts with --contrast")
    rows = [dict(_one(dict(params, **{key: v}), approx), **{key: v}) for v in values]
    if plot is not None:
        from wallcli.plots.snr import save_sweep_png

        what = save_sweep_png(plot, key, rows, force=force)
        from wallcli.cli.output import wrote

        wrote((plot, f"predicted {what} against {key.replace('_', '-')}"))
    if json_out:
        emit_json({"mode": "predict", "parameters": settings, "sweep": {"parameter": key.replace("_", "-"), "values": values},
                   "rows": rows, "units": {k: UNITS[k] for k in rows[0] if k in UNITS}})
        return
    cols = [key.replace("_", "-"), "theta", "amplitude", "signal_power"] + (
        ["noise_power", "snr_db"] if "noise_power" in rows[0] else [])
    print_table(f"snr --predict, sweeping {key.replace('_', '-')} (theta: fraction of the wall point's view "
                "the person blocks; cv: code values of an 8-bit video)", [_headed(c) for c in cols],
                [[_shown(c, r.get(c)) for c in [key] + cols[1:]] for r in rows])


# what each predicted quantity is measured in: radiances are in code values (what a white wall lit
# by that radiance alone would record, signal_predict.predict), so powers are code values squared
UNITS = {"theta": "fraction of view blocked", "amplitude": "code values", "signal_power": "code values²",
         "noise_power": "code values²", "shot": "code values²", "read": "code values²",
         "quantisation": "code values²", "snr": "ratio", "snr_db": "dB"}
_SHORT = {"theta": "", "amplitude": "cv", "signal_power": "cv²", "noise_power": "cv²", "snr_db": "dB"}


def _headed(col: str) -> str:
    """A sweep table's column with its unit (short: cv = code values of an 8-bit video)."""
    return f"{col} ({_SHORT[col]})" if _SHORT.get(col) else col


def _shown(name: str, value) -> str:
    """A predicted quantity for the table: dB as every output writes dB, the rest to 6 digits."""
    from wallcli.wording import format_db

    if value is None:
        return "-"
    return format_db(value) if name.endswith("_db") else f"{value:.6g}"
