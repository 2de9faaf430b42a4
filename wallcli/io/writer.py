"""Writing files safely: outputs appear whole or not at all, inputs are never touched."""

from __future__ import annotations

import errno
import os
import stat
import tempfile
import time
from contextlib import contextmanager
from contextvars import ContextVar
from fractions import Fraction
from pathlib import Path
from typing import Iterable, Iterator

from wallcli.errors import WallcliError, raise_if_interrupted

# errors of a write that say where it went, not what was read: the output's failure whatever the
# code that met them (a muxer, savefig), so one clean line, not an internal error
_OUTPUT_ERRNOS = {errno.ENOSPC, errno.EDQUOT, errno.EFBIG, errno.EROFS}


def _reason(exc: OSError) -> str:
    text = exc.strerror or (os.strerror(exc.errno) if exc.errno else str(exc))
    return (text[:1].lower() + text[1:]) if text else type(exc).__name__


def _same_file(a: Path, b: Path) -> bool:
    # os.path.realpath, not Path.resolve(): resolve() raises RuntimeError on a symlink loop, and one
    # loop among the inputs would end the whole command
    try:
        if os.path.samefile(a, b):
            return True
    except (OSError, ValueError):
        pass
    try:
        return os.path.realpath(a) == os.path.realpath(b)
    except (OSError, ValueError):
        return False


def _umask() -> int:
    mask = os.umask(0o022)
    os.umask(mask)
    return mask


def name_max(folder: str | os.PathLike) -> int:
    """The longest file name (bytes) the file system of ``folder`` takes."""
    try:
        return int(os.pathconf(folder, "PC_NAME_MAX"))
    except (OSError, ValueError, AttributeError):
        return 255


def _kind(mode: int) -> str:
    if stat.S_ISCHR(mode) or stat.S_ISBLK(mode):
        return "a device"
    if stat.S_ISFIFO(mode):
        return "a named pipe (FIFO)"
    if stat.S_ISSOCK(mode):
        return "a socket"
    return "not a regular file"


def _check_target(out: Path, *, force: bool) -> None:
    """What is at ``out`` now: nothing (or a dangling link, which the rename replaces), or a regular
    file that --force may replace. Anything else is refused before it is opened: a device or FIFO
    would be read as an earlier result (/dev/zero without end, a FIFO forever) or replaced by the
    rename (a root's /dev/null)."""
    parent = out.parent if str(out.parent) else Path(".")
    limit = name_max(parent)
    if len(os.fsencode(out.name)) > limit:
        raise WallcliError(f"output name is {len(os.fsencode(out.name))} bytes long; the file system of "
                           f"{parent} takes at most {limit}")
    try:
        st = os.stat(out)
    except FileNotFoundError:
        st = None
    except OSError as exc:
        if exc.errno == errno.ENOTDIR or not parent.is_dir():
            raise WallcliError(f"output folder does not exist: {parent}") from None
        if exc.errno == errno.ELOOP:
            raise WallcliError(f"output {out} is a symbolic link loop") from None
        raise WallcliError(f"cannot use output {out}: {_reason(exc)}") from None
    if not parent.is_dir():
        raise WallcliError(f"output folder does not exist: {parent}")
    if st is not None and stat.S_ISDIR(st.st_mode):
        raise WallcliError(f"output is a folder: {out}")
    if st is not None and not stat.S_ISREG(st.st_mode):
        raise WallcliError(f"output {out} is {_kind(st.st_mode)}; wallcli writes its outputs to files",
                           hint="give a file path")
    if st is not None and not force:
        raise WallcliError(f"output exists: {out}", hint="use --force to overwrite")


# temporaries being written -> an open descriptor holding a lock on each (see _temporary)
_HELD: dict[str, int] = {}
SWEEP_AGE = 10.0  # seconds since a leftover temporary was last written


