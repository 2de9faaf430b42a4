"""The ``.npz`` files wallcli writes: float arrays plus a JSON metadata string, never pickles."""

from __future__ import annotations

import json
import os
import zipfile
from pathlib import Path

import numpy as np

from wallcli.errors import WallcliError
from wallcli.io import jsonfile
from wallcli.io.writer import atomic_path

META_KEY = "meta"
# What a .npz may unpack to beyond twice its own size: wallcli writes them uncompressed (about
# 1:1), and a compressed one of 7 MB declaring 2,000,000 frames (3 GB) took count to 9.2 GB
UNPACK_FREE = 256 << 20


def save_npz(path: str | os.PathLike, arrays: dict[str, np.ndarray], meta: dict, *, force: bool = False) -> None:
    """Write ``arrays`` and ``meta`` (as a JSON unicode scalar) atomically."""
    payload = {k: np.asarray(v) for k, v in arrays.items()}
    for k, v in payload.items():
        if v.dtype == object:
            raise TypeError(f"array {k!r} has dtype object; it would need pickle")
    payload[META_KEY] = np.array(json.dumps(meta))
    with atomic_path(path, force=force) as tmp:
        with zipfile.ZipFile(tmp, "w", zipfile.ZIP_STORED, allowZip64=True) as zf:  # as np.savez writes
            for k, v in payload.items():
                with zf.open(k + ".npy", "w", force_zip64=True) as fid:
                    _write_npy(fid, v)


def _write_npy(fid, a: np.ndarray, step_bytes: int = 1 << 16) -> None:
    """One .npy member, its data in C order a slab of about ``step_bytes`` at a time: np.savez
    copies a whole array (chunk.tobytes) to write it, a second plot's worth of memory."""
    from numpy.lib import format as npy

    header = npy.header_data_from_array_1_0(a)
    header["fortran_order"] = False  # the slabs below are written in C order, whatever a's layout
    npy.write_array_header_1_0(fid, header)
    if a.ndim == 0:
        fid.write(a.tobytes())
        return
    step = max(1, step_bytes // max(1, a[:1].nbytes))
    for i in range(0, a.shape[0], step):
        fid.write(np.ascontiguousarray(a[i:i + step]).data)


def _compressed(p: Path) -> bool:
    """Whether any member of the zip at ``p`` is stored compressed (np.savez_compressed)."""
    try:
        with zipfile.ZipFile(p) as zf:
            return any(i.compress_type != zipfile.ZIP_STORED for i in zf.infolist())
    except (OSError, zipfile.BadZipFile):
        return False


def _declared_bytes(p: Path) -> int | None:
    """The bytes the .npy members' headers declare, read before any array is; None if unreadable
    (np.load then says what is wrong)."""
    from numpy.lib import format as npy

    total = 0
    try:
        with zipfile.ZipFile(p) as zf:
            for info in zf.infolist():
                if not info.filename.endswith(".npy"):
                    continue
                with zf.open(info) as f:
                    version = npy.read_magic(f)
                    read = npy.read_array_header_1_0 if version == (1, 0) else npy.read_array_header_2_0
                    shape, _, dtype = read(f)
                total += int(np.prod(shape, dtype=object)) * dtype.itemsize
    except Exception:  # noqa: BLE001 - damaged: left to np.load's own message
        return None
    return total


def load_npz(path: str | os.PathLike, *, kind: str | None = None) -> tuple[dict[str, np.ndarray], dict]:
    """Load a wallcli ``.npz``; ``kind`` checks ``meta['format']``. Corrupt files raise WallcliError."""
    p = Path(path)
    if not p.is_file():
        raise WallcliError(f"no such file: {p}")
    # np.load falls back to unpickling for anything that is not a zip or .npy, and its refusal
    # then advises allow_pickle=True: never the advice for a file a user fed us by mistake.
    if not zipfile.is_zipfile(p):
        raise WallcliError(f"{p} is not a readable .npz file (not a zip archive)")
    declared = _declared_bytes(p)
    if declared is not None and declared > max(UNPACK_FREE, 2 * p.stat().st_size):
        size = f"{declared / 1e9:.2f} GB of arrays from {p.stat().st_size / 1e6:.1f} MB"
        if _compressed(p):
            raise WallcliError(f"{p} unpacks to {size} (compressed); wallcli reads a .npz of at most twice its "
                               f"size or {UNPACK_FREE >> 20} MB", hint="write it uncompressed (np.savez), as wallcli does")
        # stored uncompressed, the headers claim arrays the file does not hold: damaged or crafted
        raise WallcliError(f"{p} is not a readable .npz file: its headers declare {size} (uncompressed), "
                           "more than the file holds")
    try:
        with np.load(p, allow_pickle=False) as npz:
            arrays = {k: npz[k] for k in npz.files}
    except MemoryError:  # a header that declares an array far larger than the file
        raise WallcliError(f"{p} is not a readable .npz file (it declares an array too large for memory)") from None
    except Exception as exc:  # noqa: BLE001
        # zipfile, zlib and NumPy's .npy header parser (Python's tokenizer and literal_eval) raise
        # a dozen kinds of error on damaged bytes (BadZipFile, zlib.error, struct.error,
        # tokenize.TokenError, SyntaxError, NotImplementedError, ...): all mean a damaged file
        raise WallcliError(f"{p} is not a readable .npz file ({type(exc).__name__}: {' '.join(str(exc).split())[:200]})") from None
    odd = [k for k, v in arrays.items() if not isinstance(v, np.ndarray)]
    if odd:  # np.load hands back members that are not .npy as raw bytes
        raise WallcliError(f"{p} is not a readable .npz file (member {odd[0]!r} is not a NumPy array)")
    meta_arr = arrays.pop(META_KEY, None)
    if meta_arr is None:
        raise WallcliError(f"{p} has no wallcli metadata; was it written by wallcli?")
    if meta_arr.shape != () or meta_arr.dtype.kind != "U":
        raise WallcliError(f"{p} has corrupt metadata (not a JSON string)")
    try:
        meta = jsonfile.loads(str(meta_arr[()]))
    except ValueError as exc:  # JSONDecodeError is a ValueError
        raise WallcliError(f"{p} has corrupt metadata: {exc}") from None
    if not isinstance(meta, dict):
        raise WallcliError(f"{p} has corrupt metadata (not a JSON object)")
    if kind is not None and meta.get("format") != kind:
        raise WallcliError(f"{p} is a {meta.get('format', 'unknown')!r} file, expected {kind!r}")
    return arrays, meta
