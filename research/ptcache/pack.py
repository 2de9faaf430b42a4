"""Pack cached clean scenes for the way back from a lent machine (research/transfer/device_run.sh pt).

The device tool brings back at most 8 files of 16 MiB, 64 MiB in all, per call: scenes go into
gzipped tar parts of at most ``--part-mib``, in index order, until ``--total-mib`` is reached;
the names packed are appended to ``--ledger``, so that the next call packs the ones left.
Unpack here with ``tar -xzf pt-*.tgz -C ~/.cache/wallcli/pt`` (the scenes' recipe folders).

    python research/ptcache/pack.py --root /tmp/ptc/pt --out "$OUT" --ledger /tmp/packed.txt
"""
from __future__ import annotations

import argparse
import tarfile
from pathlib import Path


def main(argv=None) -> int:
    ap = argparse.ArgumentParser()
    ap.add_argument("--root", type=Path, required=True)
    ap.add_argument("--out", type=Path, required=True)
    ap.add_argument("--ledger", type=Path, required=True)
    ap.add_argument("--part-mib", type=float, default=15.0)
    ap.add_argument("--total-mib", type=float, default=60.0)
    ap.add_argument("--tag", default="a")
    a = ap.parse_args(argv)
    done = set(a.ledger.read_text().split()) if a.ledger.is_file() else set()
    scenes = sorted(p for p in a.root.glob("*/scene-*.npz") if str(p.relative_to(a.root)) not in done)
    biggest = max((p.stat().st_size for p in scenes), default=0) / 2**20
    a.out.mkdir(parents=True, exist_ok=True)
    total, part, packed, tar, fh = 0.0, 0, [], None, None
    for p in scenes:
        if tar is not None and fh.tell() / 2**20 + biggest > a.part_mib:
            tar.close()
            total += fh.tell() / 2**20
            fh.close()
            tar = None
        if tar is None:
            if total + a.part_mib > a.total_mib:
                break
            fh = open(a.out / f"pt-{a.tag}{part}.tgz", "wb")
            tar = tarfile.open(fileobj=fh, mode="w:gz", compresslevel=6)
            for r in sorted(a.root.glob("*/recipe.json")):
                tar.add(r, arcname=str(r.relative_to(a.root)))
            part += 1
        rel = str(p.relative_to(a.root))
        tar.add(p, arcname=rel)
        packed.append(rel)
    if tar is not None:
        tar.close()
        total += fh.tell() / 2**20
        fh.close()
    with open(a.ledger, "a") as led:
        led.writelines(r + "\n" for r in packed)
    print(f"packed {len(packed)} scenes ({len(scenes) - len(packed)} left) in {part} parts, {total:.1f} MiB")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