def _temporary(out: Path, hold: bool = False) -> Path:
    """Create the empty temporary beside ``out`` that will become it: hidden (scan and editors skip
    it), named after it so a leftover is recognisable, the same suffix (muxers choose the format by
    it), and never longer than the file system's name limit, however long the output's name.

    ``hold``: keep it locked until :func:`_release` (its rename or removal), and first remove the
    leftovers of earlier runs for the same output that nobody holds: runs killed hard (SIGKILL,
    a power cut) cannot remove their own, and they piled up beside the outputs."""
    parent = out.parent if str(out.parent) else Path(".")
    suffix = f".tmp{out.suffix}"
    room = name_max(parent) - len(os.fsencode(f"..{suffix}")) - 8  # mkstemp adds 8 random characters
    if room < 0:  # a suffix of some 240 bytes: no muxer knows it anyway
        suffix, room = ".tmp", name_max(parent) - 14
    # cut in bytes (the limit's unit); a character cut in two decodes to surrogates, which encode
    # back to the same bytes
    stem = os.fsdecode(os.fsencode(out.stem)[:max(room, 0)])
    if hold:
        _sweep(parent, f".{stem}.", suffix)
    try:
        fd, name = tempfile.mkstemp(prefix=f".{stem}.", suffix=suffix, dir=parent)
        if hold and _try_lock(fd):
            _HELD[name] = fd
        else:
            os.close(fd)
    except OSError as exc:
        raise WallcliError(f"cannot create files in {parent}: {_reason(exc)}") from None
    try:
        os.chmod(name, 0o666 & ~_umask())  # mkstemp makes 0600; outputs get the usual permissions
    except OSError as exc:
        Path(name).unlink(missing_ok=True)
        _release([Path(name)])
        raise WallcliError(f"cannot write {out}: {_reason(exc)}") from None
    return Path(name)


def _try_lock(fd: int) -> bool:
    try:
        import fcntl

        fcntl.flock(fd, fcntl.LOCK_EX | fcntl.LOCK_NB)
        return True
    except (ImportError, OSError):  # not POSIX, a file system without locks, held by another run
        return False


def _sweep(parent: Path, prefix: str, suffix: str) -> None:
    """Remove ``prefix`` + mkstemp's 8 characters + ``suffix`` files in ``parent`` that no process
    holds locked: a running wallcli holds its temporaries (a lock dies with its process)."""
    import glob

    try:
        import fcntl  # noqa: F401 - without locks nobody's temporaries can be told from leftovers
    except ImportError:
        return
    for name in glob.glob(os.path.join(glob.escape(str(parent)), glob.escape(prefix) + "?" * 8 + glob.escape(suffix))):
        if name in _HELD:
            continue
        try:
            fd = os.open(name, os.O_RDONLY | getattr(os, "O_NOFOLLOW", 0) | getattr(os, "O_NONBLOCK", 0))
        except OSError:
            continue
        try:
            st = os.fstat(fd)
            # a few seconds old at least: one just made by mkstemp may not be locked by its run yet
            if stat.S_ISREG(st.st_mode) and time.time() - st.st_mtime > SWEEP_AGE and _try_lock(fd):
                os.unlink(name)
        except OSError:
            pass
        finally:
            os.close(fd)


def release_temporary(path: Path) -> None:
    """Let go of the lock :func:`atomic_path` holds on its temporary, for a caller that locks it
    itself (flock: two locks of one file conflict even within one process)."""
    _release([path])


def _release(paths: Iterable[Path]) -> None:
    for p in paths:
        fd = _HELD.pop(str(p), None)
        if fd is not None:
            try:
                os.close(fd)
            except OSError:
                pass


# files read together with an input of this suffix: a model's card beside it (wallcli.infer.card)
_READ_BESIDE = {".onnx": (".json",)}


def read_with(inputs: Iterable) -> list[Path]:
    """Every file a command reads for ``inputs`` (paths; None, '-' and URLs are skipped): each one,
    and what is read beside it, so an output can be checked against all of them: a model (.onnx)
    brings its card (.json). Folders are left to the caller, which knows which of their files it
    reads (labels.csv, sidecars, a dataset's manifest and shards)."""
    out: list[Path] = []
    for src in inputs:
        if src is None or str(src) in ("", "-") or "://" in str(src):
            continue
        p = Path(str(src))
        out.append(p)
        out += [p.with_suffix(s) for s in _READ_BESIDE.get(p.suffix.lower(), ())]
    return out


