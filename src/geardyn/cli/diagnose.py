"""``geardyn diagnose``: the diagnostic chain on a simulation result or on measured data."""

from __future__ import annotations

from pathlib import Path
from typing import Annotated

import typer
from rich.markup import escape

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
    "tach_edge": "--tach-edge", "tach_threshold": "--tach-threshold",
    "tach_min_interval": "--tach-min-interval", "unwrap_angle": "--unwrap-angle",
    # the diagnosis settings come from the case (--config, --set diagnostics.<key>=...)
    "harmonic": "diagnostics.harmonic", "bandwidth": "diagnostics.bandwidth",
    "samples_per_rev": "diagnostics.samples_per_rev",
    "residual_preset": "diagnostics.residual_preset",
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
    angle_unit: Annotated[str | None, typer.Option(
        "--angle-unit", help="rad, deg or rev (default: the unit the angle column states, as "
                             "in 'angle [deg]', else rad).", show_default=False)] = None,
    unwrap_angle: Annotated[bool, typer.Option(
        "--unwrap-angle", help="The angle column is wrapped (0..360 deg per turn, as an "
                               "encoder's position reads): unwrap it.")] = False,
    tach: Annotated[str | None, typer.Option("--tach", help="Tachometer column (pulse train, or "
                                                            "pulse times with --tach-times).",
                                             show_default=False)] = None,
    tach_times: Annotated[bool, typer.Option("--tach-times", help="The tach column holds pulse "
                                                                  "times [s].")] = False,
    tach_edge: Annotated[str, typer.Option(
        "--tach-edge", help="Edge that marks a tach pulse: rising (active-high) or falling "
                            "(active-low): the pulse's leading edge.")] = "rising",
    tach_threshold: Annotated[float | None, typer.Option(
        "--tach-threshold", help="Tach edge level, in the tach column's unit (default "
                                 "mid-range).", show_default=False)] = None,
    tach_min_interval: Annotated[str | None, typer.Option(
        "--tach-min-interval", help="Shortest time between tach pulses [s], or with a unit "
                                    "(e.g. '5 ms'): later edges closer than this are noise.",
        show_default=False)] = None,
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
    from ..errors import DataFileError, InputError
    from ..units import parse_frequency, to_si
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
    if tach_edge not in ("rising", "falling"):
        raise InputError("--tach-edge", tach_edge, "rising or falling")
    min_interval = None
    if tach_min_interval is not None:
        min_interval = to_si(tach_min_interval, "time", "--tach-min-interval")  # [s]
        if not min_interval > 0:
            raise InputError("--tach-min-interval", tach_min_interval, "a positive time, e.g. "
                             "'5 ms'")
    options = {"signal": signal or None, "teeth": teeth, "fs": fs, "time": time, "angle": angle,
               "angle_unit": angle_unit, "tach": tach, "tach_times": tach_times,
               "pulses_per_rev": pulses_per_rev, "figures": figures, "tach_edge": tach_edge,
               "tach_threshold": tach_threshold, "tach_min_interval": min_interval,
               "unwrap_angle": unwrap_angle}
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
        tach_edge=tach_edge, tach_threshold=tach_threshold, tach_min_interval=min_interval,
        unwrap_angle=unwrap_angle,
        angle_unit=angle_unit, default_teeth=case.pinion.teeth, option_names=OPTION_NAMES,
        samples_per_rev=d.samples_per_rev, harmonic=d.harmonic, bandwidth=d.bandwidth,
        residual_preset=d.residual_preset)
    say_state(state, target)
    begin(target, ident)
    result.write(out, figures=figures)
    mark_complete(target, ident)
    summary = result.to_dict()
    written = "metrics.json and figures" if figures else "metrics.json"
    # names and paths are the user's text, not rich markup (a column "acc [/s]" closed a tag)
    console.print(f"[green]done[/green]: {escape(written)} in {escape(str(out))}/ (teeth "
                  f"{result.teeth})", soft_wrap=True)  # a path is not broken across lines
    def num(v) -> str:
        return f"{v:.4g}" if isinstance(v, int | float) else "n/a"

    speed = result.settings.get("shaft_speed_rev_s")
    at = ""
    if speed:  # a wrong --pulses-per-rev or angle unit shows as a wrong speed
        lo, hi = speed["min"], speed["max"]
        at = (f" at {speed['mean']:.4g} rev/s ({60 * speed['mean']:.4g} rpm)"
              if hi - lo <= 0.02 * speed["mean"] else
              f" at {lo:.4g}-{hi:.4g} rev/s ({60 * lo:.4g}-{60 * hi:.4g} rpm)")
    for name, sig in summary.get("signals", {}).items():
        k = sig.get("kurtosis", {})
        console.print(f"  {escape(str(name))}: {sig.get('n_averages')} revolutions averaged{at}; "
                      f"kurtosis of TSA {num(k.get('tsa'))}, residual {num(k.get('residual'))}, "
                      f"envelope {num(k.get('envelope'))}, PM "
                      f"{num(k.get('phase_modulation'))}", soft_wrap=True)
