"""Jinja2 with autoescape: every value from a file (names, metadata, tags) reaches the page as text.

Pages are self-contained and say so to the browser: a Content-Security-Policy that allows no
network at all (images only as data: URIs) and only the page's own style and script, named by
their sha256. Even a value that escaped escaping could neither run nor fetch anything.
"""
from __future__ import annotations

import base64
import hashlib
import math
from functools import lru_cache

from markupsafe import Markup


@lru_cache(maxsize=1)
def environment():
    from jinja2 import Environment, PackageLoader, StrictUndefined

    env = Environment(loader=PackageLoader("wallcli.report", "templates"), autoescape=True,
                      undefined=StrictUndefined, trim_blocks=True, lstrip_blocks=True, keep_trailing_newline=True)
    env.filters.update(pct=pct, num=num, ci=ci, nbytes=nbytes, hms=hms, db=db, path_breaks=path_breaks)
    return env


def asset(name: str) -> str:
    """A static file of the templates folder (style, script), as text."""
    env = environment()
    return env.loader.get_source(env, name)[0]


def _hash(text: str) -> str:
    return "'sha256-" + base64.b64encode(hashlib.sha256(text.encode("utf-8")).digest()).decode("ascii") + "'"


def csp(styles: list[str], scripts: list[str]) -> str:
    def sources(texts):
        return " ".join(map(_hash, texts)) or "'none'"

    return (f"default-src 'none'; img-src data:; style-src {sources(styles)}; script-src {sources(scripts)}; "
            "base-uri 'none'; form-action 'none'")


def render(template: str, *, scripts: tuple[str, ...] = (), **context) -> str:
    """Render ``template`` with the shared style and the named scripts inlined (trusted package data)."""
    from wallcli import __version__

    from wallcli.io.text import escape_surrogates

    style = asset("style.css")
    code = [asset(s) for s in scripts]
    context.setdefault("wallcli_version", __version__)
    # a file name that is not UTF-8 (in a title, a table, the command line) is shown escaped as in
    # JSON: the page is UTF-8 and cannot hold its raw bytes
    return escape_surrogates(environment().get_template(template).render(
        csp=csp([style], code), style=Markup(style), scripts=[Markup(c) for c in code], **context))


def path_breaks(name) -> Markup:
    """A file name, escaped, that a narrow column breaks after each '/' (a break opportunity,
    <wbr>) rather than anywhere inside a folder's or file's name."""
    from markupsafe import escape

    return Markup("/<wbr>").join(escape(part) for part in str(name).split("/"))


# ---------------------------------------------------------------------------- number filters
def _finite(x) -> bool:
    return isinstance(x, (int, float)) and not isinstance(x, bool) and math.isfinite(x)


def num(x, fmt: str = "{:.3g}", missing: str = "—") -> str:
    return fmt.format(x) if _finite(x) else missing


def db(x, missing: str = "—") -> str:
    """A dB figure as every other output writes it (one decimal, never -0.0)."""
    from wallcli.wording import format_db

    return format_db(x) if _finite(x) else missing


def pct(x, digits: int = 1) -> str:
    return f"{100 * x:.{digits}f} %" if _finite(x) else "—"


def ci(x) -> str:
    if isinstance(x, (list, tuple)) and len(x) == 2 and all(_finite(v) for v in x):
        return f"95 % interval {100 * x[0]:.0f}–{100 * x[1]:.0f} %"
    return ""


def nbytes(n) -> str:
    if not _finite(n):
        return "—"
    size, unit = float(n), "bytes"
    for unit in ("bytes", "KB", "MB", "GB", "TB"):
        if abs(size) < 1000 or unit == "TB":
            break
        size /= 1000.0
    return f"{int(n):,} bytes" if unit == "bytes" else f"{size:.1f} {unit} ({int(n):,} bytes)"


def hms(seconds) -> str:
    if not _finite(seconds):
        return "—"
    s = float(seconds)
    if s < 60:
        return f"{s:.2f} s"
    h, rem = divmod(int(round(s)), 3600)
    m, sec = divmod(rem, 60)
    return f"{h}:{m:02d}:{sec:02d}" if h else f"{m}:{sec:02d}"