def check_output(path: str | os.PathLike, *, force: bool = False, inputs: Iterable = ()) -> Path:
    """Validate an output path before any work starts, so a long job never fails at the end.

    ``inputs``: every file the command reads (see :func:`read_with`, applied here); an output that
    is one of them, by any name (a link, a hard link, ``./``), is refused, --force or not: --force
    replaces an earlier output, never an input."""
    out = Path(path)
    if str(path) in ("", "-"):
        raise WallcliError("this output must be a file path, not '-'")
    for src in read_with(inputs):
        if _same_file(out, src):
            raise WallcliError(f"output {out} is the input {src}; wallcli never overwrites an input, --force or not")
    _check_target(out, force=force)
    parent = out.parent if str(out.parent) else Path(".")
    if not os.access(parent, os.W_OK):
        raise WallcliError(f"output folder is not writable: {parent}")
    # the folder's permissions do not tell all (a read-only mount, /proc, /sys): try the real thing
    _temporary(out).unlink(missing_ok=True)
    return out


def check_outputs(paths: Iterable, *, force: bool = False, inputs: Iterable = ()) -> list[Path]:
    """:func:`check_output` for each of a command's outputs (None = not asked for), and refuse
    two outputs on one file: the second write would silently replace the first (even without
    --force, as the first one exists by then), after all the work was done."""
    from wallcli.errors import UsageError

    outs = [Path(p) for p in paths if p is not None]
    for i, out in enumerate(outs):
        for other in outs[:i]:
            if _same_file(out, other):
                raise UsageError(f"{out} is given for two outputs; each output needs its own file")
    inputs = list(inputs)
    return [check_output(out, force=force, inputs=inputs) for out in outs]


def output_folder(path: str | os.PathLike) -> Path:
    """Make (or reuse) a folder for outputs, and check files can be created in it, before any
    work: a read-only mount or /proc is one clean line, not an internal error."""
    folder = Path(path)
    try:
        folder.mkdir(parents=True, exist_ok=True)
    except FileExistsError:
        raise WallcliError(f"output folder {folder} exists and is not a folder") from None
    except OSError as exc:
        raise WallcliError(f"cannot create the output folder {folder}: {_reason(exc)}") from None
    _temporary(folder / "probe").unlink(missing_ok=True)
    return folder


@contextmanager
def atomic_path(path: str | os.PathLike, *, force: bool = False) -> Iterator[Path]:
    """Yield a temporary path beside ``path`` (same suffix, so muxers pick the right format).

    On success it is fsynced and renamed over ``path``; on any exception (Ctrl-C included) it is
    removed, so a crash never leaves a half-written output.
    """
    with atomic_paths([path], force=force) as (tmp,):
        yield tmp


# The outputs of the running committed_together() block, awaiting their rename: (temporaries, outputs, force).
_GROUP: ContextVar[list | None] = ContextVar("wallcli_commit_group", default=None)


@contextmanager
def atomic_paths(paths: Iterable, *, force: bool = False) -> Iterator[list[Path]]:
    """:func:`atomic_path` for outputs that only make sense together (a video and its ground truth).

    Every temporary is written first; then they are renamed in the order given, so list last
    the file readers look for (the video: once it is there, its sidecar is too). If anything
    fails, renames included, none of the outputs is left. Inside :func:`committed_together`,
    the renames wait for the end of that block.
    """
    outs = [Path(p) for p in paths]
    tmps: list[Path] = []
    try:
        for out in outs:
            _check_target(out, force=force)
            tmps.append(_temporary(out, hold=True))
        yield list(tmps)
        raise_if_interrupted()  # a `kill` whose exception Python swallowed still places nothing
    except OSError as exc:
        _discard(tmps)
        hit = [out for tmp, out in zip(tmps, outs) if _names_one_of(exc.filename, [tmp])]
        if hit or exc.errno in _OUTPUT_ERRNOS:
            target = hit[0] if hit else ", ".join(map(str, outs))
            raise WallcliError(f"cannot write {target}: {_reason(exc)}") from None
        raise
    except BaseException:
        _discard(tmps)
        raise
    group = _GROUP.get()
    if group is not None:
        group.append((tmps, outs, force))
    else:
        _commit([(tmps, outs, force)])


