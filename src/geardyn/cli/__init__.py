"""The ``geardyn`` command-line tool: a thin typer shell over the library.

Each command lives in its own module and registers itself on :data:`app`.
"""

from __future__ import annotations

import typer

app = typer.Typer(
    name="geardyn",
    help="Dynamics and vibration diagnostics of flexibly supported spur gears "
         "(Xue & Howard model I / II).",
    no_args_is_help=True,
    add_completion=False,
    pretty_exceptions_enable=False,
    rich_markup_mode="rich",
)

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


for _name in ("stiffness", "simulate", "diagnose", "sweep"):
    _optional(_name)


def main() -> None:
    """Entry point of the ``geardyn`` console script."""
    app()
