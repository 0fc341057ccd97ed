"""``geardyn crack-growth``: grow the case's root crack (LEFM path, K_I/K_II, Paris cycles, FE
compliance) and the vibration indicators against load cycles (:mod:`geardyn.studies.crack_growth`).
"""

from __future__ import annotations

import math
import re
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
    handle_errors,
    load_case_from_cli,
    progress_bar,
)

#: Default output folder of ``geardyn crack-growth``.
DEFAULT_OUT = Path("geardyn-out/crack_growth")

#: Files this command writes (a folder holding one without an inputs record is not overwritten).
RESULTS = ["crack_growth.nc", "crack_growth.csv", "fig_crack_path.png", "fig_sif.png",
           "fig_cycles.png", "fig_indicators.png", "fig_mesh_stiffness.png"]

_NUM = r"[+-]?(?:\d+(?:\.\d*)?|\.\d+)(?:[eE][+-]?\d+)?"
_SQRT_M = r"(?:m\^0\.5|m\^\(1/2\)|sqrt\(m\)|√m)"
_C_FORM = re.compile(rf"^({_NUM})(mm|m)/cycle/\((MPa|Pa){_SQRT_M}\)\^(m|{_NUM})$")
_K_FORM = re.compile(rf"^({_NUM})(MPa|Pa){_SQRT_M}$")
_C_ALLOWED = ("a Paris coefficient with its unit, e.g. '1.593e-11 m/cycle/(MPa m^0.5)^m' or "
              "'1.56e-33 m/cycle/(Pa m^0.5)^m' (da/dN in m or mm per cycle; geardyn ships no "
              "default material constants: give the material's own, with its source)")

#: Quick mode: growth step [modules], most steps, crack lengths simulated, settle and record [s].
QUICK = {"step_modules": 0.25, "steps": 20, "points": 3, "settle_time": 0.2, "record_time": 0.3}


def _compact(text: str) -> str:
    return re.sub(r"[\s*·]+", "", text)


def parse_paris_c(value: str | None, m: float, field: str = "--paris-c") -> float:
    """Paris ``C`` from ``"<number> <m|mm>/cycle/(<MPa|Pa> m^0.5)^m"`` to SI
    [m/cycle/(Pa m^0.5)^m]: ``C_SI = C (length unit in m) (K unit in Pa)^-m``. A bare number
    is refused (its unit would be a guess). The power may be written ``^m`` or as the number
    given to ``--paris-m``."""
    from ..errors import NOT_GIVEN, InputError

    if value is None:
        raise InputError(field, NOT_GIVEN, "required: " + _C_ALLOWED)
    text = _compact(str(value))
    if len(text) > 100:
        raise InputError(field, value, _C_ALLOWED + " (at most 100 characters)")
    match = _C_FORM.match(text)
    if not match:
        raise InputError(field, value, _C_ALLOWED)
    num, length, k_unit, power = match.groups()
    if power != "m" and not math.isclose(float(power), m, rel_tol=1e-9):
        raise InputError(field, value, f"a unit whose power is the Paris exponent (^m, or "
                                       f"^{m:g} as given to --paris-m)")
    c = float(num)
    if not (math.isfinite(c) and c > 0):
        raise InputError(field, value, "a Paris coefficient > 0")
    scale = (1e-3 if length == "mm" else 1.0) * (1e-6 ** m if k_unit == "MPa" else 1.0)
    out = c * scale
    if not (math.isfinite(out) and out > 0):
        raise InputError(field, value, "a Paris coefficient whose SI value is a finite "
                                       "number > 0")
    return out


def parse_stress_intensity(value: str, field: str) -> float:
    """A stress intensity such as ``"2 MPa m^0.5"`` (or a bare number in Pa m^0.5) [Pa m^0.5]."""
    from ..errors import InputError

    allowed = "a stress intensity >= 0, e.g. '2 MPa m^0.5' or '2e6 Pa m^0.5' (a bare number: " \
              "Pa m^0.5)"
    text = _compact(str(value))
    if len(text) > 100:
        raise InputError(field, value, allowed)
    if re.fullmatch(_NUM, text):
        out = float(text)
    else:
        match = _K_FORM.match(text)
        if not match:
            raise InputError(field, value, allowed)
        out = float(match.group(1)) * (1e6 if match.group(2) == "MPa" else 1.0)
    if not (math.isfinite(out) and 0 <= out < 1e12):
        raise InputError(field, value, allowed)
    return out


