"""``geardyn study``: shipped studies that compose the library (no physics of their own).

``geardyn study model-ii --out DIR [--quick]`` runs the shipped sweep
``sweep_model_regimes.toml`` with :class:`geardyn.studies.model_regimes.ModelRegimeEvaluator`
(model II against model I-static over crack depth, bearing damping, bearing stiffness and speed)
into ``DIR/model_regimes.zarr`` (resumable) and writes ``DIR/model_regimes.nc`` and the page
``DIR/model_regimes.html`` (with ``DIR/figures/``).
"""

from __future__ import annotations

import shlex
import sys
from pathlib import Path
from typing import Annotated

import typer

from . import app
from ._common import (
    ConfigOption,
    SetOption,
    StageProgress,
    console,
    err_console,
    handle_errors,
    progress_bar,
)

study_app = typer.Typer(help="Shipped studies built on the library (results + an HTML page).",
                        no_args_is_help=True)
app.add_typer(study_app, name="study")


@study_app.command("model-ii")
@handle_errors
def model_ii(
    out: Annotated[Path, typer.Option("--out", "-o", help="Output folder: model_regimes.zarr "
                                                          "(the sweep store), model_regimes.nc, "
                                                          "model_regimes.html, figures/.",
                                      show_default=False)],
    quick: Annotated[bool, typer.Option(
        "--quick", help="The coarse shipped grid (64 runs, about 22 s on a 2-core machine) instead "
                        "of the full one (1260 runs).")] = False,
    sweep_file: Annotated[Path | None, typer.Option(
        "--sweep", help="Your own sweep file over the study's axes (crack.depth, "
                        "pinion.bearing_damping_ratio, pinion.bearing_stiffness, load.speed) "
                        "instead of the shipped one.", show_default=False)] = None,
    workers: Annotated[int | None, typer.Option(
        "--workers", "-w", help="Worker processes of the local Dask cluster (default: the "
                                "number of CPUs).", show_default=False)] = None,
    method: Annotated[str | None, typer.Option(
        "--stiffness", "--method", help="Stiffness method of the maps (--method: its older "
                                        "name): pem (the sweep's default, fast) or fe "
                         "(one FE map per crack depth: far slower).", show_default=False)] = None,
    config: ConfigOption = None,
    set_: SetOption = None,
    force: Annotated[bool, typer.Option(
        "--force", "-f", help="Overwrite a store in --out that holds another sweep (the same "
                              "sweep is resumed without it).")] = False,
) -> None:
    """Where the centre-distance dynamics matter: model II against model I-static over bearing
    stiffness (1e5..1e8 N/m), bearing damping (0.5..10 %), speed (mesh frequency across the
    bearing modes) and crack depth; RMS(II - I-static)/STD(II), the model II iteration counts and
    the predictor vs the paper's start-of-step evaluation, as a NetCDF and an HTML page.
    Re-running the same command computes only the missing runs."""
    from .._optional import require_extra
    from ..config import load_case
    from ..errors import InputError
    from ..io import write_netcdf_atomic
    from ..studies.model_regimes import model_regimes
    from ..studies.model_regimes_report import regime_summary, write_report
    from ._outputs import OutputTarget, check_writable

    require_extra("sweep")  # dask, distributed, zarr: a clear error naming the extra
    if method is not None and method not in ("pem", "fe"):
        raise InputError("--stiffness", method, "'pem' or 'fe'")
    if workers is not None and workers < 1:
        raise InputError("--workers", workers, "a positive number of worker processes")
    if quick and sweep_file is not None:
        raise InputError("--quick", True, "either --quick or --sweep, not both")
    # a file, a path below a file or an unwritable folder fails here, before the sweep starts
    check_writable(OutputTarget(out, given=True), folder=True)
    case = load_case(config) if config is not None else None
    command = "geardyn " + " ".join(shlex.quote(a) for a in sys.argv[1:])
    out.mkdir(parents=True, exist_ok=True)
    with progress_bar() as bar:
        stages = StageProgress(bar)
        ds = model_regimes(out / "model_regimes.zarr", sweep=sweep_file, quick=quick, case=case,
                           overrides=set_ or [], method=method, workers=workers, force=force,
                           progress=stages)
        stages.close()
    write_netcdf_atomic(ds, out / "model_regimes.nc")
    page = write_report(ds, out, command=command)
    s = regime_summary(ds)
    console.print(f"[green]done[/green]: {s['points']} runs ({s['compared']} compared, "
                  f"{s['not_run']} not run, {s['failed']} failed; "
                  f"{ds.attrs['sweep_computed_now']} computed now on {ds.attrs['workers']} "
                  f"worker(s)) in {ds.attrs['run_seconds']:.0f} s", highlight=False)
    console.print(s["sentence"], highlight=False, soft_wrap=True)
    if ds.attrs.get("runup_status") == "ok":
        from ..studies.model_regimes_report import runup_summary

        ru = runup_summary(ds)
        console.print(f"run-up through the centre-distance mode ({ru['mode']:.4g} Hz): "
                      f"largest ratio {ru['max']:.3g} ({ru['max_signal']}) at "
                      f"{ru['max_ratio']:.3g} x the mode's frequency; above the threshold in "
                      f"{ru['above']} of {ru['windows']} windows", highlight=False,
                      soft_wrap=True)
    if ds.attrs.get("sweep_pending"):
        err_console.print(f"[red]{ds.attrs['sweep_pending']} run(s) still pending[/red]: re-run "
                          "the same command to compute them", highlight=False)
    console.print(f"  {out / 'model_regimes.nc'}\n  {page}", highlight=False)
    if ds.attrs.get("sweep_pending"):
        raise typer.Exit(1)
