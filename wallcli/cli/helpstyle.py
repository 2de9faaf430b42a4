"""One style for every command's ``--help``, set here rather than option by option.

Usage lines read ``wallcli CMD [OPTIONS] INPUT``: an argument in capitals, ``[INPUT]`` when it
may be left out, ``INPUT...`` when it may be repeated. An option's value is named in capitals
by what it takes (PATH, TEXT, INTEGER, NUMBER, or a shape such as X,Y,W,H). typer's own
rendering mixed ``{input}``, ``[input]``, ``{DIR}`` and ``<list[str]>`` depending on how each
parameter happened to be declared; a command module may still name a value itself (``metavar=``).
"""
from __future__ import annotations

import typing
from pathlib import PurePath

from typer.core import TyperCommand

# Values whose shape says more than their type; the same option reads alike in every command.
SHAPES = {
    "--roi": "X,Y,W,H",
    "--size": "WxH",
    "--grid": "RxC",
    "--distance": "MIN,MAX",  # simulate's; snr's --distance is a number option with its own metavar
    "--speed": "MIN,MAX",
    "--sweep": "NAME=START:STOP:STEP",
    "--scale": "FACTOR|WxH",
}


def _is_path(param) -> bool:
    desc = getattr(param, "type_descriptor", None)  # newer typer; older ones give a click type
    if desc is None:
        return type(getattr(param, "type", None)).__name__ == "Path"
    annotation = getattr(desc, "annotation", None)
    args = typing.get_args(annotation)  # a repeatable option: list[Path]
    return bool(getattr(desc, "is_path", False)) or any(isinstance(a, type) and issubclass(a, PurePath) for a in args)


def value_name(param) -> str:
    """The capitalised name of what ``param`` takes."""
    if param.param_type_name == "argument":
        return param.name.upper()
    for opt in param.opts:
        if opt in SHAPES:
            return SHAPES[opt]
    if _is_path(param):
        return "PATH"
    annotation = getattr(getattr(param, "type_descriptor", None), "annotation", None)
    kind = getattr(getattr(param, "type", None), "name", "")  # older typer: a click type
    if annotation is int or kind == "integer":
        return "INTEGER"
    if annotation is float or kind == "float":
        return "NUMBER"
    return "TEXT"


def _takes_value(param) -> bool:
    return param.param_type_name == "argument" or not (getattr(param, "is_flag", False) or getattr(param, "count", False))


class Command(TyperCommand):
    """A typer command whose help follows this module's style."""

    def __init__(self, *args, **kwargs) -> None:
        super().__init__(*args, **kwargs)
        for param in self.params:
            if param.metavar is None and _takes_value(param) and param.name != "help":
                param.metavar = value_name(param)

    def collect_usage_pieces(self, ctx) -> list[str]:
        pieces = [self.options_metavar] if self.options_metavar else []
        for param in self.get_params(ctx):
            if param.param_type_name == "argument":
                pieces.append(_argument_name(param, usage=True))
        return pieces

    def format_options(self, ctx, formatter) -> None:
        args, opts = [], []
        for param in self.get_params(ctx):
            record = param.get_help_record(ctx)
            if record is None:
                continue
            if param.param_type_name == "argument":
                # typer would write 'input <str>': the name and its type, twice the same thing
                args.append((_argument_name(param, usage=False), record[1]))
            else:
                opts.append(record)
        for title, rows in (("Arguments", args), ("Options", opts)):
            if rows:
                with formatter.section(title):
                    formatter.write_dl(rows)


def _argument_name(param, *, usage: bool) -> str:
    name = param.metavar or param.name.upper()
    if param.nargs != 1:
        name += "..."
    return f"[{name}]" if usage and not param.required else name
