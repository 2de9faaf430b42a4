"""Writing the results file of ``wallcli scan`` (the format and reading are in results.py).

One run at a time writes it: a scan holds an advisory lock (``flock``) on it from before it
reads it until it ends, and a second scan of the same file stops at once. Every line is written,
flushed and fsynced before the next one, and a write that fails (a full disk, a quota) is cut
back to where the line began: the file always ends with a whole line.

A run that rewrites the file (dropping a resume's failed or stale lines, or --force) waits for
its first new line. --force on a file that holds results goes further: its new lines go to a
hidden file beside it, which replaces it when the run ends well, so the old results stay whole
until then; a run that fails or is interrupted after some new lines merges them into the old
file instead (each video's new line replacing its old one), where the two can be merged.
"""
from __future__ import annotations

import contextlib
import errno
import os
import stat
from pathlib import Path
from typing import Callable

from wallcli.batch.results import Entry, csv_record, flatten, key, read
from wallcli.errors import WallcliError


class ResultsFile:
    """The results file of one run: :meth:`open` (and lock) it before reading it, :meth:`start`
    appending, :meth:`append` a line per video, :meth:`close` (or :meth:`abandon`) at the end."""

    def __init__(self, path: Path, encode: Callable[[dict], str], columns: list[str] | None = None):
        self.path, self.encode, self.columns = Path(path), encode, columns
        self.created = False  # by this run: removed again if the run fails before its first line
        self.appended = 0
        self.note: str | None = None  # what abandon() did with the new lines, for the run's log
        self._fd: int | None = None  # the locked file at the path
        self._out: int | None = None  # where lines go: self._fd, or the file beside it
        self._pending: list[Entry] | None = None  # lines the file is to be replaced by (start)
        self._beside = False  # --force on a file holding results: write beside, replace at the end
        self._side: tuple[contextlib.ExitStack, Path] | None = None

    def open(self) -> None:
        """Open the file, creating it if absent, and take its lock; a scan already holding it is
        an error, at once (a batch that waited would only redo that scan's work)."""
        flags = os.O_RDWR | os.O_APPEND | getattr(os, "O_NONBLOCK", 0) | getattr(os, "O_CLOEXEC", 0)
        for _ in range(20):
            try:
                try:
                    fd = os.open(self.path, flags | os.O_CREAT | os.O_EXCL, 0o666)
                    created = True
                except FileExistsError:
                    fd = os.open(self.path, flags)  # O_NONBLOCK: a FIFO put there meanwhile must not hang us
                    created = False
            except FileNotFoundError:
                continue  # removed between the two opens: try again
            except OSError as exc:
                raise WallcliError(f"cannot open {self.path}: {_reason(exc)}") from None
            if not stat.S_ISREG(os.fstat(fd).st_mode):
                os.close(fd)
                raise WallcliError(f"{self.path} is not a regular file; scan results go to a file")
            try:
                _lock(fd, self.path)
            except BaseException:
                os.close(fd)
                raise
            try:
                same = os.path.samestat(os.stat(self.path), os.fstat(fd))
            except OSError:
                same = False
            if same:
                self._fd, self.created = fd, created
                return
            # the scan that held the lock replaced or removed the file before letting go: the lock
            # taken is on a file no longer there; the one at the path now is the one to lock
            os.close(fd)
        raise WallcliError(f"cannot lock {self.path}: it keeps being replaced (another scan?)")

    def _format(self, line: dict) -> str:
        if self.columns is None:
            return self.encode(line) + "\n"
        return csv_record(flatten(line, self.columns))

    def start(self, kept: list[Entry] | None, *, force: bool = False) -> None:
        """Start appending. ``kept`` None: the file is right as it is; otherwise it is to be
        replaced by a fresh file holding the header and ``kept``'s lines, but only once this run
        stores its first line or ends well: a run that fails or is interrupted before that (an
        unreachable cluster, Ctrl-C at start-up) leaves the old file as it was. ``force``: the
        old file's results stay whole until the run ends (see the module's text)."""
        self._pending = kept
        self._beside = force and kept is not None and os.fstat(self._fd).st_size > 0
        if kept is None:
            self._out = self._fd

    def _fresh(self, kept: list[Entry]) -> tuple[contextlib.ExitStack, Path, int]:
        """A locked temporary beside the file holding the header and ``kept``: (its rename on
        the stack's close, its path, a descriptor appending to it)."""
        from wallcli.io.writer import atomic_path, release_temporary

        stack = contextlib.ExitStack()
        new = None
        try:
            tmp = stack.enter_context(atomic_path(self.path, force=True))
            header = [csv_record(self.columns)] if self.columns is not None else []
            tmp.write_text("".join(header + [f"{e.raw}\n" for e in kept]), encoding="utf-8")
            # locked before the rename, and the lock goes with the file: there is no moment
            # when the path names an unlocked file another scan could take
            new = os.open(tmp, os.O_WRONLY | os.O_APPEND | getattr(os, "O_CLOEXEC", 0))
            release_temporary(tmp)  # the writer's own lock on it gives way to this one
            _lock(new, self.path)
        except BaseException as exc:
            if new is not None:
                os.close(new)
            _discard(stack)  # the temporary goes
            if isinstance(exc, OSError):
                raise WallcliError(f"cannot write {self.path}: {_reason(exc)}") from None
            raise
        return stack, tmp, new

    def _place(self, stack: contextlib.ExitStack, new: int) -> None:
        """Rename the temporary on ``stack`` over the file; ``new`` becomes the file written."""
        try:
            stack.close()
        except BaseException:
            os.close(new)
            raise
        os.close(self._fd)
        self._fd = self._out = new

    def _begin(self) -> None:
        kept, self._pending = self._pending, None
        stack, tmp, new = self._fresh(kept)
        if self._beside:
            self._side, self._out = (stack, tmp), new
        else:
            self._place(stack, new)

    def append(self, line: dict) -> None:
        if self._pending is not None:
            self._begin()
        data = self._format(line).encode("utf-8")
        # one line at a time, fsynced: on disk before the next one starts; a write that fails
        # part way is cut back, so the file never ends in half a line (a kill can still tear one,
        # which the next run drops)
        fd = self._out
        start = os.fstat(fd).st_size
        try:
            view = memoryview(data)
            while view:
                view = view[os.write(fd, view):]
        except BaseException as exc:  # a full disk, a quota, Ctrl-C: the lines before this one are whole
            with contextlib.suppress(OSError):
                os.ftruncate(fd, start)
                os.fsync(fd)
            if isinstance(exc, OSError):
                raise WallcliError(f"cannot write {self.path}: {_reason(exc)}") from None
            raise
        self.appended += 1  # whole in the file from here: Ctrl-C during the fsync keeps it
        try:
            os.fsync(fd)
        except OSError as exc:
            raise WallcliError(f"cannot write {self.path}: {_reason(exc)}") from None

    def close(self) -> None:
        """End a run that went well: a replacement still pending (no line stored) is made now,
        and --force's new file takes the old one's place."""
        if self._pending is not None and self._fd is not None:
            self._begin()
        if self._side is not None:
            (stack, _), self._side = self._side, None
            self._place(stack, self._out)
        fd, self._fd, self._out = self._fd, None, None
        if fd is not None:
            os.close(fd)

    def abandon(self) -> None:
        """Close after a failure; a file this run created and never wrote a line to is removed
        (while still locked, so no other scan can have opened it meanwhile). --force's new lines
        are merged into the old results, which are otherwise left as they were."""
        self._pending = None  # the old file stays as it was: nothing new replaces it
        side, self._side = self._side, None
        try:
            if side is not None:
                self._merge(*side)
            if self.created and not self.appended:
                self.path.unlink(missing_ok=True)
            self.close()
        except (OSError, WallcliError):  # a full disk refuses the unwritten rest again: the first error tells
            pass

    def _merge(self, stack: contextlib.ExitStack, tmp: Path) -> None:
        """The old file with --force's new lines in place of their videos' old ones, when both
        read as results of the same tasks; else the old file as it was."""
        out, self._out = self._out, self._fd
        try:
            os.close(out)
            new, _ = read(tmp, self.columns)
            old, _ = read(self.path, self.columns)
            if new and all(e.tasks == new[0].tasks for e in old):
                done = {key(e.input) for e in new}
                merged = [e for e in old if key(e.input) not in done] + new
                header = [csv_record(self.columns)] if self.columns is not None else []
                with open(tmp, "w", encoding="utf-8", newline="") as fh:
                    fh.write("".join(header + [f"{e.raw}\n" for e in merged]))
                    fh.flush()
                    os.fsync(fh.fileno())
                # renamed here, not by the writer, which places nothing once Ctrl-C is pressed: this
                # is the answer to that Ctrl-C
                os.replace(tmp, self.path)
                _discard(stack)
                self.note = (f"{self.path}: this run's {len(new)} new line(s) merged into the {len(old)} it "
                             f"held ({len(old) + len(new) - len(merged)} replaced)")
                return
            why = f"{self.path} holds results of other tasks" if new else None
        except (OSError, WallcliError) as exc:
            why = str(exc)
        if why:
            self.note = f"this run's {self.appended} new line(s) are not kept ({why}); {self.path} is as it was"
        _discard(stack)


