"""Fit (again) a model's decided/undetermined thresholds on simulated validation sets; write them in its card.

    python research/calibrate.py models/count.onnx data/val_wide22 data/val_count6s --level 0.97 --edges 0

The same function as `wallcli train --calibrate` (wallcli/train/calibrate.py), for a model that is
not retrained: the .onnx is untouched (the card's sha256 covers only it).
"""
from __future__ import annotations

import argparse
from pathlib import Path

from wallcli.train.calibrate import DEFAULT_MIN_SNR_DB, calibrate


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("model", type=Path)
    ap.add_argument("data", type=Path, nargs="+", help="simulated validation dataset(s) the model never trained on")
    ap.add_argument("--level", type=float, default=0.97, help="how often a decided answer must have been right")
    ap.add_argument("--edges", type=float, nargs="*", default=[0.0], help="signal band edges, dB")
    ap.add_argument("--min-snr-db", type=float, default=DEFAULT_MIN_SNR_DB,
                    help="calibrate on windows whose least visible mover is at least this many dB (default -20)")
    a = ap.parse_args()
    b = calibrate(a.model, a.data, level=a.level, edges=sorted(a.edges), min_snr_db=a.min_snr_db)
    on = b["calibrated_on"]
    print(f"{a.model}: thresholds {b['thresholds']} on {on['windows']} windows; {on['coverage']:.0%} decided, "
          f"{on['accuracy_decided']} of them right (in-sample)")


if __name__ == "__main__":
    main()
