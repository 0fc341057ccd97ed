"""``geardyn sweep``: a parameter sweep on Dask into one resumable Zarr store.

The sweep file holds the base case, its overrides and the swept values; ``--config`` replaces its
base case and ``--set`` adds overrides to it. Both become part of the sweep's identity (a store
made with other values is not resumed by mistake) and are recorded with the sweep file's text in
the Zarr attributes. Re-running the same command after an interruption computes only the missing
runs; batches whose stored values fail their checksums are computed again (and named).
``geardyn sweep --verify STORE`` checks a store against its checksums without computing.
"""

from __future__ import annotations

import importlib
import re
from pathlib import Path
from typing import Annotated

import typer

from . import app
from ._common import SetOption, console, err_console, handle_errors, progress_bar


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
        base = load_case(config, {k: v for k, v in (sw.spec.set or {}).items()},
                         override_source="sweep file [set]")
    if overrides:
        base = base.with_overrides(overrides, source="--set")
    cli = " ".join(([f"--config {shlex.quote(str(config))}"] if config else [])
                   + [f"--set {shlex.quote(o)}" for o in overrides])
    return dataclasses.replace(sw, base_case=base,
                               text=sw.text.rstrip("\n") + f"\n# geardyn sweep {cli}\n")


#: A number in a failure message (replaced to group the failures by cause).
_NUMBER = re.compile(r"[-+]?\d+(?:\.\d*)?(?:[eE][-+]?\d+)?")


def verify(store: Path) -> None:
    """``--verify STORE``: check every finished batch against its checksum; exit 1 if damaged."""
    from ..studies.sweep import verify_store

    check = verify_store(store)
    if check.metadata == "missing":
        err_console.print("  [yellow]note[/yellow]: the consolidated metadata (.zmetadata) is "
                          "missing or unreadable; resuming the sweep rebuilds it", soft_wrap=True)
    if check.ok:
        console.print(f"[green]ok[/green]: {store}: {check.summary()}", highlight=False,
                      soft_wrap=True)
        return
    err_console.print(f"[red]damaged[/red]: {store}: {check.summary(10)}", highlight=False,
                      soft_wrap=True)
    err_console.print("  re-run the same `geardyn sweep` command to recompute those runs",
                      soft_wrap=True)
    raise typer.Exit(1)


