"""wallcli: what you can learn by staring at a blank wall.

The package is a pipeline: ``io`` (bytes <-> arrays) -> ``signal`` (the method, pure numpy)
-> ``plots`` / ``infer`` / ``sim`` -> ``cli``. Nothing below ``cli`` prints.

From Python (docs/api.md): ``wallcli.count``, ``activity``, ``track``, ``stplot`` and ``snr``
return what the commands write. They live in :mod:`wallcli.api`, loaded on first use, so that
``import wallcli`` (and ``wallcli --help``) stays free of numpy, PyAV and onnxruntime.
"""
import sys as _sys
import types as _types

__version__ = "0.1.0"
API = ("count", "activity", "track", "stplot", "snr")
__all__ = ["__version__", *API]


def __getattr__(name):
    if name == "snr":  # the subpackage, made callable (below)
        import wallcli.snr

        return _sys.modules["wallcli.snr"]
    if name in API:
        from wallcli import api

        return getattr(api, name)
    raise AttributeError(f"module 'wallcli' has no attribute {name!r}")


def __dir__():
    return sorted(set(globals()) | set(API))


class _CallableSnr(_types.ModuleType):
    """``wallcli.snr`` names both wallcli/snr/ (the estimator's subpackage) and the API's function.
    Python sets an imported subpackage as its parent's attribute, so the attribute is the
    subpackage, made callable: ``wallcli.snr(path)`` is :func:`wallcli.api.snr`, and
    ``wallcli.snr.estimate`` and ``import wallcli.snr.estimate as e`` work as before."""

    def __call__(self, *args, **kwargs):
        from wallcli.api import snr

        return snr(*args, **kwargs)


class _Package(_types.ModuleType):
    def __setattr__(self, name, value):
        if name == "snr" and type(value) is _types.ModuleType:
            value.__class__ = _CallableSnr
        super().__setattr__(name, value)


_sys.modules[__name__].__class__ = _Package
