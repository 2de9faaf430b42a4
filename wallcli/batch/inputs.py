"""What ``wallcli scan`` reads: files, folders searched recursively, and ``@list.txt`` files."""
from __future__ import annotations

import fnmatch
import os
from pathlib import Path

from wallcli.errors import WallcliError

VIDEO_EXTENSIONS = (".mp4", ".mov", ".m4v", ".mkv", ".webm", ".avi", ".ts", ".mts", ".m2ts", ".mpg", ".mpeg",
                    ".wmv", ".flv", ".3gp", ".nut", ".y4m")


def is_url(source: str) -> bool:
    return "://" in source


def _matches(name: str, globs: list[str] | None) -> bool:
    if not globs:
        return name.lower().endswith(VIDEO_EXTENSIONS)
    return any(fnmatch.fnmatchcase(name, g) for g in globs)


def _identity(path) -> tuple[int, int] | None:
    try:
        st = os.stat(path)
    except (OSError, ValueError):
        return None
    return st.st_dev, st.st_ino


def _walk(folder: str, globs: list[str] | None) -> list[str]:
    found = []
    for root, dirs, files in os.walk(folder):
        # hidden entries: editors' and wallcli's own temporaries (.NAME.XXXX.tmp.mp4), .git
        dirs[:] = sorted(d for d in dirs if not d.startswith("."))
        found += [os.path.join(root, f) for f in sorted(files) if not f.startswith(".") and _matches(f, globs)]
    return found


def _read_list(arg: str) -> list[str]:
    path = Path(arg[1:])
    try:
        text = path.read_text(encoding="utf-8")
    except FileNotFoundError:
        raise WallcliError(f"no such list file: {path}") from None
    except (OSError, UnicodeDecodeError) as exc:
        raise WallcliError(f"cannot read the list file {path}: {exc}") from None
    # one path or URL a line; blank lines and '#' comments skipped. Entries are taken as written
    # (relative to the current folder, as a shell loop over them would); a missing one becomes an
    # error line of the results, not a stop
    return [s for s in (line.strip() for line in text.splitlines()) if s and not s.startswith("#")]


def expand_inputs(args: list[str], globs: list[str] | None = None, skip: str | os.PathLike | None = None,
                  skipped_as: list[str] | None = None) -> list[str]:
    """The videos named by ``args``, in order, each once.

    A folder gives the files under it whose names match ``globs`` (default: the usual video
    extensions, any case); a file or URL is taken as is; ``@list.txt`` gives its lines. A path on
    the command line that does not exist is an error (a typo should not cost a run), and so is
    finding no video at all. A file found in a folder that is ``skip`` (the results file, which
    may lie among the videos) is left out, and the names it was found under are added to
    ``skipped_as``: the caller decides whether it is the results file or a video it must not
    overwrite.
    """
    from wallcli.errors import UsageError

    skipped = _identity(skip) if skip is not None else None
    out: list[str] = []
    seen: set = set()
    empty_folders = []

    def add(source: str) -> None:
        # one file by any name (./a.mp4, a symlink, a hard link) is one video: scanned once
        keys = {source} if is_url(source) else {os.path.realpath(source), _identity(source)} - {None}
        if not keys & seen:
            seen.update(keys)
            out.append(source)

    for arg in args:
        if arg == "-":  # a usage error: no stdin would do
            raise UsageError("scan reads files, folders, URLs and @lists, not '-' "
                             "(a stream on stdin cannot be resumed or shared between workers)")
        if arg.startswith("@"):
            for entry in _read_list(arg):
                add(entry)
        elif is_url(arg):
            add(arg)
        elif os.path.isdir(arg):
            found = _walk(arg, globs)
            if skipped is not None:
                hits = [f for f in found if _identity(f) == skipped]
                found = [f for f in found if f not in hits]
                if skipped_as is not None:
                    skipped_as += hits
            if not found:
                empty_folders.append(arg)
            for f in found:
                add(f)
        elif os.path.exists(arg):
            add(arg)
        else:
            raise WallcliError(f"no such file or folder: {arg}")
    if not out:
        looked = ", ".join(globs) if globs else "*" + ", *".join(VIDEO_EXTENSIONS)
        where = ", ".join(empty_folders) if empty_folders else "the inputs"
        raise WallcliError(f"no videos found in {where} (looked for {looked})",
                           hint="give --glob for other names")
    return out