@app.command("sweep")
@handle_errors
def sweep(
    sweep_file: Annotated[Path | None, typer.Argument(help="Sweep file (TOML).",
                                                      show_default=False)] = None,
    out: Annotated[Path | None, typer.Option("--out", "-o", help="Zarr store to create or "
                                                                 "resume (a folder); required "
                                                                 "to run a sweep.",
                                             show_default=False)] = None,
    verify_store: Annotated[Path | None, typer.Option(
        "--verify", help="Check the store STORE against its per-batch checksums without "
                         "computing (exit 1 if a batch is damaged), instead of running a "
                         "sweep.", metavar="STORE", show_default=False)] = None,
    max_runs: Annotated[int | None, typer.Option(
        "--max-runs", help="Largest number of runs accepted (default 100,000, or "
                           "$GEARDYN_MAX_RUNS); a larger sweep is refused before it starts.",
        show_default=False)] = None,
    scheduler: Annotated[str | None, typer.Option(
        "--scheduler", help="Address of a running Dask scheduler, e.g. tcp://10.0.0.5:8786 "
                            "(default: a local cluster).", show_default=False)] = None,
    workers: Annotated[int | None, typer.Option(
        "--workers", "-w", help="Worker processes of the local cluster, one thread each "
                                "(default: the number of CPUs).", show_default=False)] = None,
    retry_failed: Annotated[bool, typer.Option(
        "--retry-failed", help="Compute runs recorded as failed again.")] = False,
    force: Annotated[bool, typer.Option(
        "--force", "-f", help="Overwrite a store that holds a different sweep.")] = False,
    evaluator: Annotated[str | None, typer.Option(
        "--evaluator", help="Advanced: module:attribute of a custom Evaluator computing each run "
                            "instead of geardyn's simulation + diagnostics.",
        show_default=False)] = None,
    config: Annotated[Path | None, typer.Option(
        "--config", "-c", help="Case file (TOML) replacing the sweep file's base case (its "
                               "'base', else the paper's case); the sweep's [set] still "
                               "applies.", show_default=False)] = None,
    set_: SetOption = None,
) -> None:
    """Run the sweep in SWEEP_FILE on Dask into the Zarr store OUT (resumable: re-run the same
    command after an interruption to compute only the missing runs). Exit status 1 if any run
    of the store failed (their errors are in its 'error' variable) or is still pending, after
    the store and the summary are written; 0 if every run is ok."""
    from .._optional import require_extra
    from ..errors import NOT_GIVEN, InputError

    require_extra("sweep")  # before any work: exit 2 naming pip install 'geardyn[sweep]'
    from ..studies.sweep import load_sweep, open_sweep, run_sweep

    if verify_store is not None:
        if sweep_file is not None or out is not None:
            raise InputError("--verify", str(verify_store), "a store alone (no sweep file, no "
                                                            "--out)")
        verify(verify_store)
        return
    if sweep_file is None:
        raise InputError("SWEEP_FILE", NOT_GIVEN, "a sweep file (TOML), or --verify STORE")
    if out is None:
        raise InputError("--out", NOT_GIVEN, "the Zarr store to create or resume (a folder)")
    if not out.exists() or out.is_dir():  # an existing file: "not a Zarr store", below
        from ._outputs import OutputTarget, check_writable

        check_writable(OutputTarget(out, given=True), folder=True)  # before any work
    sw = with_base_case(load_sweep(sweep_file, max_runs=max_runs), config, set_ or [])
    ev = _load_evaluator(evaluator) if evaluator else None
    with progress_bar() as bar:
        task = bar.add_task(f"sweep {sw.spec.name}", total=sw.n_runs)

        def progress(done: int, total: int) -> None:
            bar.update(task, completed=done, total=total)

        result = run_sweep(sw, out, scheduler=scheduler, workers=workers,
                           retry_failed=retry_failed, force=force, evaluate=ev,
                           progress=progress)
    what = "resumed" if result.resumed else "created"
    if result.metadata_rebuilt:
        err_console.print("  [yellow]repaired[/yellow]: the store's consolidated metadata was "
                          "missing or unreadable and was rebuilt", soft_wrap=True)
    if result.damaged:
        err_console.print(f"  [yellow]repaired[/yellow]: {len(result.damaged)} batch(es) failed "
                          "their checksums and were computed again: "
                          + "; ".join(result.damaged[:5])
                          + ("; ..." if len(result.damaged) > 5 else ""),
                          highlight=False, soft_wrap=True)
    console.print(f"[green]done[/green]: {result.n_runs} runs in {result.out} ({what}; "
                  f"{result.computed} computed now on {result.workers} worker(s) in "
                  f"{result.tasks} task(s) of up to {result.batch_size} runs, "
                  f"{result.seconds:.1f} s)")
    console.print(f"  ok {result.ok}, failed {result.failed}, pending {result.pending}")
    if result.failed:
        ds = open_sweep(result.out, verify=False)  # verified by the resume; only read errors
        errors = ds["error"].values[ds["status"].values == 2]
        # one cause, one line: the same failure differs from run to run only in its numbers
        # (three lines of one cause took the summary's three places: a user audit)
        causes: dict[str, tuple[int, str]] = {}
        for e in (str(e) for e in errors):
            shape = _NUMBER.sub("#", e)
            n, first = causes.get(shape, (0, e))
            causes[shape] = (n + 1, first)
        for n, first in sorted(causes.values(), key=lambda c: -c[0])[:3]:
            err_console.print(f"  [yellow]{n} failed[/yellow]"
                              + (" (numbers of the first)" if n > 1 else "") + f": {first}",
                              highlight=False, soft_wrap=True)
        if len(causes) > 3:
            err_console.print(f"  ... and {len(causes) - 3} other cause(s): see the store's "
                              "'error' variable", highlight=False)
        if not retry_failed:
            err_console.print("  (failed runs stay recorded; --retry-failed computes them "
                              "again)")
    if result.pending:
        for t in result.incomplete_tasks[:3]:
            err_console.print(f"  [red]task lost[/red]: {t}", highlight=False, soft_wrap=True)
        err_console.print(f"[red]{result.pending} run(s) still pending[/red]: re-run the same "
                          "command to compute them")
    if result.failed:  # the last line: a script sees the failures in the exit status too
        from rich.markup import escape

        err_console.print(f"[red]{result.failed} of {result.n_runs} runs failed[/red] (their "
                          f"errors are in the store: {escape(str(result.out))}, variable "
                          "'error')", highlight=False, soft_wrap=True)
    if result.failed or result.pending:
        raise typer.Exit(1)