def _discard(stack: contextlib.ExitStack) -> None:
    """Close ``stack``'s atomic_path without its rename: the temporary is removed."""
    with contextlib.suppress(BaseException):
        stack.__exit__(_Discarded, _Discarded(), None)


class _Discarded(Exception):
    pass


def _reason(exc: OSError) -> str:
    text = exc.strerror or str(exc)
    return text[:1].lower() + text[1:]


def _lock(fd: int, path: Path) -> None:
    """An exclusive advisory lock on the open file ``fd``; an error naming ``path`` when another
    process holds one. flock, not lockf: a POSIX lock is dropped when the process closes *any*
    descriptor of the file, as reading it does."""
    try:
        import fcntl
    except ImportError:  # not POSIX: no lock, as before
        return
    try:
        fcntl.flock(fd, fcntl.LOCK_EX | fcntl.LOCK_NB)
    except BlockingIOError:
        raise WallcliError(f"another wallcli scan is writing {path}",
                           hint="wait for it to end, or choose another -o") from None
    except OSError as exc:
        if exc.errno in (errno.ENOLCK, errno.EOPNOTSUPP, errno.ENOSYS):
            return  # a file system without locks (some network ones): carry on unlocked, as before
        raise WallcliError(f"cannot lock {path}: {_reason(exc)}") from None
