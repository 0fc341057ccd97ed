"""``geardyn config``: show, validate and describe case files."""

from __future__ import annotations

from pathlib import Path
from typing import Annotated

import typer

from . import app
from ._common import ConfigOption, SetOption, console, handle_errors, load_case_from_cli

config_app = typer.Typer(help="Show, validate and describe case files.", no_args_is_help=True)
app.add_typer(config_app, name="config")


@config_app.command("show")
@handle_errors
def show(config: ConfigOption = None, set_: SetOption = None) -> None:
    """Print the effective case as TOML (SI units, every value with its source)."""
    from ..config import case_to_toml

    case = load_case_from_cli(config, set_)
    typer.echo(case_to_toml(case), nl=False)


@config_app.command("validate")
@handle_errors
def validate(file: Annotated[Path, typer.Argument(help="Case file (TOML) to check.")],
             set_: SetOption = None) -> None:
    """Check a case file: exit 0 and say so if it is valid, else name the problem (exit 2)."""
    case = load_case_from_cli(file, set_)
    pair = case.gear_pair()
    problems = pair.checks()
    console.print(f"[green]valid[/green]: {file} ({case.name}, {pair})")
    for p in problems:
        console.print(f"[yellow]warning[/yellow]: {p}")


@config_app.command("schema")
@handle_errors
def schema() -> None:
    """Print the JSON schema of case files."""
    from ..config import case_schema

    typer.echo(case_schema())
