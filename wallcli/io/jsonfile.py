"""The one JSON parser for everything wallcli reads back (model cards, .npz metadata, results
lines, sidecars, manifests): a depth limit, so that a hostile or damaged file is refused as bad
JSON instead of ending in a RecursionError deep inside Python's parser or in whatever walks the
result afterwards (report's templates, a resume's comparisons)."""

from __future__ import annotations

import json
from typing import Any

# wallcli's own files nest fewer than ten levels; 64 leaves room for fields added later while
# staying far below Python's recursion limit for any code that walks the object.
MAX_DEPTH = 64


def _no_constant(name: str):
    # Python's json reads NaN and Infinity, which JSON does not have
    raise ValueError(f"{name} is not a JSON number")


def loads(text: str | bytes, *, allow_nan: bool = False) -> Any:
    """``json.loads`` that raises ``json.JSONDecodeError`` (a ValueError) for anything nested more
    than MAX_DEPTH deep and, unless ``allow_nan``, for NaN and Infinity: callers that already
    handle bad JSON handle these too."""
    if isinstance(text, bytes):
        text = text.decode("utf-8")
    try:
        obj = json.loads(text) if allow_nan else json.loads(text, parse_constant=_no_constant)
    except RecursionError:
        raise _too_deep(text) from None
    except ValueError as exc:
        if isinstance(exc, json.JSONDecodeError):
            raise
        raise json.JSONDecodeError(str(exc), text, 0) from None
    if _depth_exceeds(obj, MAX_DEPTH):
        raise _too_deep(text)
    return obj


def _too_deep(text: str) -> json.JSONDecodeError:
    return json.JSONDecodeError(f"nested more than {MAX_DEPTH} deep", text, 0)


def _depth_exceeds(obj: Any, limit: int) -> bool:
    # iterative: the point is to never recurse on untrusted nesting
    stack = [(obj, 1)]
    while stack:
        o, d = stack.pop()
        if isinstance(o, dict):
            children = o.values()
        elif isinstance(o, list):
            children = o
        else:
            continue
        if d > limit:
            return True
        stack.extend((c, d + 1) for c in children if isinstance(c, (dict, list)))
    return False


def plain(obj: Any) -> Any:
    """``obj`` made JSON-safe as wallcli writes it: numpy scalars and arrays as Python numbers and
    lists, tuples as lists, keys as str, NaN and infinities as None (never invalid JSON). The one
    conversion behind every ``--json`` and the Python API (wallcli.api), so that both give one object."""
    import math

    if isinstance(obj, dict):
        return {str(k): plain(v) for k, v in obj.items()}
    if isinstance(obj, (list, tuple)):
        return [plain(v) for v in obj]
    if hasattr(obj, "tolist") and not isinstance(obj, (str, bytes)):
        return plain(obj.tolist())
    if isinstance(obj, float):
        return obj if math.isfinite(obj) else None
    return obj
