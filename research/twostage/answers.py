"""Both nets' clip probabilities on every clip of a labelled folder, one decode per clip.

    python research/twostage/answers.py ../shared/transfer runs/ans_transfer.json [--count M] [--activity M]

Writes, per clip: truth (people, activity, the labels' snr_db), the count net's and the activity
net's clip probabilities (window mean, as the commands answer) and the measured signal. The
space-time plots are cached in runs/plots/<folder name>/ so several models can be compared
without decoding again. Read by combine.py. Clips are only measured here: nothing is fitted.
"""
from __future__ import annotations

import argparse
import json
from pathlib import Path

from wallcli.evaluate.labels import read_labels
from wallcli.infer.classify import classify_plot, load_plot
from wallcli.infer.model import load_model


def main(argv=None) -> int:
    ap = argparse.ArgumentParser()
    ap.add_argument("folder")
    ap.add_argument("out")
    ap.add_argument("--count", default=None)
    ap.add_argument("--activity", default=None)
    a = ap.parse_args(argv)
    labels = read_labels(a.folder)
    cache = Path("runs/plots") / Path(a.folder).resolve().name
    cache.mkdir(parents=True, exist_ok=True)
    models = {"count": load_model("count", a.count, threads=1), "activity": load_model("activity", a.activity, threads=1)}
    rows = []
    for clip in labels.clips:
        npz = cache / (Path(clip.file).stem + ".npz")
        try:
            if not npz.exists():
                from wallcli.io.arrays import save_npz
                from wallcli.signal.stplot import to_arrays

                plot = load_plot(str(clip.path))
                arrays, meta = to_arrays(plot)
                save_npz(npz, arrays, meta)
            plot = load_plot(str(npz))
            res = {t: classify_plot(m, plot, stride=int(m.card["stride"]), source=clip.file) for t, m in models.items()}
        except Exception as exc:  # one clip's failure is that clip's row
            rows.append({"file": clip.file, "error": str(exc)})
            continue
        rows.append({"file": clip.file, "people": clip.people, "activity": clip.activity, "persons": clip.persons,
                     "detectable": clip.detectable, "snr_db": clip.snr_db,
                     "count": res["count"]["probabilities"], "count_signal_db": res["count"]["signal_db"],
                     "activity_p": res["activity"]["probabilities"], "activity_signal_db": res["activity"]["signal_db"]})
    Path(a.out).write_text(json.dumps({"folder": a.folder, "models": {t: m.info() for t, m in models.items()},
                                       "rows": rows}, indent=1))
    print(f"{a.out}: {len(rows)} clips")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
