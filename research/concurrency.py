"""Are count's two-person errors windows whose two movers are not seen at the same time?

    .venv/bin/python research/concurrency.py --seed 107 --domain shifted [--scenes 256] [--chunk 64]

The seed's count net takes a max over 13 time steps of features with a ~4.5 s receptive field:
it can only tell two people from one where both show within one such stretch. A window's
visibility (``snr_db_weakest``) is measured over its whole 8.5 s, so a person seen only in its
first seconds and another only in its last pass as "both visible". This script re-renders the
two-person scenes of a dataset (scene i of ``--seed`` is the same scene the dataset mode writes),
fits each person's noise-free signal to every ``--chunk``-frame stretch of every window (as the
dataset mode fits whole windows), and scores the shipped count model against the *concurrent*
visibility: the best stretch's weaker person. If the errors sat in windows without a stretch
where both show, the fix would be in the data (or the labels), not the net.
"""
from __future__ import annotations

import argparse
from multiprocessing import Pool

import numpy as np

import wallcli.datagen.clips as clips
from wallcli.signal.window import WINDOW

_last: dict = {}
_window_snr_db = clips._window_snr_db


def _with_chunks(chunk: int):
    def measure(scene, cam, h, t, starts):
        out = _window_snr_db(scene, cam, h, t, starts)
        prof = scene.clean_profiles
        snr = np.full((len(starts), WINDOW // chunk, 2), np.nan)
        if prof and len(prof[0]) > 2:  # per-person profiles exist for scenes with several people
            people = [clips.profile_on_plot([p[2][j] for p in prof], cam.fps, h.shape[0])
                      for j in range(len(prof[0][2]))]
            for k, s in enumerate(starts):
                for c in range(WINDOW // chunk):
                    a, b = s + c * chunk, s + (c + 1) * chunk
                    if h.shape[1] < b or people[0].shape[1] < b:
                        continue
                    x = h[:, a:b].astype(np.float64)
                    x = (x - x.mean(axis=1, keepdims=True)).ravel()
                    snr[k, c] = clips._fit_snr_db(x, [q[:, a:b] for q in people])[0]
        _last["chunks"] = snr
        return out
    return measure


def _render(args):
    seed, index, domain, chunk = args
    rng = np.random.default_rng(np.random.SeedSequence([seed, index, 7]))  # as clips.scene_plan draws
    if int(rng.integers(0, 3)) != 2:
        return None
    clips._window_snr_db = _with_chunks(chunk)
    out = clips.render_windows(seed, index, "count", domain=domain, windows=4)
    return out["horizontal"], out["snr_db_weakest"], _last["chunks"]


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--seed", type=int, default=107)
    ap.add_argument("--domain", default="shifted")
    ap.add_argument("--scenes", type=int, default=256)
    ap.add_argument("--chunk", type=int, default=64, help="frames per stretch (64 = 2.1 s at 30 fps)")
    ap.add_argument("--jobs", type=int, default=2)
    ap.add_argument("--model", default=None)
    a = ap.parse_args()
    from wallcli.infer.model import load_model

    with Pool(a.jobs) as pool:
        res = [r for r in pool.imap(_render, [(a.seed, i, a.domain, a.chunk) for i in range(a.scenes)]) if r]
    h = np.concatenate([r[0] for r in res])
    weakest = np.concatenate([r[1] for r in res])
    chunks = np.concatenate([r[2] for r in res])
    model = load_model("count", a.model)
    pred = model.predict({"horizontal": model.normalize(h)}).argmax(1)
    visible = weakest >= -10
    with np.errstate(all="ignore"):
        concurrent = np.nanmax(np.nanmin(chunks, axis=2), axis=1)  # best stretch's weaker person
    print(f"{len(res)} two-person scenes, {len(h)} windows, {visible.sum()} visible; "
          f"{model.info()['name']} {model.info()['version']} right on {(pred[visible] == 2).mean():.1%} of those")
    print("visible windows by the weaker person's SNR in the best stretch where both show:")
    for lo, hi in [(-np.inf, -10), (-10, 0), (0, 10), (10, np.inf)]:
        s = visible & (concurrent >= lo) & (concurrent < hi)
        if s.any():
            print(f"  {lo:>5} .. {hi:<4} dB: {s.sum():4d} windows, counted 2: {(pred[s] == 2).mean():.1%}, "
                  f"counted 1: {(pred[s] == 1).mean():.1%}")


if __name__ == "__main__":
    main()
