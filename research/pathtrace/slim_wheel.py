"""Repack a Mitsuba wheel with only the RGB variants wallcli uses, so that it and drjit fit in
one device call (the device tool carries at most 64 MiB; mitsuba-3.9.1 cp312 is 62.6 MB and
drjit-1.5.0 5.0 MB: 64.4 MiB together, before the working tree).

Drops the mono / spectral / polarized variant modules, the C++ headers and the docs (~12 MB);
the plugins, Embree and the data folder stay. RECORD loses the dropped files' lines.

    python research/pathtrace/slim_wheel.py .whl/mitsuba-3.9.1-cp312-*.whl   # rewrites it in place
"""

import re
import sys
import zipfile
from pathlib import Path

DROP = re.compile(r"^mitsuba/(include/|\w+_(mono|spectral)\w*\.cpython)|^share/doc/")


def slim(path: Path) -> None:
    tmp = path.with_suffix(".slim")
    with zipfile.ZipFile(path) as src, zipfile.ZipFile(tmp, "w", zipfile.ZIP_DEFLATED) as dst:
        for info in src.infolist():
            if DROP.search(info.filename):
                continue
            data = src.read(info)
            if info.filename.endswith(".dist-info/RECORD"):
                data = "".join(ln for ln in data.decode().splitlines(True) if not DROP.search(ln)).encode()
            dst.writestr(info, data)
    before = path.stat().st_size
    tmp.replace(path)
    print(f"{path.name}: {before / 1e6:.1f} MB -> {path.stat().st_size / 1e6:.1f} MB")


if __name__ == "__main__":
    for p in sys.argv[1:]:
        slim(Path(p))
