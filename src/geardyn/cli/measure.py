"""``geardyn measure``: simulate a case and write what a housing accelerometer and a tachometer
record (NetCDF, optionally CSV and .mat)."""

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

#: Default output file of ``geardyn measure``.
DEFAULT_OUT = Path("measurement.nc")


@app.command("measure")
@handle_errors
def measure(
    config: ConfigOption = None,
    set_: SetOption = None,
    model: Annotated[str | None, typer.Option(
        "--model", "-m", help="I, I-static or II, any case (default: the case's "
                              "simulation.model).",
        show_default=False)] = None,
    crack: Annotated[bool, typer.Option("--crack/--no-crack",
                                        help="Include the case's crack and faults (--no-crack: "
                                             "the healthy pair, also without wear's gap).")
                     ] = True,
    out: Annotated[Path | None, typer.Option(
        "--out", "-o", help=f"Output NetCDF file (default: {DEFAULT_OUT}).", show_default=False)
                   ] = None,
    csv: Annotated[bool, typer.Option("--csv", help="Also write a CSV file beside it.")] = False,
    mat: Annotated[bool, typer.Option("--mat", help="Also write a MATLAB .mat file beside it.")
                   ] = False,
    stiffness: Annotated[str | None, typer.Option(
        "--stiffness", help="Mesh stiffness method: pem or fe (default: the case's).",
        show_default=False)] = None,
    force: ForceOption = False,
) -> None:
    """Simulate the gear pair, pass the bearing forces through the case's measurement chain
    (housing modes, accelerometer, anti-alias filter, sampling, noise, ADC, tachometer) and write
    the record (case.simulation.record_time long) to OUT."""
    import json
    from typing import get_args

    from ._outputs import (
        check_record_name,
        check_writable,
        claim_file,
        copies_to_refresh,
        identity,
        resolve,
    )

    target = resolve(out, DEFAULT_OUT)
    out = target.path
    # before loading anything heavy: an unwritable --out (or one below a file, or a folder)
    # fails at once, not after the simulation
    check_record_name(target)
    check_writable(target, folder=False)

    from ..case_checks import check_measurement
    from ..config import SimulationConfig
    from ..errors import InputError
    from ..measurement.record import write_csv, write_mat, write_netcdf
    from ..stiffness import build_map
    from ..studies.measure import measure as run_measure

    models = get_args(SimulationConfig.model_fields["model"].annotation)  # "I", "I-static", "II"
    model = choice("--model", model, models)  # before the case: a bad name fails at once
    if stiffness is not None and stiffness not in ("pem", "fe"):
        raise InputError("--stiffness", stiffness, "'pem' or 'fe'")
    from .simulate import case_with_options

    # the options become the case's values (with their source): the record's case_toml is the
    # case that was run, which measures the same when loaded again
    case = case_with_options(load_case_from_cli(config, set_),
                             {"stiffness.method": ("--stiffness", stiffness),
                              "simulation.model": ("--model", model)})
    if not crack:  # the healthy pair: no faults at all (no wear gap either)
        from ..faults import without_faults

        case = without_faults(case)
    which = case.simulation.model
    companions = tuple([out.with_suffix(".csv")] if csv else []) \
        + tuple([out.with_suffix(".mat")] if mat else [])
    check_measurement(case)  # bad chain settings and sample rate fail before the simulation
    # the CSV and MATLAB copies are other formats of the same record, not other inputs: a
    # re-run with fewer of them is up to date, one with more writes them from the record
    ident = identity("measure", case, {"crack": crack})
    inputs_json = json.dumps(ident)

    def remove_stale(stale: list[Path]) -> None:
        """Copies of a record this one replaced: removed, and said (issue 6, "nothing
        silently wrong": a forced re-run without --csv left the old record's CSV)."""
        for c in stale:
            c.unlink(missing_ok=True)
        if stale:
            err_console.print(f"[dim]removed {', '.join(str(c) for c in stale)}: a copy of "
                              f"the record {out} held before[/dim]", highlight=False,
                              soft_wrap=True)

    if claim_file(target, ident, force=force, companions=companions, companions_needed=False):
        # copies missing, or left by a record this one replaced, are written from the record
        stale_wanted, stale_other = copies_to_refresh(out, inputs_json, companions)
        remove_stale(stale_other)
        if stale_wanted:
            from ..io import read_netcdf

            record = read_netcdf(out)
            for c in stale_wanted:
                (write_csv if c.suffix == ".csv" else write_mat)(record, c)
            err_console.print(f"[dim]{out} is up to date (same inputs); wrote "
                              f"{', '.join(str(c) for c in stale_wanted)} from it[/dim]",
                              highlight=False, soft_wrap=True)
        else:
            err_console.print(f"[dim]{out} is up to date (same inputs); --force recomputes "
                              f"it[/dim]", highlight=False, soft_wrap=True)
        console.print(f"  diagnose it: geardyn diagnose {out} --signal acc --tach tach",
                      highlight=False, soft_wrap=True)
        return
    with progress_bar() as bar:
        task = bar.add_task("stiffness map", total=None)

        def tick(done: int, total: int) -> None:
            bar.update(task, completed=done, total=total)

        smap = build_map(case, method=case.stiffness.method, cracked=crack, progress=tick)
        bar.update(task, description=f"model {which}", completed=0, total=None)
        result = run_measure(case, smap, model=which, cracked=crack, progress=tick)
    ds = result.record
    ds.attrs["geardyn_inputs"] = inputs_json
    remove_stale(copies_to_refresh(out, inputs_json, companions)[1])
    written = [str(out)]
    if csv:
        write_csv(ds, out.with_suffix(".csv"))
        written.append(str(out.with_suffix(".csv")))
    if mat:
        write_mat(ds, out.with_suffix(".mat"))
        written.append(str(out.with_suffix(".mat")))
    write_netcdf(ds, out)  # last: the NetCDF with its inputs marks the whole result done
    m = result.measured
    pulses = m.pulse_times.size
    console.print(f"[green]done[/green]: {m.acc.size} samples at {m.fs:.6g} Hz "
                  f"({m.acc.size / m.fs:.4g} s), {pulses} tachometer "
                  f"pulse{'' if pulses == 1 else 's'} -> {', '.join(written)}")
    console.print(f"  acceleration RMS {float(m.acc.std()):.4g} m/s^2 "
                  f"({float(m.acc.std()) / 9.80665:.4g} g), noise RMS {m.noise_rms:.4g} m/s^2")
    if m.clipped:
        err_console.print(f"[yellow]warning[/yellow]: the ADC clipped {m.clipped} samples "
                          f"({100 * m.clipped / m.acc.size:.3g} %): raise measurement.adc_range")
    # the file states its rate, the teeth of the tachometer's shaft and the pulses per
    # revolution: diagnose reads them
    if pulses < 2:  # diagnose needs a revolution between two pulses (a user audit)
        err_console.print(f"[yellow]warning[/yellow]: {pulses} tachometer "
                          f"pulse{'' if pulses == 1 else 's'} in the record: diagnose needs at "
                          "least 2 (a whole revolution of the tachometer's shaft); lengthen "
                          "simulation.record_time", highlight=False, soft_wrap=True)
    else:
        console.print(f"  diagnose it: geardyn diagnose {out} --signal acc --tach tach")
