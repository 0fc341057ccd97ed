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
    StageProgress,
    choice,
    console,
    err_console,
    handle_errors,
    load_case_from_cli,
    progress_bar,
)

#: Default output folder of ``geardyn run``.
DEFAULT_OUT = Path("geardyn-out")

#: Files whose presence (without an inputs record) means a folder holds earlier results.
RESULTS = ["summary.json", "report.html", "results.nc", "geometry.json", "case.toml"]
#: What else a run writes: refused without a record and removed when --force replaces the
#: results of other inputs, like RESULTS, but not required to call a folder up to date.
OTHER_RESULTS = ["figures", "runs", "stiffness_healthy.nc", "stiffness_cracked.nc"]


@app.command("run")
@handle_errors
def run(
    config: ConfigOption = None,
    set_: SetOption = None,
    out: Annotated[Path | None, typer.Option(
        "--out", "-o", help=f"Output folder (default: {DEFAULT_OUT}). Re-running the same command "
                            "into it continues or repeats the run (fast: the cache keeps the "
                            "maps and simulations).", show_default=False)] = None,
    quick: Annotated[bool, typer.Option("--quick", help="Shorter simulations, coarser maps.")
                     ] = False,
    stiffness: Annotated[str | None, typer.Option(
        "--stiffness", help="Mesh stiffness method: fe or pem, any case (default: the case's "
                            "stiffness.method).", show_default=False)] = None,
    force: ForceOption = False,
) -> None:
    """Reproduce the paper's case study (model I vs II, healthy and cracked) into OUT."""
    from rich.markup import escape

    from ..run_limits import check_step_count
    from ._outputs import (
        check_writable,
        claim_folder,
        identity,
        input_errors_recorded,
        mark_complete,
        resolve,
        say_state,
    )

    stiffness = choice("--stiffness", stiffness, ("fe", "pem"))
    target = resolve(out, DEFAULT_OUT)
    check_writable(target)  # before loading anything heavy: a bad --out fails at once
    case = load_case_from_cli(config, set_)
    if stiffness is not None:
        case = case.with_overrides({"stiffness.method": stiffness})
    from ..studies.paper import _simulation_case

    check_step_count(_simulation_case(case, quick).simulation)  # before the heavy imports

    ident = identity("run", case, {"quick": quick})
    if not force and _up_to_date(target.path, ident):
        # same inputs, complete results: nothing to compute (--force recomputes)
        import json

        summary = json.loads((target.path / "summary.json").read_text())
        err_console.print(f"[dim]{escape(target.label)} is up to date (same inputs, complete "
                          "results); --force recomputes it[/dim]", highlight=False,
                          soft_wrap=True)
        _print_summary(summary, target.path)
        return
    from ..cache import record_lookups
    from ..run_limits import check_bounded_work
    from ..studies.paper import STAGES, run_paper_study

    check_bounded_work(_simulation_case(case, quick))
    from ..processes import fe_processes

    fe_processes()  # a bad GEARDYN_FE_PROCESSES refused before the output folder is claimed
    if case.stiffness.method == "fe":  # and a bad GEARDYN_FE_SOLVER
        from ..stiffness.fe.factor import default_solver

        default_solver()
    state = claim_folder(target, ident, force=force, results=RESULTS + OTHER_RESULTS)
    say_state(state, target)
    with (input_errors_recorded(target, ident), progress_bar() as bar,
          record_lookups() as lookups):
        progress = StageProgress(bar, "run: ", stages=tuple(name for name, _ in STAGES))
        result = run_paper_study(case, target.path, quick=quick, progress=progress)
        progress.close()
    mark_complete(target, ident, lookups)
    _print_summary(result.summary, result.out, lookups)


def _up_to_date(folder: Path, ident: dict) -> bool:
    """True if ``folder`` holds complete results of exactly these inputs (every result file)."""
    from ._outputs import differences, read_record

    old = read_record(folder) if folder.is_dir() else None
    return (old is not None and bool(old.get("complete"))
            and differences(old["identity"], ident) == []
            and all((folder / name).is_file() for name in RESULTS))


