"""``geardyn config``: show, validate and describe case files."""

from __future__ import annotations

from pathlib import Path
from typing import Annotated

import typer

from . import app
from ._common import ConfigOption, SetOption, console, handle_errors

config_app = typer.Typer(help="Show, validate and describe case files.", no_args_is_help=True)
app.add_typer(config_app, name="config")


@config_app.command("show")
@handle_errors
def show(config: ConfigOption = None, set_: SetOption = None) -> None:
    """Print the effective case as TOML: each value as written (e.g. "20 deg") with its SI value
    beside when it differs, its source and its origin (case file, --set or default)."""
    from ..config import case_to_display_toml, load_case_details

    details = load_case_details(config, set_ or [])
    typer.echo(case_to_display_toml(details), nl=False)


@config_app.command("validate")
@handle_errors
def validate(file: Annotated[Path, typer.Argument(help="Case file (TOML) to check.")],
             set_: SetOption = None) -> None:
    """Check a case file with every check that needs no simulation (geometry, crack, FE mesh
    size, load laws, run length): exit 0 and say so if it is valid, else name the problem
    (exit 2)."""
    from ..case_checks import check_case
    from ..config import load_case

    case = load_case(file, set_ or [])
    check_case(case)
    pair = case.gear_pair()
    problems = pair.checks()
    from rich.markup import escape

    console.print(f"[green]valid[/green]: {escape(str(file))} ({escape(case.name)}, {pair})",
                  highlight=False, soft_wrap=True)
    for p in problems:
        console.print(f"[yellow]warning[/yellow]: {p}", highlight=False, soft_wrap=True)


@config_app.command("schema")
@handle_errors
def schema() -> None:
    """Print the JSON schema of case files."""
    from ..config import case_schema

    typer.echo(case_schema())
