"""``geardyn simulate``: model I or model II time response of a case to NetCDF (and .mat)."""

from __future__ import annotations

import math
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


@app.command("simulate")
@handle_errors
def simulate(
    config: ConfigOption = None,
    set_: SetOption = None,
    model: Annotated[str | None, typer.Option(
        "--model", "-m", help="I: stiffness at the design centre distance; II: iterated with the "
                              "operating centre distance (default: the case's simulation.model).",
        show_default=False)] = None,
    crack: Annotated[bool, typer.Option("--crack/--no-crack",
                                        help="Include the case's tooth crack in the stiffness.")
                     ] = True,
    out: Annotated[Path, typer.Option("--out", "-o", help="Output NetCDF file.")
                   ] = Path("sim.nc"),
    mat: Annotated[bool, typer.Option("--mat", help="Also write a MATLAB .mat file beside it.")
                   ] = False,
    stiffness: Annotated[str | None, typer.Option(
        "--stiffness", help="Mesh stiffness method: pem or fe (default: the case's).",
        show_default=False)] = None,
    force: ForceOption = False,
) -> None:
    """Simulate the gear pair (Newmark, paper section 4) and write the record to OUT."""
    from ..dynamics import save_mat, save_netcdf, summary
    from ..dynamics import simulate as run_simulation
    from ..errors import InputError, NumericalError
    from ..stiffness import build_map

    case = load_case_from_cli(config, set_)
    which = case.simulation.model if model is None else model.strip().upper()
    if which not in ("I", "II"):
        raise InputError("--model", model, "I or II")
    if stiffness is not None and stiffness not in ("pem", "fe"):
        raise InputError("--stiffness", stiffness, "'pem' or 'fe'")
    if out.exists() and out.is_dir():
        raise InputError("--out", str(out), "a file path (it is a folder)")
    refuse_overwrite([out] + ([out.with_suffix(".mat")] if mat else []), force)
    with progress_bar() as bar:
        task = bar.add_task("stiffness map", total=None)

        def map_progress(done: int, total: int) -> None:
            bar.update(task, completed=done, total=total)

        smap = build_map(case, method=stiffness, cracked=crack, progress=map_progress)
        bar.update(task, description=f"model {which}", completed=0, total=None)

        def sim_progress(done: int, total: int) -> None:
            bar.update(task, completed=done, total=total)

        try:
            ds = run_simulation(case, smap, model=which, cracked=crack, progress=sim_progress)
        except NumericalError as exc:
            partial = getattr(exc, "partial", None)
            if partial is not None and partial.sizes.get("time", 0):
                save_netcdf(partial, out)
                err_console.print(f"[yellow]partial record[/yellow] ({partial.sizes['time']} "
                                  f"samples, complete = 0) written to {out}")
            raise
    save_netcdf(ds, out)
    written = [str(out)]
    if mat:
        mat_path = out.with_suffix(".mat")
        save_mat(ds, mat_path)
        written.append(str(mat_path))
    s = summary(ds)
    console.print(f"[green]done[/green]: model {which}, {ds.sizes['time']} samples over "
                  f"{float(ds.time[-1] - ds.time[0]):.4g} s -> {', '.join(written)}")
    console.print(f"  mean pinion speed {s['mean_pinion_speed_rad_s']:.5g} rad/s, mean mesh force "
                  f"{s['mean_mesh_force_N']:.5g} N, centre distance change "
                  f"{s['mean_centre_distance_change_m'] * 1e3:.4f} mm")
    console.print(f"  pressure angle {s['mean_pressure_angle_deg']:.4f} deg, contact ratio "
                  f"{s['mean_contact_ratio']:.4f} (paper eq. 8: {s['mean_contact_ratio_eq8']:.4f})"
                  f", transmission error {s['mean_transmission_error_rad']:.5g} rad "
                  f"(std {s['std_transmission_error_rad']:.3g})")
    if which == "II":
        rb = s["max_residual_before_m"]
        console.print(f"  iterating steps {100 * s['steps_iterating_fraction']:.2f} %, at most "
                      f"{s['max_iterations']} iterations; max |b1 - b2| before iterating "
                      f"{rb * 1e6 if math.isfinite(rb) else math.nan:.4g} um")
