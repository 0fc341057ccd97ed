"""``geardyn static-te``: the loaded and unloaded static transmission error of the pair (what a
single-flank tester measures), with or without the case's tooth errors and relief."""

from __future__ import annotations

from pathlib import Path
from typing import Annotated

import typer

from . import app
from ._common import (
    ConfigOption,
    ForceOption,
    SetOption,
    choice,
    console,
    err_console,
    handle_errors,
    load_case_from_cli,
    progress_bar,
)

#: Default output file of ``geardyn static-te``.
DEFAULT_OUT = Path("static_te.nc")


@app.command("static-te")
@handle_errors
def static_te(
    config: ConfigOption = None,
    set_: SetOption = None,
    stiffness: Annotated[str | None, typer.Option(
        "--stiffness", help="Mesh stiffness method: pem or fe, any case (default: the case's "
                            "stiffness.method).", show_default=False)] = None,
    torque: Annotated[str | None, typer.Option(
        "--torque", "-t", help="Pinion torque of the loaded TE, a number in N m or a unit "
                               "string such as '100 N m' (default: the case's motor.torque).",
        show_default=False)] = None,
    errors: Annotated[bool, typer.Option(
        "--errors/--no-errors", help="Include the case's [modifications] (tooth errors, relief, "
                                     "runout); --no-errors: perfect involutes.")] = True,
    crack: Annotated[bool, typer.Option(
        "--crack/--no-crack", help="Include the case's crack and faults (spall, breakage, "
                                   "wear...): the faulty pair's map and gaps; --no-crack: the "
                                   "healthy pair.")] = False,
    centre_distance_change: Annotated[str, typer.Option(
        "--centre-distance-change", "--dd", help="Centre distance change d' - d, a number in m "
                                                 "or a unit string such as '0.5 mm'.")] = "0",
    points: Annotated[int, typer.Option(
        "--points", "-n", help="Pinion angles over one hunting period (the tooth pairing's "
                               "repeat).")] = 4096,
    out: Annotated[Path | None, typer.Option(
        "--out", "-o", help=f"Output NetCDF file (default: {DEFAULT_OUT}); the figure is written "
                            "beside it (.png).", show_default=False)] = None,
    force: ForceOption = False,
) -> None:
    """Static transmission error of the pair, unloaded (T = 0) and loaded, along the line of
    action [um] and as pinion rotation [rad], over one hunting period: NetCDF with units to OUT
    and a figure beside it."""
    import json
    import warnings

    from ..errors import InputError
    from ..units import to_si
    from ._outputs import check_writable, claim_file, identity, resolve

    method = choice("--stiffness", stiffness, ("pem", "fe"))
    if not 16 <= points <= 1_000_000:
        raise InputError("--points", points, "an integer from 16 to 1000000")
    target = resolve(out, DEFAULT_OUT)
    out = target.path
    # an unwritable --out (or one below a file, or a folder) fails here, not after the map
    check_writable(target, folder=False)
    png = out.with_suffix(".png")
    from .simulate import case_with_options

    # the stored case_toml is the case that was run (the option recorded as the value's source)
    case = case_with_options(load_case_from_cli(config, set_),
                             {"stiffness.method": ("--stiffness", method)})
    tq = case.motor.torque if torque is None else to_si(torque, "torque", "--torque")
    if not (tq >= 0 and tq < float("inf")):
        raise InputError("--torque", torque, "a finite pinion torque >= 0 [N m]")
    dd = to_si(centre_distance_change, "length", "--centre-distance-change")
    from .geometry import operating_summary

    operating_summary(case.gear_pair(), dd)  # the teeth apart and in mesh, as geometry checks
    lo, hi = case.stiffness.centre_distance_min, case.stiffness.centre_distance_max
    if not lo <= dd <= hi:  # before the map is built: it covers [lo, hi] only
        raise InputError("--centre-distance-change", centre_distance_change,
                         f"a change within the stiffness map's range [{lo * 1e3:.6g}, "
                         f"{hi * 1e3:.6g}] mm, or a wider map (--set "
                         f"stiffness.centre_distance_{'max' if dd > hi else 'min'}=...)")
    from ..faults import faults_from_case

    faults = [f for f in faults_from_case(case) if not f.is_null()]
    if crack and not faults:
        raise InputError("--crack", "the case has no fault (no enabled [crack], no [[faults]] "
                         "of non-zero size)", "--no-crack, or a case with a fault")
    if not crack:  # the healthy pair: no faults at all (no wear gap either)
        from ..faults import without_faults

        case = without_faults(case)
    ident = identity("static-te", case, {"crack": crack, "torque_N_m": tq, "errors": errors,
                                         "centre_distance_change_m": dd, "points": points})
    if claim_file(target, ident, force=force, companions=(png,)):
        from ..io import read_netcdf

        err_console.print(f"[dim]{out} is up to date (same inputs); --force recomputes it[/dim]",
                          highlight=False, soft_wrap=True)
        ds = read_netcdf(out)
        _say(ds, out, png, points, case, crack, faults, bool(ds.attrs.get("tooth_errors", 0)),
             verb="kept")
        return

    from ..io import atomic_path, write_netcdf_atomic
    from ..modifications import ToothModifications
    from ..static_te import fig_static_te, static_te_curves
    from ..stiffness import build_map

    mods = ToothModifications.from_case(case)  # bad tables fail before the map is built
    with progress_bar() as bar, warnings.catch_warnings():
        warnings.simplefilter("ignore", UserWarning)  # map validity notes: in its attrs
        task = bar.add_task(f"{case.stiffness.method} map", total=None)

        def tick(done: int, total: int) -> None:
            bar.update(task, completed=done, total=total)

        smap = build_map(case, cracked=crack, progress=tick)
    ds = static_te_curves(case, tq, cracked=crack, errors=errors, stiffness_map=smap,
                          centre_distance_change=dd, n=points)
    ds.attrs["map_torque_N_m"] = float(case.motor.torque)
    ds.attrs["tooth_errors"] = int(bool(errors and mods.active))
    ds.attrs["geardyn_inputs"] = json.dumps(ident)
    fig = fig_static_te(ds)
    with atomic_path(png, suffix=".png") as tmp:  # the figure first: the NetCDF marks it done
        fig.savefig(tmp, dpi=150, format="png")
    write_netcdf_atomic(ds, out)
    _say(ds, out, png, points, case, crack, faults, errors and mods.active)