@contextmanager
def committed_together() -> Iterator[None]:
    """A command's outputs appear together or not at all.

    Files written inside this block through :func:`atomic_path` / :func:`atomic_paths` stay
    temporaries until the block ends without an error; then all are renamed into place. Put the
    command's stdout data (``--json``, the table) inside too: if that write fails (a full disk, a
    closed stdout), no file is placed either. Nested blocks join the outermost one.
    """
    if _GROUP.get() is not None:
        yield
        return
    pending: list = []
    token = _GROUP.set(pending)
    try:
        yield
    except BaseException:
        for tmps, _, _ in pending:
            _discard(tmps)
        raise
    finally:
        _GROUP.reset(token)
    _commit(pending)


def _names_one_of(filename, paths: Iterable[Path]) -> bool:
    if filename is None:
        return False
    try:
        return any(os.fsencode(filename) == os.fsencode(p) for p in paths)
    except (TypeError, ValueError):
        return False


def _discard(paths: Iterable[Path]) -> None:
    for p in paths:
        try:
            p.unlink(missing_ok=True)
        except OSError:  # clearing up after a failure: the failure is what the user must hear of
            pass
    _release(paths)


def _commit(batches: list) -> None:
    """fsync every temporary, then rename each onto its output; on any failure remove them all,
    and the outputs already renamed (half a set is worse than none)."""
    tmps = [t for batch in batches for t in batch[0]]
    outs_of = {t: o for batch_tmps, outs, _ in batches for t, o in zip(batch_tmps, outs)}
    placed: list[Path] = []
    tmp = None
    try:
        raise_if_interrupted()
        for tmp in tmps:
            with open(tmp, "rb+") as fh:
                os.fsync(fh.fileno())
        for _, outs, force in batches:
            for out in outs:
                # someone else created it (or put a device there) while we worked
                _check_target(out, force=force)
        for batch_tmps, outs, _ in batches:
            for tmp, out in zip(batch_tmps, outs):
                os.replace(tmp, out)
                placed.append(out)
        _release(tmps)
    except OSError as exc:
        _discard(tmps)
        _discard(placed)
        raise WallcliError(f"cannot write {outs_of.get(tmp, tmp)}: {_reason(exc)}") from None
    except BaseException:
        _discard(tmps)
        _discard(placed)
        raise


def write_text_atomic(path: str | os.PathLike, text: str, *, force: bool = False) -> None:
    with atomic_path(path, force=force) as tmp:
        tmp.write_text(text, encoding="utf-8")


def _x264_repeatable() -> dict[str, str]:
    """x264 options that keep it off its AVX-512 code (see VideoWriter), on CPUs that have it."""
    try:
        from numpy._core._multiarray_umath import __cpu_features__ as cpu
    except ImportError:  # numpy < 2
        try:
            from numpy.core._multiarray_umath import __cpu_features__ as cpu
        except ImportError:
            return {}
    # 'AVX2' is x264's name for everything up to AVX2 (SSE..AVX2, FMA3, BMI); only passed where
    # the CPU has AVX-512, hence AVX2, and never on non-x86 CPUs (where the name is unknown)
    return {"x264-params": "asm=AVX2"} if all(cpu.get(k) for k in ("AVX512F", "AVX2", "FMA3")) else {}


