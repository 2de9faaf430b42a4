"""File names in text outputs.

A file name that is not valid UTF-8 reaches Python as a str with lone surrogates (PEP 383: byte
0xff becomes U+DCFF). No UTF-8 file can hold those, so every text output (JSON, CSV, HTML,
figure titles) writes each one as the six characters ``\\udcff``: JSON readers turn that back
into the same str (``os.fsencode`` of it gives the original bytes), and the others show it as
it is. One escape for all formats, so a name looks the same in all of them.
"""
from __future__ import annotations

import re

_SURROGATE = re.compile("[\ud800-\udfff]")
_ESCAPED = re.compile(r"\\u(d[89a-f][0-9a-f]{2})")


def escape_surrogates(text: str) -> str:
    return _SURROGATE.sub(lambda m: f"\\u{ord(m.group()):04x}", text)


def unescape_surrogates(text: str) -> str:
    """The inverse of :func:`escape_surrogates`, for reading back a non-JSON output (the CSV)."""
    return _ESCAPED.sub(lambda m: chr(int(m.group(1), 16)), text)
