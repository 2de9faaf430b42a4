"""What `wallcli count` would cost with parts of its per-frame work switched off (issue 45 part 1):
the ceiling that the checks leave for any speed-up of theirs. Each configuration runs in a fresh
process (monkeypatched in-process, the CLI's own path otherwise), alternating with decode-only.

    .venv/bin/python research/speed/ablate.py bench/out/export_t002_p1_walking_900_crf18.mp4 --rounds 2
    .venv/bin/python research/speed/ablate.py bench/out/export_t002_p1_walking_900_crf18.mp4 --command stplot

Configurations: every check on (as shipped); each of overlay, repeats, interlace, TNR, the view
check and the shift registration off alone; all the camera checks and the view check off; and
those with the shift registration off too (the projection, the windows and the nets alone).
"""
from __future__ import annotations

import argparse
import contextlib
import io
import json
import os
import resource
import statistics
import subprocess
import sys
import time
from pathlib import Path

PARTS = ("overlay", "repeats", "interlace", "tnr", "view", "shift")
CONFIGS = ["", *PARTS, "overlay,repeats,interlace,tnr,view", ",".join(PARTS)]


def _switch_off(off: set[str]) -> None:
    from wallcli.camera import interlace, overlay, repeats, tnr
    from wallcli.signal import blocks
    from wallcli.view import check as view

    if "overlay" in off:
        overlay.OverlayFilter.frames = lambda self: self.reader.frames()
    if "repeats" in off:
        def frames(self):
            for f in self.reader.frames():
                self.decoded += 1
                self.last_time = f.time
                yield f
        repeats.RepeatFilter.frames = frames
    if "interlace" in off:
        interlace.InterlaceFilter.frames = lambda self: self.reader.frames()
    if "tnr" in off:
        tnr.TemporalNoise.__call__ = lambda self, f: None
    if "view" in off:
        view.ViewCheck.update = lambda self, t, p: None
    if "shift" in off:
        blocks.LineShift.__call__ = lambda self, s: 0.0


def _args(command: str, clip: str) -> list[str]:
    if command == "stplot":  # the plots written, as `wallcli stplot CLIP -o plots.npz` writes them
        import tempfile

        return ["stplot", clip, "-o", str(Path(tempfile.gettempdir()) / "wallcli_ablate.npz"), "--force"]
    return ["count", clip, "--json"]


def _child(clip: str, config: str, command: str) -> None:
    t0 = time.perf_counter()
    if config == "decode":
        import av

        with av.open(clip) as c:
            s = c.streams.video[0]
            s.thread_type = "AUTO"
            for _ in c.decode(s):
                pass
    else:
        # as the CLI's entry does before numpy loads (wallcli/cli/entry.py): OpenBLAS's helper
        # threads would otherwise spin on the small matrices and be counted as the checks' cost
        os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")
        _switch_off(set(filter(None, config.split(","))))
        from wallcli.cli.app import main

        with contextlib.redirect_stdout(io.StringIO()):
            try:
                main(_args(command, clip))
            except SystemExit as exc:
                if exc.code:
                    raise
    ru = resource.getrusage(resource.RUSAGE_SELF)
    print(json.dumps({"seconds": time.perf_counter() - t0, "cpu": ru.ru_utime + ru.ru_stime}))


def _run(clip: str, config: str, command: str) -> dict:
    out = subprocess.run([sys.executable, __file__, clip, "--child", config, "--command", command],
                         capture_output=True, text=True, check=True)
    return json.loads(out.stdout.strip().splitlines()[-1])


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("clip")
    ap.add_argument("--rounds", type=int, default=2)
    ap.add_argument("--command", choices=("count", "stplot"), default="count")
    ap.add_argument("--child")
    args = ap.parse_args()
    if args.child is not None:
        return _child(args.clip, args.child, args.command)
    ratios = {c: [] for c in CONFIGS}
    cpu = {c: [] for c in CONFIGS}
    dec_cpu = []
    for _ in range(args.rounds):
        for c in CONFIGS:
            d = _run(args.clip, "decode", args.command)
            r = _run(args.clip, c, args.command)
            ratios[c].append(d["seconds"] / r["seconds"])
            cpu[c].append(r["cpu"])
            dec_cpu.append(d["cpu"])
    print(f"decode-only: {statistics.median(dec_cpu):.2f} CPU s (median of {len(dec_cpu)})")
    print(f"| switched off | {args.command} / decode-only, wall (median; runs) | {args.command}'s CPU s |")
    print("|---|---|---|")
    for c in CONFIGS:
        print(f"| {c or 'nothing (as shipped)'} | {statistics.median(ratios[c]):.2f} "
              f"({', '.join(f'{x:.2f}' for x in ratios[c])}) | {statistics.median(cpu[c]):.2f} |")


if __name__ == "__main__":
    main()
