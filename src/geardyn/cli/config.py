"""``geardyn config``: show and validate case files, and print their schema."""

from __future__ import annotations

from pathlib import Path
from typing import Annotated

import typer
from rich.markup import escape

from . import app
from ._common import ConfigOption, SetOption, console, err_console, handle_errors

config_app = typer.Typer(help="Show and validate case files (config show, config validate FILE), "
                              "and print their JSON schema (config schema).",
                         no_args_is_help=True)
app.add_typer(config_app, name="config")


@config_app.command("show")
@handle_errors
def show(config: ConfigOption = None, set_: SetOption = None) -> None:
    """Print the effective case as TOML: each value as written (e.g. "20 deg") with its SI value
    beside when it differs, its source and its origin (case file, --set or default). A case that
    'config validate' would refuse is shown all the same, with the reason on standard error."""
    from ..case_checks import check_case
    from ..config import case_to_display_toml, load_case_details, with_written_value
    from ..errors import InputError
    from ._common import one_line

    # a fault that does not fit its tooth is shown too (the case is read to be mended)
    details = load_case_details(config, set_ or [], faults_checked=False)
    typer.echo(case_to_display_toml(details), nl=False)
    try:  # shown to be read, not run: say what the commands that run it would refuse
        check_case(details.case)
    except InputError as exc:
        err_console.print(f"[yellow]note[/yellow]: this case does not pass 'geardyn config "
                          f"validate': {escape(one_line(str(with_written_value(exc, details))))}",
                          highlight=False, soft_wrap=True)


@config_app.command("validate")
@handle_errors
def validate(file: Annotated[Path, typer.Argument(help="Case file (TOML) to check.")],
             set_: SetOption = None) -> None:
    """Check a case file without simulating: exit 0 and say so if it is valid, else name the
    problem (exit 2).

    Runs every check that 'geardyn simulate' and 'geardyn measure' make before their first time
    step, except FE computations, on the case as they run it by default (its simulation.model,
    with its crack and faults): the geometry, crack, faults and FE mesh size; the load laws; the
    run length; the model options; the time-step limit, static operating point and set-up of
    the simulation on the case's stiffness map; the measurement chain and its sample rate.

    Not checked: what only a simulation shows (divergence, the model II iteration, the centre
    distance leaving the map). With stiffness.method = "fe" the checks that need the FE map run
    only if the map is in the cache ('geardyn stiffness' builds it); otherwise the output names
    them: the time-step limit from the map's largest mesh stiffness (the step is still checked
    against the mesh frequency and the natural frequencies without mesh stiffness), the mesh
    stiffness at the static operating point, the tooth modifications and the kernel set-up."""

    from ..case_checks import check_case
    from ..config import load_case_details, with_written_value
    from ..errors import InputError

    try:
        details = load_case_details(file, set_ or [], faults_checked=False)
    except InputError as exc:
        _say_if_sweep_file(file, exc)
        raise
    case = details.case
    try:  # the faults' checks here too, so that an error shows the value as written ("30 mm")
        notes = check_case(case)
    except InputError as exc:
        raise with_written_value(exc, details) from None
    pair = case.gear_pair()
    problems = pair.checks()
    console.print(f"[green]valid[/green]: {escape(str(file))} ({escape(case.name)}, {pair})",
                  highlight=False, soft_wrap=True)
    for p in problems:
        console.print(f"[yellow]warning[/yellow]: {p}", highlight=False, soft_wrap=True)
    for note in notes:
        console.print(f"[yellow]not checked[/yellow]: {escape(note)}", highlight=False,
                      soft_wrap=True)


def _say_if_sweep_file(file, exc) -> None:
    """A sweep file given to ``config validate`` is refused as a case with unknown keys
    (``base``, ``axes``): say what it is and what checks it instead."""
    import tomllib

    from ..errors import InputError

    try:
        data = tomllib.loads(Path(file).read_text(encoding="utf-8"))
    except (OSError, ValueError, UnicodeDecodeError):
        return
    if isinstance(data, dict) and ({"axes", "sample", "base", "execution"} & set(data)):
        raise InputError(str(file), "a sweep file (it has " + ", ".join(
            f"[{k}]" for k in ("base", "axes", "sample", "execution") if k in data) + ")",
            "a case file: config validate checks cases; a sweep file is read, and refused with "
            "its errors before any run, by 'geardyn sweep FILE'") from exc


@config_app.command("schema")
@handle_errors
def schema() -> None:
    """Print the JSON schema of case files."""
    from ..config import case_schema

    typer.echo(case_schema())