def _say(ds, out, png, points, case, crack, faults, errors_active, verb: str = "wrote"
         ) -> None:
    """The summary lines of a static-TE result (computed now or up to date)."""
    te = ds["transmission_error"].values
    kinds = sorted({f.kind.replace("_", " ") for f in faults})
    pair = (("faulty: " + ", ".join(kinds)) if crack else
            "healthy" + (f" (the case's {', '.join(kinds)} left out; --crack includes it)"
                         if faults else ""))
    console.print(f"[green]{verb}[/green] {out}, {png}: static TE over {points} pinion angles "
                  f"({case.stiffness.method} map, {pair}, "
                  f"{'with the case' + chr(39) + 's tooth errors' if errors_active else 'perfect teeth'})",
                  highlight=False, soft_wrap=True)
    for i, t in enumerate(ds["torque"].values):
        console.print(f"  T = {t:g} N m: mean {te[i].mean():.4g} um, peak-to-peak "
                      f"{te[i].max() - te[i].min():.4g} um along the line of action",
                      highlight=False)
    map_t = float(ds.attrs.get("map_torque_N_m", case.motor.torque))
    if case.stiffness.method == "fe" and any(abs(float(t) - map_t) > 1e-9 * max(map_t, 1.0)
                                             for t in ds["torque"].values if t > 0):
        console.print(f"  note: the FE map's contact was solved at motor.torque = {map_t:g} N m "
                      "and is used at the other torques as it is; for a map at another load: "
                      "--set motor.torque=...", highlight=False, soft_wrap=True)
