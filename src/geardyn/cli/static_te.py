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
    handle_errors,
    load_case_from_cli,
    progress_bar,
    refuse_overwrite,
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
    crack: Annotated[bool, typer.Option("--crack/--no-crack",
                                        help="Use the cracked stiffness map.")] = False,
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
    import warnings

    from ..errors import InputError
    from ..units import to_si
    from ._outputs import check_writable, resolve

    method = choice("--stiffness", stiffness, ("pem", "fe"))
    if not 16 <= points <= 1_000_000:
        raise InputError("--points", points, "an integer from 16 to 1000000")
    target = resolve(out, DEFAULT_OUT)
    out = target.path
    # an unwritable --out (or one below a file, or a folder) fails here, not after the map
    check_writable(target, folder=False)
    png = out.with_suffix(".png")
    refuse_overwrite([out, png], force)
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
    has_crack = case.crack is not None and case.crack.active
    if crack and not has_crack:
        raise InputError("--crack", "the case has no enabled crack", "--no-crack, or a case "
                         "with an enabled [crack]")

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
    write_netcdf_atomic(ds, out)
    fig = fig_static_te(ds)
    with atomic_path(png, suffix=".png") as tmp:
        fig.savefig(tmp, dpi=150, format="png")
    te = ds["transmission_error"].values
    active = errors and mods.active
    console.print(f"[green]wrote[/green] {out}, {png}: static TE over {points} pinion angles "
                  f"({case.stiffness.method} map, {'cracked' if crack else 'healthy'}, "
                  f"{'with the case' + chr(39) + 's tooth errors' if active else 'perfect teeth'})")
    for i, t in enumerate(ds["torque"].values):
        console.print(f"  T = {t:g} N m: mean {te[i].mean():.4g} um, peak-to-peak "
                      f"{te[i].max() - te[i].min():.4g} um along the line of action")
