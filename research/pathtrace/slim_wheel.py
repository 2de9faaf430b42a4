"""Repack a Mitsuba wheel with only what wallcli's path tracer uses, so that it and drjit fit in
one device call with the working tree (the device tool carries at most 64 MiB; mitsuba-3.9.1 cp312
is 62.6 MB and drjit-1.5.0 5.0 MB: 64.4 MiB together, before the working tree).

Drops the variants' Python modules other than ``--variants`` (default: all RGB ones), the plugins
that pathtrace.py's scenes never name (``--all-plugins`` keeps them), the C++ headers and the docs.
RECORD loses the dropped files' lines.

    python research/pathtrace/slim_wheel.py .whl/mitsuba-3.9.1-cp312-*.whl                      # RGB variants
    python research/pathtrace/slim_wheel.py --variants cuda_ad_rgb,scalar_rgb .whl/mitsuba-*.whl  # a GPU machine
"""

import argparse
import re
import zipfile
from pathlib import Path

# What pathtrace.py's scene dictionaries name (and their defaults: film filters, samplers, the
# spectra an RGB variant builds for 'rgb' values), with some margin.
PLUGINS = {"area", "bitmap", "box", "constant", "d65", "diffuse", "direct", "gaussian", "hdrfilm", "independent",
           "irradiancemeter", "ldsampler", "mesh_attribute", "multijitter", "orthographic", "path", "radiancemeter",
           "merge", "rectangle", "sphere", "srgb", "stratified", "tent", "twosided", "uniform", "obj", "ply", "serialized"}
ALWAYS = re.compile(r"^mitsuba/include/|^share/doc/")
VARIANT_MOD = re.compile(r"^mitsuba/((?:scalar|llvm_ad|cuda_ad|llvm|cuda)_\w+?)\.cpython")
PLUGIN = re.compile(r"^mitsuba/plugins/(\w+)\.so$")


def dropped(name: str, variants: set[str] | None, all_plugins: bool) -> bool:
    if ALWAYS.search(name):
        return True
    m = VARIANT_MOD.match(name)
    if m:
        v = m.group(1)
        return v not in variants if variants else not v.endswith("_rgb")
    m = PLUGIN.match(name)
    return bool(m) and not all_plugins and m.group(1) not in PLUGINS


def slim(path: Path, variants: set[str] | None, all_plugins: bool) -> None:
    tmp = path.with_suffix(".slim")
    with zipfile.ZipFile(path) as src, zipfile.ZipFile(tmp, "w", zipfile.ZIP_DEFLATED) as dst:
        for info in src.infolist():
            if dropped(info.filename, variants, all_plugins):
                continue
            data = src.read(info)
            if info.filename.endswith(".dist-info/RECORD"):
                data = "".join(ln for ln in data.decode().splitlines(True)
                               if not dropped(ln.split(",")[0], variants, all_plugins)).encode()
            dst.writestr(info, data)
    before = path.stat().st_size
    tmp.replace(path)
    print(f"{path.name}: {before / 1e6:.1f} MB -> {path.stat().st_size / 1e6:.1f} MB")


if __name__ == "__main__":
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("wheels", nargs="+", type=Path)
    ap.add_argument("--variants", help="comma-separated variants to keep (default: every *_rgb one)")
    ap.add_argument("--all-plugins", action="store_true")
    a = ap.parse_args()
    keep = set(a.variants.split(",")) if a.variants else None
    for p in a.wheels:
        slim(p, keep, a.all_plugins)
