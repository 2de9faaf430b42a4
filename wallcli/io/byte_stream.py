"""Byte streams read by a thread of ours (stdin, FIFOs, a file still being written) and handed to
FFmpeg as a Python file, so that every wait is in Python: a signal or a stall ends it."""

from __future__ import annotations

import os
import queue
import threading

from wallcli.errors import WallcliError

_POLL = 0.2  # s: how often a wait on a stream looks at its stop flag (a signal ends it within this)
FLUSH_FACTOR = 3.0  # a followed file ends after this many of its longest waits for growth, if longer
HEAD = 4096  # bytes: a followed file's beginning, compared while waiting for it to grow


class _Stopped(Exception):
    """The read was stopped (the reader closed, or a signal in the main thread): an Exception, so
    that PyAV hands it back where FFmpeg returns instead of dropping it."""


def _front_to_back(path: str) -> bool:
    """Whether a file can be read as a stream, front to back (what reading it as it grows needs):
    not an MP4/MOV whose index (moov) comes after its media (mdat), as most recorders write it
    when they finish; a fragmented or 'faststart' MP4 and MPEG-TS, MKV, raw streams can."""
    import struct

    try:
        with open(path, "rb") as fh:
            head = fh.read(8)
            if len(head) < 8 or head[4:8] != b"ftyp":
                return True
            fh.seek(0)
            for _ in range(64):
                box = fh.read(8)
                if len(box) < 8:
                    # its header is still being written (nothing after 'ftyp' yet): what follows
                    # will tell, and a reader that waits for it loses nothing
                    return True
                size, kind = struct.unpack(">I4s", box)
                if kind in (b"moov", b"moof"):
                    return True
                if kind == b"mdat":
                    return False
                if size == 1:
                    size = struct.unpack(">Q", fh.read(8))[0] - 8
                elif size == 0:
                    return False
                fh.seek(size - 8, os.SEEK_CUR)
    except (OSError, struct.error):
        return True
    return False


class StreamInput:
    """A byte stream (stdin, a FIFO) read by a thread of ours and handed to FFmpeg as a Python file.

    FFmpeg's own read() of a pipe blocks in C, where neither Ctrl-C, SIGTERM nor the decoder's stop
    reach it (a stalled writer held wallcli for as long as it stalled); here every wait is in
    Python, in steps of _POLL, and fails with one line after ``stall`` seconds without data. Memory:
    at most 64 chunks of 64 KiB queued."""

    def __init__(self, source: str, path: str | None, stall: float | None, idle: float | None = None) -> None:
        self.source, self.stall = source, stall
        self.idle = idle  # a growing file: at its end, wait this long for more before calling it the end
        self._longest = 0.0  # the longest wait at its end before it grew: how slowly its recorder flushes
        self.interrupted = False  # a signal arrived while FFmpeg read in the main thread
        self._q: queue.Queue = queue.Queue(maxsize=64)
        self._stop = threading.Event()
        self._buf = b""
        self._done = False  # EOF given, or the read failed once (FFmpeg may ask again: say EOF)
        threading.Thread(target=self._pump, args=(path,), daemon=True, name="wallcli-input").start()

    def _pump(self, path: str | None) -> None:
        # (opening a FIFO blocks until its writer opens it: here, not in the main thread). The
        # thread may stay in os.read when the command ends: a daemon, holding nothing of FFmpeg's.
        try:
            fd = os.dup(0) if path is None else os.open(path, os.O_RDONLY)
        except OSError as exc:
            return self._put(exc)
        try:
            if self.idle is not None:  # a growing file: what it began with, to tell it was overwritten
                self._path, self._head = path, os.pread(fd, HEAD, 0)
            while not self._stop.is_set():
                chunk = os.read(fd, 1 << 16)
                if not chunk and self.idle is not None and self._grows(fd):
                    continue
                self._put(chunk)
                if not chunk:
                    break
        except OSError as exc:
            self._put(exc)
        except WallcliError as exc:
            self._put(exc)
        finally:
            os.close(fd)

    def _same_file(self, fd: int, end: int) -> None:
        """A followed file only grows: one that shrank under the read, or whose first bytes or inode
        changed, was truncated or replaced, and what was read of it no longer describes it (a
        recorder restarted on the same name, a file overwritten): WallcliError, not a quiet end."""
        size = os.fstat(fd).st_size
        if size < end:
            raise WallcliError(f"{self.source} shrank while it was followed ({end} bytes read, {size} now): "
                               "it was truncated or replaced; the result so far is of the file before")
        try:
            moved = os.stat(self._path).st_ino != os.fstat(fd).st_ino
        except OSError:
            moved = True
        if moved or os.pread(fd, len(self._head), 0) != self._head:
            raise WallcliError(f"{self.source} was replaced while it was followed (its first bytes or the file "
                               "itself changed); the result so far is of the file before")

    def _grows(self, fd: int) -> bool:
        """At the end of a file being written: whether it grows within ``idle`` seconds, or within
        FLUSH_FACTOR times the longest pause between its growths so far (a recorder that flushes
        every 5 s outlasted a 5 s --idle-timeout and was taken for finished)."""
        import time

        end, waited = os.lseek(fd, 0, os.SEEK_CUR), 0.0
        while not self._stop.is_set() and waited < max(self.idle, FLUSH_FACTOR * self._longest):
            self._same_file(fd, end)
            if os.fstat(fd).st_size > end:
                # the wait is a lower bound of the recorder's pause (not the time we spent reading)
                self._longest = max(self._longest, waited)
                return True
            time.sleep(_POLL)
            waited += _POLL
        return False

    def _put(self, item) -> None:
        while not self._stop.is_set():
            try:
                return self._q.put(item, timeout=_POLL)
            except queue.Full:
                pass

    def read(self, n: int) -> bytes:
        try:
            return self._read(int(n))
        except KeyboardInterrupt:  # the signal handler's raise, inside FFmpeg's call of read()
            self.interrupted = True
            self._done = True
            raise _Stopped("interrupted") from None
        except BaseException:
            self._done = True
            raise

    def _read(self, n: int) -> bytes:
        if not self._buf:
            if self._done:
                return b""
            import time

            waited = 0.0
            while True:
                if self._stop.is_set():
                    raise _Stopped("stopped")
                t = time.monotonic()
                try:
                    item = self._q.get(timeout=_POLL)
                    break
                except queue.Empty:
                    waited += time.monotonic() - t
                    if self.stall is not None and waited >= self.stall:
                        raise WallcliError(f"{self.source}: no data for {self.stall:g} s (its writer stalled)",
                                           hint="--stall-timeout SECONDS waits longer; 0, for ever")
            if isinstance(item, WallcliError):
                raise item
            if isinstance(item, OSError):
                raise WallcliError(f"cannot read {self.source}: {item.strerror or item}")
            if not item:
                self._done = True
                return b""
            self._buf = item
        out, self._buf = self._buf[:n], self._buf[n:]
        return out

    def close(self) -> None:
        self._stop.set()


def _byte_stream(source: str) -> bool:
    """A path that is a pipe, socket or character device (not a camera): read as a stream."""
    import stat

    if source.startswith("/dev/video"):
        return False
    try:
        mode = os.stat(source).st_mode
    except OSError:
        return False
    return stat.S_ISFIFO(mode) or stat.S_ISSOCK(mode) or stat.S_ISCHR(mode)
