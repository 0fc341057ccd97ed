"""Shared pieces of the command-line tool: common options, case loading, error handling.

Every command takes ``--config FILE`` and repeatable ``--set dotted.key=value``. Errors a user can
cause (:class:`geardyn.errors.GeardynError`) print one line naming the field, the value and what is
allowed, and exit with status 2; Ctrl-C exits with 130; nothing prints a traceback unless
``GEARDYN_DEBUG=1``.
"""

from __future__ import annotations

import functools
import os
import sys
from collections.abc import Callable
from pathlib import Path
from typing import Annotated, Any, TypeVar

import typer
from rich.console import Console
from rich.markup import escape

from ..errors import GeardynError

__all__ = ["ConfigOption", "SetOption", "OutOption", "ForceOption", "refuse_overwrite",
           "load_case_from_cli", "handle_errors",
           "console", "err_console", "progress_bar"]

F = TypeVar("F", bound=Callable[..., Any])

console = Console()
err_console = Console(stderr=True)

ConfigOption = Annotated[
    Path | None,
    typer.Option("--config", "-c", help="Case file (TOML). Default: the paper's case shipped with "
                                        "geardyn.", show_default=False),
]
SetOption = Annotated[
    list[str] | None,
    typer.Option("--set", "-s", help="Override a case value: dotted.key=value (repeatable), e.g. "
                                     "--set pinion.teeth=25 --set simulation.dt='5e-6 s'.",
                 show_default=False),
]
OutOption = Annotated[
    Path,
    typer.Option("--out", "-o", help="Output folder."),
]
ForceOption = Annotated[
    bool,
    typer.Option("--force", "-f", help="Overwrite existing outputs."),
]


def refuse_overwrite(paths, force: bool, option: str = "--out") -> None:
    """Raise an InputError naming ``option`` if any of ``paths`` exists and not ``force``."""
    from ..errors import InputError

    existing = [str(p) for p in paths if Path(p).exists()]
    if existing and not force:
        raise InputError(option, existing[0], "a path with no earlier result in it (it exists; "
                                              "pass --force to overwrite, or choose another "
                                              f"{option})")


def load_case_from_cli(config: Path | None, overrides: list[str] | None):
    """Load the case named by ``--config`` (or the paper's) with the ``--set`` overrides."""
    from ..config import load_case

    return load_case(config, overrides or [])


def handle_errors(fn: F) -> F:
    """Turn geardyn errors into one clear line and exit code 2 (130 on Ctrl-C)."""

    @functools.wraps(fn)
    def wrapper(*args: Any, **kwargs: Any) -> Any:
        try:
            return fn(*args, **kwargs)
        except typer.Exit:
            raise
        except GeardynError as exc:
            if os.environ.get("GEARDYN_DEBUG"):
                raise
            err_console.print(f"[bold red]error:[/bold red] {escape(str(exc))}", highlight=False,
                              soft_wrap=True)
            raise typer.Exit(2) from None
        except KeyboardInterrupt:
            err_console.print("[yellow]interrupted[/yellow]: finished results and caches are "
                              "kept; re-run the same command to continue.")
            raise typer.Exit(130) from None
        except Exception as exc:  # a bug: say so briefly, keep the traceback for GEARDYN_DEBUG
            if os.environ.get("GEARDYN_DEBUG"):
                raise
            err_console.print(f"[bold red]internal error:[/bold red] {type(exc).__name__}: "
                              f"{escape(str(exc))}"
                              "\n(this is a bug in geardyn; set GEARDYN_DEBUG=1 to see the "
                              "traceback)", highlight=False, soft_wrap=True)
            raise typer.Exit(1) from None

    return wrapper  # type: ignore[return-value]


def progress_bar():
    """A rich progress display for long stages (writes to stderr, hidden when not a terminal
    unless ``GEARDYN_PROGRESS=1``)."""
    from rich.progress import (
        BarColumn,
        MofNCompleteColumn,
        Progress,
        TextColumn,
        TimeElapsedColumn,
        TimeRemainingColumn,
    )

    disable = not (err_console.is_terminal or os.environ.get("GEARDYN_PROGRESS"))
    return Progress(TextColumn("[bold]{task.description}"), BarColumn(), MofNCompleteColumn(),
                    TimeElapsedColumn(), TimeRemainingColumn(), console=err_console,
                    disable=disable, transient=False)


def exit_code_of(exc: BaseException) -> int:  # pragma: no cover - helper for scripts
    """Exit status geardyn uses for an exception."""
    return 2 if isinstance(exc, GeardynError) else (130 if isinstance(exc, KeyboardInterrupt)
                                                    else 1)


def eprint(*args: Any) -> None:
    """Print to stderr without markup."""
    print(*args, file=sys.stderr)
