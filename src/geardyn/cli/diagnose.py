"""``geardyn diagnose``: the diagnostic chain on a simulation result or on measured data."""

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
    handle_errors,
    load_case_from_cli,
)

#: The command-line option of each argument of :func:`geardyn.diagnostics.diagnose_file` and
#: its loaders, for their error messages.
OPTION_NAMES = {
    "signal": "--signal", "signals": "--signal", "teeth": "--teeth", "fs": "--fs",
    "time": "--time", "angle": "--angle", "angle_unit": "--angle-unit", "tach": "--tach",
    "tach_column_is_pulse_times": "--tach-times", "pulses_per_rev": "--pulses-per-rev",
}


@app.command("diagnose")
@handle_errors
def diagnose(
    file: Annotated[Path, typer.Argument(metavar="FILE", help="A geardyn simulation (.nc) or measured data "
                                              "(.csv, .txt, .npy, .npz, .mat).")],
    config: ConfigOption = None,
    set_: SetOption = None,
    out: Annotated[Path | None, typer.Option(
        "--out", "-o", help="Output folder for metrics.json and figures/ (default: "
                            "<FILE without suffix>-diagnose beside FILE).", show_default=False)
                   ] = None,
    signal: Annotated[list[str] | None, typer.Option(
        "--signal", help="Signal column/variable (repeatable). Default for a simulation: "
                         "v_yg, omega_p, transmission_error.", show_default=False)] = None,
    teeth: Annotated[int | None, typer.Option(
        "--teeth", help="Teeth on the shaft whose angle is given, for files that do not "
                        "state it (default: the simulation's pinion; for measured data the "
                        "pinion of the case FILE stores, as a record of geardyn measure does "
                        "(the gear if its tachometer reads the gear), else the pinion of the "
                        "--config case). A count that contradicts the file is refused.",
        show_default=False)] = None,
    fs: Annotated[str | None, typer.Option("--fs", help="Sampling rate of measured data: Hz, or "
                                                        "with a unit (Hz, kHz, MHz, 1/s), e.g. "
                                                        "'20 kHz'. A file that stores its own "
                                                        "rate (.nc, a .mat/.npz with fs) is "
                                                        "read at that rate.", show_default=False
                                       )] = None,
    time: Annotated[str | None, typer.Option("--time", help="Time column [s] (instead of --fs).",
                                             show_default=False)] = None,
    angle: Annotated[str | None, typer.Option("--angle", help="Shaft angle column.",
                                              show_default=False)] = None,
    angle_unit: Annotated[str, typer.Option("--angle-unit", help="rad, deg or rev.")] = "rad",
    tach: Annotated[str | None, typer.Option("--tach", help="Tachometer column (pulse train, or "
                                                            "pulse times with --tach-times).",
                                             show_default=False)] = None,
    tach_times: Annotated[bool, typer.Option("--tach-times", help="The tach column holds pulse "
                                                                  "times [s].")] = False,
    pulses_per_rev: Annotated[int | None, typer.Option(
        "--pulses-per-rev", min=1, help="Tachometer pulses per revolution (default: the count "
                                        "the file states, as geardyn measure records it, else "
                                        "1).", show_default=False)] = None,
    figures: Annotated[bool, typer.Option("--figures/--no-figures",
                                          help="Write the figures (PNG) as well as metrics.json."
                                          )] = True,
    force: ForceOption = False,
) -> None:
    """Run TSA, spectra, residual, demodulation, PWVD and condition metrics; write figures and
    metrics.json into OUT."""
    from ..errors import DataFileError
    from ..units import parse_frequency
    from ._outputs import (
        begin,
        check_writable,
        claim_folder,
        identity,
        mark_complete,
        resolve,
        say_state,
    )

    fs = parse_frequency(fs, "--fs") if fs is not None else None  # [Hz]; "20 kHz" -> 20000.0
    if not file.exists():
        raise DataFileError(file, "no such file")
    if not file.is_file():
        raise DataFileError(file, "is not a file (a folder?)")
    target = resolve(out, file.with_name(f"{file.stem}-diagnose"))
    out = target.path
    check_writable(target)  # before loading anything heavy: a bad --out fails at once
    case = load_case_from_cli(config, set_)
    options = {"signal": signal or None, "teeth": teeth, "fs": fs, "time": time, "angle": angle,
               "angle_unit": angle_unit, "tach": tach, "tach_times": tach_times,
               "pulses_per_rev": pulses_per_rev, "figures": figures}
    ident = identity("diagnose", case, options, files={"FILE": file})
    state = claim_folder(target, ident, force=force, results=["metrics.json", "figures"],
                         record=False)
    from ..diagnostics import diagnose_file

    d = case.diagnostics
    # teeth: --teeth, else what FILE says (a simulation's pinion_teeth, the case a measured
    # record stores), else for measured data the pinion of the --config case
    result = diagnose_file(
        file, teeth=teeth, signals=signal or None, fs=fs, time=time, angle=angle, tach=tach,
        tach_column_is_pulse_times=tach_times, pulses_per_rev=pulses_per_rev,
        angle_unit=angle_unit, default_teeth=case.pinion.teeth, option_names=OPTION_NAMES,
        samples_per_rev=d.samples_per_rev, harmonic=d.harmonic, bandwidth=d.bandwidth,
        residual_preset=d.residual_preset)
    say_state(state, target)
    begin(target, ident)
    result.write(out, figures=figures)
    mark_complete(target, ident)
    summary = result.to_dict()
    written = "metrics.json and figures" if figures else "metrics.json"
    console.print(f"[green]done[/green]: {written} in {out}/ (teeth {result.teeth})")
    def num(v) -> str:
        return f"{v:.4g}" if isinstance(v, int | float) else "n/a"

    for name, sig in summary.get("signals", {}).items():
        k = sig.get("kurtosis", {})
        console.print(f"  {name}: {sig.get('n_averages')} revolutions averaged; kurtosis of TSA "
                      f"{num(k.get('tsa'))}, residual {num(k.get('residual'))}, envelope "
                      f"{num(k.get('envelope'))}, PM {num(k.get('phase_modulation'))}")