def _csv(ds) -> str:
    """One row per analysed crack length; the indicator columns filled at the sampled lengths."""
    import numpy as np

    cols = [("crack_length", ds["crack_length"].values, "m")]
    for name in ("tip_x", "tip_y", "K_I", "K_II", "kink_angle", "K_eq", "cycles",
                 "compliance"):
        cols.append((name, ds[name].values, ds[name].attrs.get("units", "")))
    lengths = ds["crack_length"].values
    if "sample_length" in ds.dims:
        rows = [int(np.argmin(np.abs(lengths - a))) for a in ds["sample_length"].values]
        for name, var in ds.data_vars.items():
            if var.dims != ("sample_length",) or var.dtype.kind not in "fiu" \
                    or name == "sample_cycles":
                continue
            full = np.full(lengths.shape, np.nan)
            full[rows] = var.values
            cols.append((name, full, var.attrs.get("units", "")))
    head = ",".join(f"{n} [{u}]" if u else n for n, _, u in cols)
    lines = [head]
    for i in range(lengths.size):
        lines.append(",".join("" if not np.isfinite(v[i]) else repr(float(v[i]))
                              for _, v, _ in cols))
    return "\n".join(lines) + "\n"


@app.command("crack-growth")
@handle_errors
def crack_growth(
    config: ConfigOption = None,
    set_: SetOption = None,
    paris_c: Annotated[str | None, typer.Option(
        "--paris-c", help="Paris coefficient C with its unit, e.g. '1.593e-11 m/cycle/(MPa "
                          "m^0.5)^m' (required: geardyn ships no material constants).",
        show_default=False)] = None,
    paris_m: Annotated[float | None, typer.Option(
        "--paris-m", help="Paris exponent m [-] (required).", show_default=False)] = None,
    paris_threshold: Annotated[str, typer.Option(
        "--paris-threshold", help="Threshold Delta K_th, e.g. '2 MPa m^0.5' (the crack arrests "
                                  "where Delta K_eq is at or below it).")] = "0",
    steps: Annotated[int | None, typer.Option(
        "--steps", help="Largest number of growth steps (default 60, --quick 20); growth stops "
                        "earlier when the tip comes within one step of the outline.",
        show_default=False)] = None,
    step_size: Annotated[str | None, typer.Option(
        "--step-size", help="Crack extension per step, a length such as '1 mm', below four "
                            "times the initial crack length (default: module/6, --quick "
                            "module/4, at most 3.9 times the initial crack length).",
        show_default=False)] = None,
    points: Annotated[int | None, typer.Option(
        "--points", help="Crack lengths simulated for the indicators (default 5, --quick 3).",
        show_default=False)] = None,
    snr: Annotated[float | None, typer.Option(
        "--snr", help="White noise added to each simulated signal before the TSA, as a "
                      "signal-to-noise ratio in dB (default 20, as the shipped sweep); "
                      "--no-noise for none.", show_default=False)] = None,
    no_noise: Annotated[bool, typer.Option(
        "--no-noise", help="Indicators of the noise-free signals (a healthy gear's are then "
                           "numerical residue).")] = False,
    quick: Annotated[bool, typer.Option(
        "--quick", help="A coarse, fast run: module/4 steps, at most 20, 3 simulated lengths, "
                        "0.2 s settle and 0.3 s record, and the stiffness maps of 'geardyn run "
                        "--quick' (FE mesh refinement 0.5, at most 11 centre distances).")
                        ] = False,
    stiffness: Annotated[str, typer.Option(
        "--stiffness", help="Mesh stiffness of the simulated lengths: 'pem' (the equivalent "
                            "straight crack, fast) or 'fe' (the grown path itself meshed, one FE "
                            "body per length, about 7 s each).")] = "pem",
    out: Annotated[Path | None, typer.Option(
        "--out", "-o", help=f"Output folder (default: {DEFAULT_OUT}).", show_default=False)
                   ] = None,
    force: ForceOption = False,
) -> None:
    """Grow the case's root crack (its crack section or a faults root_crack entry) under the
    mesh force of motor.torque at the highest point of single tooth contact (at the design
    centre distance; the operating one, opened by the bearings, puts it higher), then simulate a few
    crack lengths (PEM map of the equivalent straight crack, or with --stiffness fe the FE map
    of the grown path): the path, K_I, K_II, Paris cycles,
    the FE compliance and the indicators against cycles go to OUT as crack_growth.nc,
    crack_growth.csv and figures."""
    import warnings

    from ..errors import NOT_GIVEN, InputError
    from ..units import to_si
    from ._outputs import (
        begin,
        check_writable,
        claim_folder,
        identity,
        mark_complete,
        resolve,
        say_state,
    )

    target = resolve(out, DEFAULT_OUT)
    check_writable(target)
    if paris_m is None:
        raise InputError("--paris-m", NOT_GIVEN, "required: the Paris exponent m of the material, "
                                            "a number in (0, 20] (geardyn ships no default)")
    if not (math.isfinite(paris_m) and 0 < paris_m <= 20):
        raise InputError("--paris-m", paris_m, "a Paris exponent in (0, 20]")
    c_si = parse_paris_c(paris_c, paris_m)
    dk_th = parse_stress_intensity(paris_threshold, "--paris-threshold")
    if steps is not None and not 1 <= steps <= 1000:
        raise InputError("--steps", steps, "an integer from 1 to 1000")
    if points is not None and not 1 <= points <= 100:
        raise InputError("--points", points, "an integer from 1 to 100")
    if snr is not None and (no_noise or not math.isfinite(snr)):
        raise InputError("--snr", snr, "a finite signal-to-noise ratio in dB, without --no-noise")
    noise_snr_db = None if no_noise else (20.0 if snr is None else float(snr))
    stiffness = choice("--stiffness", stiffness, ("pem", "fe"))
    case = load_case_from_cli(config, set_)

    from ..faults.tooth_growth import check_step, initial_geometry

    crack, gear, *_ = initial_geometry(case)  # no crack, or one deeper than the tooth: fail now
    if step_size is None:
        step = gear.module * (QUICK["step_modules"] if quick else 1 / 6)
        step = min(step, 3.9 * crack.depth)
    else:
        step = to_si(step_size, "length", "--step-size")
    try:
        check_step(step, crack.depth, "--step-size")
    except InputError as exc:  # the value as written ("30 mm"), the bound in mm
        raise InputError(exc.field, step_size if step_size is not None else exc.value,
                         f"a crack extension in (0, {4e3 * crack.depth:.6g}) mm: below four "
                         f"times the initial crack length, {1e3 * crack.depth:.6g} mm") from None
    n_steps = steps if steps is not None else (QUICK["steps"] if quick else 60)
    n_points = points if points is not None else (QUICK["points"] if quick else 5)
    settle = QUICK["settle_time"] if quick else None
    record = QUICK["record_time"] if quick else None
    options = {"paris_c_si": c_si, "paris_m": paris_m, "paris_threshold_si": dk_th,
               "steps": n_steps, "step_m": step, "points": n_points, "quick": quick,
               "noise_snr_db": noise_snr_db,
               **({"stiffness": "fe"} if stiffness == "fe" else {})}
    ident = identity("crack-growth", case, options)
    state = claim_folder(target, ident, force=force, results=RESULTS, record=False)

    from ..io import atomic_path, write_netcdf_atomic, write_text_atomic
    from ..studies.crack_growth import crack_growth_study
    from ..studies.crack_growth_figures import FIGURES

    if quick:  # the simulated lengths' maps as coarse as geardyn run --quick's (the growth and
        # its SIFs have their own crack mesh: unchanged)
        from ..studies.paper import quick_map_case

        case = quick_map_case(case.with_overrides({"stiffness.method": stiffness}))

    with progress_bar() as bar, warnings.catch_warnings():
        warnings.simplefilter("ignore", UserWarning)  # map validity notes: in the map attrs
        progress = StageProgress(bar)
        progress("crack growth", 0, 0)
        ds = crack_growth_study(case, paris_c=c_si, paris_m=paris_m, paris_threshold=dk_th,
                                step=step, n_steps=n_steps, points=n_points,
                                settle_time=settle, record_time=record,
                                noise_snr_db=noise_snr_db, stiffness=stiffness,
                                progress=progress)
        progress.close()
    say_state(state, target)
    begin(target, ident)
    folder = target.path
    write_netcdf_atomic(ds, folder / "crack_growth.nc")
    write_text_atomic(folder / "crack_growth.csv", _csv(ds))
    for name, fn in FIGURES.items():
        fig = fn(ds)
        with atomic_path(folder / name, suffix=".png") as tmp:
            fig.savefig(tmp, dpi=150, format="png")
    mark_complete(target, ident)

    import numpy as np

    a = ds["crack_length"].values
    n = ds["cycles"].values
    fm4 = ds["v_yg__FM4"].values if "v_yg__FM4" in ds else np.array([np.nan])
    ok = int(np.sum(ds["simulation_status"].values == "ok"))
    finite = n[np.isfinite(n)]  # an arrested crack's last length takes infinitely many cycles
    cycles = (f"{finite.max():.4g} cycles" + (" (then arrested)" if finite.size < n.size else "")
              if finite.size else "no countable cycles")
    console.print(
        f"[green]wrote[/green] {', '.join(RESULTS)} -> {folder}/: crack "
        f"{a[0] * 1e3:.3g} -> {a[-1] * 1e3:.3g} mm in {a.size - 1} steps over "
        f"{cycles} ({ds.attrs['stop']}); K_I {ds['K_I'].values[0] / 1e6:.3g} -> "
        f"{ds['K_I'].values[-1] / 1e6:.3g} MPa m^0.5; v_yg FM4 {fm4[0]:.3g} -> {fm4[-1]:.3g} "
        f"(healthy {float(ds['v_yg__FM4_healthy']) if 'v_yg__FM4_healthy' in ds else np.nan:.3g})"
        f" at {ok}/{ds.sizes['sample_length']} simulated lengths", soft_wrap=True)
    if str(ds.attrs.get("stop", "")).startswith("n_steps"):
        # not a life: the crack would grow on; the cycles are those to the last length
        console.print(
            f"[yellow]note[/yellow]: growth stopped at the step limit ({n_steps} steps of "
            f"{step * 1e3:.3g} mm) at {a[-1] * 1e3:.3g} mm, before the tip reached the tooth's "
            "outline: the cycles are those to this length, not a life. For the whole path: "
            "raise --steps or --step-size.", soft_wrap=True, highlight=False)