class VideoWriter:
    """Encode RGB uint8 frames with PyAV.

    ``.mp4``/``.mov`` -> H.264 (``crf``), ``.mkv`` with ``codec='ffv1'`` -> FFV1 4:4:4 (lossless after RGB->YUV),
    ``.y4m`` -> raw yuv. The caller owns atomicity (write to ``atomic_path``'s temp path).
    """

    def __init__(
        self,
        path: str | os.PathLike,
        fps: Fraction | float,
        width: int,
        height: int,
        *,
        codec: str | None = None,
        crf: int = 18,
        pix_fmt: str | None = None,
        preset: str = "medium",
        repeatable: bool = False,
        timed: bool = False,
    ):
        """``repeatable``: the same frames always give the same file (the simulator's promise:
        a seed gives one video). Two things in x264 break that by default, both measured here:
        its output depends on its thread count, and FFmpeg's default is one thread per core
        (the same 40 frames at 1, 2, 4 and 8 threads gave four different files); and its AVX-512
        code (PyAV 18.1's x264, core 165) is not repeatable from run to run on smooth, faint
        content like a simulated wall (10 encodes of one clip's frames in one process: 8
        different files; with AVX2 code or plain C: always one). So: one thread, and on CPUs with
        AVX-512, x264 limited to AVX2 (the same code an AVX2 machine runs; about as fast)."""
        import av

        path = Path(path)
        suffix = path.suffix.lower()
        fps = Fraction(fps).limit_denominator(1001) if not isinstance(fps, Fraction) else fps
        if suffix == ".y4m":
            codec, pix_fmt = "rawvideo", pix_fmt or "yuv444p"
            fmt = "yuv4mpegpipe"
        else:
            fmt = None
            codec = codec or "libx264"
        self._container = av.open(str(path), mode="w", format=fmt)
        stream = self._container.add_stream(codec, rate=fps)
        if codec in ("libx264", "h264"):
            # x264 needs even sizes for 4:2:0; callers pass even sizes, we refuse silently odd ones.
            pix_fmt = pix_fmt or "yuv420p"
            stream.options = {"crf": str(crf), "preset": preset, **(_x264_repeatable() if repeatable else {})}
        elif codec == "ffv1":
            # (gbrp would be lossless RGB, but FFV1 in the PyAV wheels refuses it; 4:4:4 YUV
            # loses only the rounding of the RGB->YUV conversion.)
            pix_fmt = pix_fmt or "yuv444p"
        if repeatable:
            stream.codec_context.thread_count = 1
        stream.width, stream.height = int(width), int(height)
        stream.pix_fmt = pix_fmt or "yuv420p"
        if stream.pix_fmt.startswith("yuv"):
            # swscale converts rgb24 with the BT.601 limited-range matrix; say so in the stream,
            # or readers guess BT.709 for HD sizes and shift the colours.
            stream.codec_context.colorspace = 6
            stream.codec_context.color_range = 1
        # write(rgb, t): each frame at its source's time (gaps, variable rates), in ticks of about
        # 1/90000 s (MPEG's clock) of which a frame at ``fps`` lasts a whole number: a steady
        # source stays exactly steady (24000/1001 in 1/90000 s ticks read back as 23.9759 fps)
        self._tick = Fraction(fps.denominator, fps.numerator * max(1, -(-90000 * fps.denominator // fps.numerator)))
        if timed:
            stream.codec_context.time_base = stream.time_base = self._tick
        self._stream = stream
        self._av = av
        self._timed = timed
        self._last_pts = -1
        self.frames = 0

    def write(self, rgb, t: float | None = None) -> None:
        """``t``: the frame's time in seconds (a ``timed`` writer); otherwise frames follow at ``fps``."""
        frame = self._av.VideoFrame.from_ndarray(rgb, format="rgb24")
        frame.pts = None
        if self._timed and t is not None:
            # strictly increasing, as muxers require, even where two source times round together
            frame.pts = self._last_pts = max(round(float(t) / self._tick), self._last_pts + 1)
            frame.time_base = self._tick
        for packet in self._stream.encode(frame):
            self._container.mux(packet)
        self.frames += 1

    def close(self, drain: bool = True) -> None:
        """``drain``: encode the frames the encoder still holds (its look-ahead); not after a
        failure or Ctrl-C, whose output is thrown away: at 6400x4800 that took 17 s."""
        if self._container is None:
            return
        try:
            if drain:
                for packet in self._stream.encode():
                    self._container.mux(packet)
        finally:
            container, self._container = self._container, None
            try:
                container.close()
            except Exception:  # noqa: BLE001 - after a failure its own error is the one to tell
                if drain:
                    raise

    def __enter__(self) -> "VideoWriter":
        return self

    def __exit__(self, exc_type, *exc) -> None:
        self.close(drain=exc_type is None)
