"""The ``geardyn`` command-line tool: a thin typer shell over the library.

Each command lives in its own module and registers itself on :data:`app`. :func:`main` (the
console script) adds what a user expects of any command-line tool: ``--version``, ``-h`` as well
as ``--help`` on every command, flags shown without a type, and Python warnings as one clean
line.
"""

from __future__ import annotations

from typing import Annotated

import typer

app = typer.Typer(
    name="geardyn",
    help="Dynamics and vibration diagnostics of flexibly supported spur gears "
         "(Xue & Howard model I / II).",
    no_args_is_help=True,
    add_completion=True,
    pretty_exceptions_enable=False,
    rich_markup_mode="rich",
    context_settings={"help_option_names": ["-h", "--help"]},
)


def _print_version(value: bool) -> None:
    if value:
        from .._version import __version__

        typer.echo(f"geardyn {__version__}")
        raise typer.Exit()


@app.callback()
def _root(
    version: Annotated[bool, typer.Option("--version", "-V", is_eager=True,
                                          callback=_print_version,
                                          help="Show geardyn's version and exit.")] = False,
) -> None:
    pass


# command modules register themselves on `app` when imported
from . import config as _config  # noqa: E402,F401
from . import geometry as _geometry  # noqa: E402,F401
from . import run as _run  # noqa: E402,F401


def _optional(name: str) -> None:
    import importlib

    try:
        importlib.import_module(f"{__name__}.{name}")
    except ModuleNotFoundError as exc:  # a command whose module is not written yet
        if exc.name != f"{__name__}.{name}":
            raise


for _name in ("stiffness", "simulate", "diagnose", "sweep", "measure", "static_te",
              "study", "crack_growth", "cache"):
    _optional(_name)


def _literal_brackets(text: str) -> str:
    """``text`` with every ``[`` escaped for rich markup (``[um]`` stays ``[um]``, not a style);
    an already escaped ``\\[`` is left as it is."""
    import re

    return re.sub(r"(?<!\\)\[", r"\\[", text)


def _tidy_help(command, ctx_settings: dict) -> None:
    """Walk the click command tree: flags without a ``<bool>`` type, arguments named in capitals,
    square brackets in help texts (options' and commands' own) shown literally (rich markup would
    eat ``[s]``), and ``-h``."""
    import inspect

    try:
        import typer._click as click  # the click typer vendors (typer >= 0.2x)
    except ImportError:  # pragma: no cover - older typer on the real click
        import click

    ctx = click.Context(command, info_name=command.name, **ctx_settings)
    command.get_help_option(ctx)  # create (and cache) the -h/--help option now
    params = list(command.params) + [p for p in [getattr(command, "_help_option", None)] if p]
    for p in params:
        if getattr(p, "is_flag", False):
            p.metavar = ""
        elif getattr(p, "param_type_name", "") == "argument" and p.metavar is None:
            p.metavar = (p.name or "arg").upper()
        if getattr(p, "help", None):
            p.help = _literal_brackets(p.help)
    if getattr(command, "help", None):  # docstring line breaks are not paragraph breaks
        command.help = _literal_brackets(
            "\n\n".join(" ".join(par.split())
                         for par in inspect.cleandoc(command.help).split("\n\n")))
    for attr in ("short_help", "epilog"):
        if getattr(command, attr, None):
            setattr(command, attr, _literal_brackets(getattr(command, attr)))
    for sub in (getattr(command, "commands", None) or {}).values():
        _tidy_help(sub, ctx_settings)


def main() -> None:
    """Entry point of the ``geardyn`` console script."""
    import warnings

    from ..processes import skip_collection_at_exit
    from ._common import warning_line

    skip_collection_at_exit()
    warnings.showwarning = warning_line
    command = typer.main.get_command(app)
    _tidy_help(command, {"help_option_names": ["-h", "--help"]})
    command(prog_name="geardyn")
