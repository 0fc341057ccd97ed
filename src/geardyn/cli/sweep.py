"""``geardyn sweep``: a parameter sweep on Dask into one resumable Zarr store.

The sweep file holds the base case, its overrides and the swept values; ``--config`` replaces its
base case and ``--set`` adds overrides to it. Both become part of the sweep's identity (a store
made with other values is not resumed by mistake) and are recorded with the sweep file's text in
the Zarr attributes. Re-running the same command after an interruption computes only the missing
runs.
"""

from __future__ import annotations

import importlib
from collections import Counter
from pathlib import Path
from typing import Annotated

import typer

from . import app
from ._common import ConfigOption, SetOption, console, err_console, handle_errors, progress_bar


def _load_evaluator(spec: str):
    """``module:attribute`` -> an Evaluator (an instance, or a class/factory called with no
    arguments)."""
    from ..errors import InputError
    from ..studies.sweep import Evaluator

    allowed = "module:attribute naming a geardyn.studies.sweep.Evaluator (or a class or " \
              "function returning one), importable here and on every worker"
    if ":" not in spec:
        raise InputError("--evaluator", spec, allowed)
    mod_name, attr = spec.split(":", 1)
    try:
        obj = getattr(importlib.import_module(mod_name), attr)
    except (ImportError, AttributeError) as exc:
        raise InputError("--evaluator", spec, f"{allowed} ({exc})") from None
    if not isinstance(obj, Evaluator) and callable(obj):
        obj = obj()
    if not isinstance(obj, Evaluator):
        raise InputError("--evaluator", spec, allowed)
    return obj


def with_base_case(sw, config: Path | None, overrides: list[str]):
    """The sweep with ``--config`` as its base case (plus the sweep's own ``[set]``) and the
    ``--set`` overrides applied; the command line is appended to the stored sweep text."""
    import dataclasses
    import shlex

    from ..config import load_case

    if config is None and not overrides:
        return sw
    base = sw.base_case
    if config is not None:
        base = load_case(config, {k: v for k, v in (sw.spec.set or {}).items()})
    if overrides:
        base = base.with_overrides(overrides)
    cli = " ".join(([f"--config {shlex.quote(str(config))}"] if config else [])
                   + [f"--set {shlex.quote(o)}" for o in overrides])
    return dataclasses.replace(sw, base_case=base,
                               text=sw.text.rstrip("\n") + f"\n# geardyn sweep {cli}\n")


@app.command("sweep")
@handle_errors
def sweep(
    sweep_file: Annotated[Path, typer.Argument(help="Sweep file (TOML).", show_default=False)],
    out: Annotated[Path, typer.Option("--out", "-o", help="Zarr store to create or resume "
                                                          "(a folder).", show_default=False)],
    scheduler: Annotated[str | None, typer.Option(
        "--scheduler", help="Address of a running Dask scheduler, e.g. tcp://10.0.0.5:8786 "
                            "(default: a local cluster).", show_default=False)] = None,
    workers: Annotated[int | None, typer.Option(
        "--workers", "-w", help="Worker processes of the local cluster, one thread each "
                                "(default: the number of CPUs).", show_default=False)] = None,
    retry_failed: Annotated[bool, typer.Option(
        "--retry-failed", help="Compute runs recorded as failed again.")] = False,
    force: Annotated[bool, typer.Option(
        "--force", help="Overwrite a store that holds a different sweep.")] = False,
    evaluator: Annotated[str | None, typer.Option(
        "--evaluator", help="Advanced: module:attribute of a custom Evaluator computing each run "
                            "instead of geardyn's simulation + diagnostics.",
        show_default=False)] = None,
    config: ConfigOption = None,
    set_: SetOption = None,
) -> None:
    """Run the sweep in SWEEP_FILE on Dask into the Zarr store OUT (resumable: re-run the same
    command after an interruption to compute only the missing runs)."""
    from ..studies.sweep import load_sweep, open_sweep, run_sweep

    sw = with_base_case(load_sweep(sweep_file), config, set_ or [])
    ev = _load_evaluator(evaluator) if evaluator else None
    with progress_bar() as bar:
        task = bar.add_task(f"sweep {sw.spec.name}", total=sw.n_runs)

        def progress(done: int, total: int) -> None:
            bar.update(task, completed=done, total=total)

        result = run_sweep(sw, out, scheduler=scheduler, workers=workers,
                           retry_failed=retry_failed, force=force, evaluate=ev,
                           progress=progress)
    what = "resumed" if result.resumed else "created"
    console.print(f"[green]done[/green]: {result.n_runs} runs in {result.out} ({what}; "
                  f"{result.computed} computed now on {result.workers} worker(s) in "
                  f"{result.tasks} task(s) of up to {result.batch_size} runs, "
                  f"{result.seconds:.1f} s)")
    console.print(f"  ok {result.ok}, failed {result.failed}, pending {result.pending}")
    if result.failed:
        ds = open_sweep(result.out)
        errors = ds["error"].values[ds["status"].values == 2]
        for msg, n in Counter(str(e) for e in errors).most_common(3):
            err_console.print(f"  [yellow]{n} failed[/yellow]: {msg}", highlight=False,
                              soft_wrap=True)
        if not retry_failed:
            err_console.print("  (failed runs stay recorded; --retry-failed computes them "
                              "again)")
    if result.pending:
        for t in result.incomplete_tasks[:3]:
            err_console.print(f"  [red]task lost[/red]: {t}", highlight=False, soft_wrap=True)
        err_console.print(f"[red]{result.pending} run(s) still pending[/red]: re-run the same "
                          "command to compute them")
        raise typer.Exit(1)