def _print_summary(s: dict, out: Path, lookups: list | None = None) -> None:
    """The terminal summary of a run: the headline table, validation, measurement, cache."""
    from rich.markup import escape
    from rich.table import Table

    from ..studies.paper_report import location_check_failed
    from ._outputs import say_cache

    # a case whose physical inputs differ from the paper's is compared with nothing (as in
    # its report), and its fault need not be a crack
    paper = bool(s.get("paper_case", True))
    faulty = "cracked" if paper else "faulty"
    t = Table(title=f"geardyn run: {escape(str(out))}/", show_lines=False)
    for col in ("quantity", "geardyn", "paper") if paper else ("quantity", "geardyn"):
        t.add_column(col, justify="left" if col == "quantity" else "right")
    cr = s.get("contact_ratio", {})
    rows = [("centre distance change \\[mm]", s.get("centre_distance_change_mm"), "~1.07"),
            ("operating pressure angle \\[deg]", s.get("operating_pressure_angle_deg"), "21.18"),
            ("contact ratio, physical / eq. 8",
             f"{cr.get('physical', float('nan')):.4f} / {cr.get('paper_eq8', float('nan')):.4f}",
             "- / 1.43"),
            ("mean pinion speed \\[rad/s]", s.get("mean_pinion_speed_rad_s"), "114.14"),
            ("mean transmission error \\[rad]", s.get("mean_transmission_error_rad"), "0.05"),
            ("crack seen at \\[deg]" if paper else "fault seen at \\[deg]",
             None if location_check_failed(s) else s.get("crack_angle_deg"), "~170")]
    for label, ours, theirs in rows:
        if ours is None:
            continue
        cells = [label, ours if isinstance(ours, str) else f"{ours:.4f}"]
        t.add_row(*(cells + [theirs] if paper else cells))
    console.print(t)
    val = s.get("validation", [])
    failed = [v for v in val if not v["pass"]]
    stages = (f"stages: {', '.join(s.get('stages', []))} "
              f"({s.get('run_time_s', {}).get('total', float('nan')):.1f} s)")
    if paper:
        console.print(f"validation against the paper: {len(val) - len(failed)}/{len(val)} "
                      f"within tolerance; {stages}")
    else:
        keys = [d.get("key", "?") for d in s.get("differences_from_paper", [])]
        shown = ", ".join(keys[:3]) + (f" and {len(keys) - 3} more" if len(keys) > 3 else "")
        console.print(f"not the paper's case ({escape(shown) or 'its inputs differ'}): nothing "
                      f"is compared with the paper; {stages}", highlight=False)
    for v in failed:
        err_console.print(f"[yellow]outside tolerance[/yellow]: {escape(v['quantity'])}: "
                          f"geardyn {v['geardyn']:.4g}, paper {v['paper']:.4g}")
    for v in s.get("checks", []):  # a failed consistency check is said too (it was not)
        if not v.get("pass"):
            err_console.print(f"[yellow]consistency check failed[/yellow]: "
                              f"{escape(str(v['quantity']))}: geardyn {v['geardyn']:.4g}, "
                              f"expected {v.get('reference', float('nan')):.4g} "
                              f"{escape(str(v.get('tolerance_text', '')))} (see the report)",
                              highlight=False, soft_wrap=True)
    cmp = s.get("model_comparison", {}).get("cracked", {}).get("signals", {})
    ratios = {k: [v[k] for v in cmp.values() if v.get(k) is not None]
              for k in ("rms_ii_minus_i_static", "rms_ii_minus_i", "explained_fraction")}
    if all(ratios.values()):
        console.print(
            f"model I-static (K at the static centre distance) vs model II, {faulty}: within "
            f"{100 * max(ratios['rms_ii_minus_i_static']):.3g}% of each signal's STD, model I "
            f"{100 * min(ratios['rms_ii_minus_i']):.3g}-{100 * max(ratios['rms_ii_minus_i']):.3g}"
            f"%; the static shift explains {100 * min(ratios['explained_fraction']):.3g}-"
            f"{100 * max(ratios['explained_fraction']):.3g}% of II - I (see the report)")
    meas = s.get("measurement", {})
    if "indicators" in meas:
        h = meas["indicators"]["errors+noise"]["healthy"]
        c = meas["indicators"]["errors+noise"]["cracked"]
        seen = [k for k, r in meas["detections"]["errors+noise"].items() if r["detected"]]
        console.print(f"realistic measurement (housing accelerometer, tooth errors, noise, "
                      f"model {meas['model']}): FM4 healthy {h['FM4']:.3g} / {faulty} "
                      f"{c['FM4']:.3g}, NA4* {h['NA4star']:.3g} / {c['NA4star']:.3g}, energy "
                      f"ratio {h['EnergyRatio']:.3g} / {c['EnergyRatio']:.3g}; "
                      f"{'crack' if paper else 'fault'} seen by: "
                      f"{', '.join(seen) or 'none of the indicators'}")
    elif "skipped" in meas:
        err_console.print(f"[yellow]note[/yellow]: realistic-measurement section skipped: "
                          f"{escape(meas['skipped'])}")
    if lookups is not None:
        say_cache(lookups)
    report = out / "report.html"
    if report.exists():
        console.print(f"report: [bold]{escape(str(report))}[/bold] (self-contained; open it in "
                      "a browser)")
