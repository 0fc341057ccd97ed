"""``geardyn simulate``: model I, I-static or II time response of a case to NetCDF (and .mat)."""

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
    StageProgress,
    choice,
    console,
    err_console,
    handle_errors,
    load_case_from_cli,
    progress_bar,
)

#: Default output file of ``geardyn simulate``.
DEFAULT_OUT = Path("sim.nc")


def case_with_options(case, options: dict[str, tuple[str, object]]):
    """``case`` with the values of command-line options that override case values, each with
    its option as the value's source: ``{"stiffness.method": ("--stiffness", "pem")}`` records
    ``stiffness.method = "pem"`` from ``"--stiffness option"``. The record's stored case
    (``case_toml``) is then the case that was run: loaded again it runs the same. An option not
    given (None) leaves the case's value and source."""
    for key, (option, value) in options.items():
        if value is not None:
            case = case.with_overrides({key: value}, source=f"{option} option")
    return case


def _recorded_identity(path: Path) -> tuple[dict | None, int | None]:
    """The inputs identity (:func:`._outputs.recorded_inputs`) and ``complete`` flag a geardyn
    record carries (None if not one)."""
    import h5py
    import numpy as np

    from ._outputs import recorded_inputs

    ident = recorded_inputs(path)
    if ident is None:
        return None, None
    try:
        with h5py.File(path, "r") as f:
            flag = np.asarray(f.attrs.get("complete")).ravel()
        return ident, (int(flag[0]) if flag.size else None)
    except (OSError, ValueError, TypeError):  # (no flag at all: int(None))
        return None, None


@app.command("simulate")
@handle_errors
def simulate(
    config: ConfigOption = None,
    set_: SetOption = None,
    model: Annotated[str | None, typer.Option(
        "--model", "-m", help="I: stiffness at the design centre distance; I-static: at the "
                              "static operating centre distance (eq. 4), held fixed; II: "
                              "iterated with the operating centre distance; any case (default: "
                              "the case's simulation.model).", show_default=False)] = None,
    crack: Annotated[bool, typer.Option("--crack/--no-crack",
                                        help="Include the case's crack and faults (--no-crack: the "
                                             "healthy pair, also without wear's gap).")
                     ] = True,
    out: Annotated[Path | None, typer.Option(
        "--out", "-o", help=f"Output NetCDF file (default: {DEFAULT_OUT}). Re-running the same "
                            "command finds it up to date.", show_default=False)] = None,
    mat: Annotated[bool, typer.Option("--mat", help="Also write a MATLAB .mat file beside it.")
                   ] = False,
    stiffness: Annotated[str | None, typer.Option(
        "--stiffness", help="Mesh stiffness method: pem or fe, any case (default: the case's "
                            "stiffness.method).", show_default=False)] = None,
    force: ForceOption = False,
) -> None:
    """Simulate the gear pair (Newmark, paper section 4) and write the record to OUT."""
    import json
    from typing import get_args

    from ..config import SimulationConfig
    from ..run_limits import check_step_count
    from ._outputs import (
        OutputInUse,
        check_record_name,
        check_writable,
        copies_to_refresh,
        differences,
        identity,
        refuse_different,
        resolve,
    )

    models = get_args(SimulationConfig.model_fields["model"].annotation)  # "I", "I-static", "II"
    model = choice("--model", model, models)
    stiffness = choice("--stiffness", stiffness, ("pem", "fe"))
    target = resolve(out, DEFAULT_OUT)
    out = target.path
    check_record_name(target)  # the record is NetCDF whatever its name: not "x.mat"
    check_writable(target, folder=False)  # before loading anything heavy
    old, complete = _recorded_identity(out) if out.exists() else (None, None)
    if out.exists() and old is None and not force:  # refused before the case and the imports
        raise OutputInUse(target.label, "is an existing file that is not a geardyn record "
                                        "of known inputs", "pass --force to replace it, or "
                                                          "choose another file with --out")
    # the options become the case's values (with their source): the stored case_toml is the
    # effective case, which simulates the same when loaded again
    case = case_with_options(load_case_from_cli(config, set_),
                             {"stiffness.method": ("--stiffness", stiffness),
                              "simulation.model": ("--model", model)})
    which = case.simulation.model
    method = case.stiffness.method
    check_step_count(case.simulation)  # a run that would not end is refused before the imports

    from ..dynamics import save_mat, save_netcdf, summary
    from ..dynamics import simulate as run_simulation
    from ..errors import NumericalError
    from ..io import read_netcdf
    from ..run_limits import check_bounded_work
    from ..stiffness import build_map

    check_bounded_work(case)
    if not crack:  # the healthy pair: no faults at all (no wear gap either)
        from ..faults import without_faults

        case = without_faults(case)
    # --model and --stiffness are in the case now (simulation.model, stiffness.method)
    ident = identity("simulate", case, {"crack": crack})
    mat_path = out.with_suffix(".mat")
    up_to_date = False
    if out.exists():
        diff = differences(old, ident) if old is not None else None
        if diff and not force:
            raise refuse_different(target, diff)
        up_to_date = diff == [] and complete == 1
    elif mat and mat_path.exists() and not force:
        raise OutputInUse(target.label, f"has no record but {mat_path} exists",
                          "pass --force to replace it, or choose another file with --out")
    if up_to_date:
        ds = read_netcdf(out)
        err_console.print(f"[dim]{out} is up to date (same inputs); --force recomputes it[/dim]",
                          highlight=False, soft_wrap=True)
    else:
        with progress_bar() as bar:
            progress = StageProgress(bar)
            progress(f"{method} map", 0, 0)
            smap = build_map(case, method=method, cracked=crack,
                             progress=progress.stage(f"{method} map"))
            progress(f"model {which}", 0, 0)
            try:
                ds = run_simulation(case, smap, model=which, cracked=crack,
                                    progress=progress.stage(f"model {which}"))
            except NumericalError as exc:
                partial = getattr(exc, "partial", None)
                if partial is not None and partial.sizes.get("time", 0):
                    partial.attrs["geardyn_inputs"] = json.dumps(ident)
                    save_netcdf(partial, out)
                    err_console.print(f"[yellow]partial record[/yellow] "
                                      f"({partial.sizes['time']} samples, complete = 0) written "
                                      f"to {out}")
                raise
            progress.close()
        ds.attrs["geardyn_inputs"] = json.dumps(ident)
        save_netcdf(ds, out)
    written = [str(out)]
    # the .mat copy: written when missing or a copy of another record (one this replaced); an
    # unwanted copy of another record is removed, so none is left looking like this one's
    stale_wanted, stale_other = copies_to_refresh(
        out, ds.attrs["geardyn_inputs"], (mat_path,) if mat else ())
    for c in stale_other:
        c.unlink(missing_ok=True)
        err_console.print(f"[dim]removed {c}: a copy of the record {out} held before[/dim]",
                          highlight=False, soft_wrap=True)
    if mat and (not up_to_date or stale_wanted):
        save_mat(ds, mat_path)
    if mat:
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
    if which == "I-static":
        console.print(f"  stiffness held at the static centre distance change "
                      f"{ds.attrs['stiffness_centre_distance_change'] * 1e3:.4f} mm (pressure angle "
                      f"{math.degrees(ds.attrs['stiffness_pressure_angle']):.4f} deg)")
    if which == "II":
        rb = s["max_residual_before_m"]
        console.print(f"  iterating steps {100 * s['steps_iterating_fraction']:.2f} %, at most "
                      f"{s['max_iterations']} iterations; max |b1 - b2| before iterating "
                      f"{rb * 1e6 if math.isfinite(rb) else math.nan:.4g} um")
