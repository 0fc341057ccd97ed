"""``geardyn run``: the paper's case study end to end."""

from __future__ import annotations

from pathlib import Path
from typing import Annotated

import typer

from . import app
from ._common import (
    ConfigOption,
    ForceOption,
    SetOption,
    console,
    err_console,
    handle_errors,
    load_case_from_cli,
    progress_bar,
    refuse_overwrite,
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
    force: ForceOption = False,
) -> None:
    """Reproduce the paper's case study (model I vs II, healthy and cracked) into OUT."""
    from ..errors import InputError
    from ..studies.paper import run_paper_study

    if stiffness is not None and stiffness not in ("fe", "pem"):
        raise InputError("--stiffness", stiffness, "'fe' or 'pem'")
    case = load_case_from_cli(config, set_)
    refuse_overwrite([out / "summary.json", out / "report.html"], force)
    with progress_bar() as bar:
        task = bar.add_task("geardyn run", total=None)

        def progress(stage: str, done: int, total: int) -> None:
            bar.update(task, description=f"run: {stage}", completed=done, total=total)

        result = run_paper_study(case, out, quick=quick, stiffness=stiffness, progress=progress)
    s = result.summary
    from rich.markup import escape
    from rich.table import Table

    t = Table(title=f"geardyn run: {escape(str(result.out))}/", show_lines=False)
    for col in ("quantity", "geardyn", "paper"):
        t.add_column(col, justify="left" if col == "quantity" else "right")
    cr = s.get("contact_ratio", {})
    rows = [("centre distance change \\[mm]", s.get("centre_distance_change_mm"), "~1.07"),
            ("operating pressure angle \\[deg]", s.get("operating_pressure_angle_deg"), "21.18"),
            ("contact ratio, physical / eq. 8",
             f"{cr.get('physical', float('nan')):.4f} / {cr.get('paper_eq8', float('nan')):.4f}",
             "- / 1.43"),
            ("mean pinion speed \\[rad/s]", s.get("mean_pinion_speed_rad_s"), "114.14"),
            ("mean transmission error \\[rad]", s.get("mean_transmission_error_rad"), "0.05"),
            ("crack seen at \\[deg]", s.get("crack_angle_deg"), "~170")]
    for label, ours, paper in rows:
        if ours is None:
            continue
        t.add_row(label, ours if isinstance(ours, str) else f"{ours:.4f}", paper)
    console.print(t)
    val = s.get("validation", [])
    failed = [v for v in val if not v["pass"]]
    console.print(f"validation against the paper: {len(val) - len(failed)}/{len(val)} within "
                  f"tolerance; stages: {', '.join(result.stages)} "
                  f"({sum(result.seconds.values()):.1f} s)")
    for v in failed:
        err_console.print(f"[yellow]outside tolerance[/yellow]: {escape(v['quantity'])}: "
                          f"geardyn {v['geardyn']:.4g}, paper {v['paper']:.4g}")
    report = result.out / "report.html"
    if report.exists():
        console.print(f"report: [bold]{escape(str(report))}[/bold] (self-contained; open it in "
                      "a browser)")
