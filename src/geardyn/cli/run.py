"""``geardyn run``: the paper's case study end to end."""

from __future__ import annotations

from pathlib import Path
from typing import Annotated

import typer

from . import app
from ._common import (
    ConfigOption,
    SetOption,
    console,
    err_console,
    handle_errors,
    load_case_from_cli,
    progress_bar,
)


@app.command("run")
@handle_errors
def run(
    config: ConfigOption = None,
    set_: SetOption = None,
    out: Annotated[Path, typer.Option("--out", "-o", help="Output folder.")] = Path("geardyn-out"),
    quick: Annotated[bool, typer.Option("--quick", help="Shorter simulations, coarser maps.")
                     ] = False,
    stiffness: Annotated[str | None, typer.Option(
        "--stiffness", help="Mesh stiffness method: fe or pem (default: the case's).",
        show_default=False)] = None,
) -> None:
    """Reproduce the paper's case study (model I vs II, healthy and cracked) into OUT."""
    from ..errors import InputError
    from ..studies.paper import run_paper_study

    if stiffness is not None and stiffness not in ("fe", "pem"):
        raise InputError("--stiffness", stiffness, "'fe' or 'pem'")
    case = load_case_from_cli(config, set_)
    with progress_bar() as bar:
        task = bar.add_task("geardyn run", total=None)

        def progress(stage: str, done: int, total: int) -> None:
            bar.update(task, description=f"run: {stage}", completed=done, total=total)

        result = run_paper_study(case, out, quick=quick, stiffness=stiffness, progress=progress)
    s = result.summary
    console.print(f"[green]done[/green]: {', '.join(result.stages)} -> {result.out}/")
    console.print(f"  centre distance change {s['centre_distance_change_mm']:.4f} mm, "
                  f"pressure angle {s['operating_pressure_angle_deg']:.4f} deg, contact ratio "
                  f"{s['contact_ratio']['physical']:.4f} (paper eq. 8: "
                  f"{s['contact_ratio']['paper_eq8']:.4f})")
    failed = [v for v in s.get("validation", []) if not v["pass"]]
    if failed:
        err_console.print(f"[yellow]{len(failed)} validation row(s) outside tolerance[/yellow] "
                          "(see summary.json)")


