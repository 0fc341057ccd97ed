"""Running a sweep on Dask: preparation, pilot, batches, progress, resume.

The library never prints: :func:`run_sweep` reports through ``progress(done, total)`` and
returns a :class:`SweepResult`.
"""

from __future__ import annotations

import contextlib
import math
import os
import signal
import socket
import threading
import time
import uuid
from collections.abc import Callable, Iterator, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from ..._thread_warnings import thread_warnings
from ...config import Case
from ...errors import DataFileError, InputError
from .evaluate import Evaluator, GeardynEvaluator, Output
from .integrity import verify_store
from .spec import Sweep, SweepPlan, check_runnable, load_sweep
from .store import (
    STATUS_FAILED,
    STATUS_OK,
    STATUS_PENDING,
    RunRecord,
    _check_out,
    _check_values_shapes,
    _clip,
    _create_store,
    _message,
    _outputs_from_store,
    _read_attrs,
    _remove_partials,
    _template,
    _write_batch,
    restore_set_aside,
    store_status,
)

__all__ = ["run_sweep", "SweepResult", "sweep_digest"]

Progress = Callable[[int, int], None]

# ============================================================================================
# tasks run on the workers
# ============================================================================================
@dataclass(frozen=True)
class _Context:
    """What every task needs (pickled to the workers)."""

    out: str
    base_case: Case
    evaluator: Evaluator
    outputs: tuple[Output, ...]
    batch: int
    n_runs: int


def _evaluate_one(base_case: Case, overrides: dict, evaluator: Evaluator, seed: int,
                  outputs: Sequence[Output]) -> RunRecord:
    """One run, never raising: failures and warnings are recorded in the result."""
    t0 = time.perf_counter()
    with thread_warnings() as caught:  # this thread's warnings only (threaded workers)
        try:
            case = base_case.with_overrides(overrides) if overrides else base_case
            values = _check_values_shapes(evaluator(case, int(seed)), outputs)
            status, error = STATUS_OK, ""
        except Exception as exc:  # any failure of one run is recorded; the sweep goes on
            status, values, error = STATUS_FAILED, {}, _message(exc)
    seen = dict.fromkeys(f"{w.category.__name__}: {w.message}" for w in caught)
    return RunRecord(status, values, error, _clip(" | ".join(seen)), time.perf_counter() - t0,
                     _WORKER)


_WORKER = f"{socket.gethostname()}:{os.getpid()}"


def _run_batch(ctx: _Context, chunk: int, items: list[tuple[int, dict, int]]) -> dict:
    """Evaluate the given runs of one chunk and write the chunk (a Dask task)."""
    results = {run: _evaluate_one(ctx.base_case, ov, ctx.evaluator, seed, ctx.outputs)
               for run, ov, seed in items}
    start = chunk * ctx.batch
    _write_batch(ctx.out, start, min(start + ctx.batch, ctx.n_runs), results, ctx.outputs,
                 ctx.batch)
    ok = sum(1 for r in results.values() if r.status == STATUS_OK)
    return {"chunk": chunk, "ok": ok, "failed": len(results) - ok}


def _prepare_task(base_case: Case, evaluator: Evaluator, overrides: dict) -> str | None:
    """Build shared inputs (e.g. a stiffness map) once; a failure is left to the runs."""
    with thread_warnings():  # discarded: the runs record them
        try:
            evaluator.prepare(base_case.with_overrides(overrides) if overrides else base_case)
            return None
        except Exception as exc:
            return _message(exc)


def _pilot_task(base_case: Case, evaluator: Evaluator, candidates: list[tuple[dict, int]]):
    """Evaluate the first run that succeeds twice; return (values, seconds of the 2nd)."""
    last = ""
    for overrides, seed in candidates:
        with thread_warnings():  # discarded: the runs record them
            try:
                case = base_case.with_overrides(overrides) if overrides else base_case
                evaluator(case, seed)  # warm: maps, compiled kernels
                t0 = time.perf_counter()
                values = evaluator(case, seed)
                return values, time.perf_counter() - t0, ""
            except Exception as exc:
                last = _message(exc)
    return None, math.nan, last


def _store_visible(out: str, digest: str) -> bool:
    try:
        return _read_attrs(Path(out)).get("sweep_hash") == digest
    except Exception:
        return False


# ============================================================================================
# running a sweep
# ============================================================================================
@dataclass
class SweepResult:
    """What :func:`run_sweep` did.

    Attributes
    ----------
    out : Path
        The store.
    n_runs : int
        Runs in the sweep.
    ok, failed, pending : int
        Runs by status at the end.
    computed : int
        Runs evaluated in this call.
    skipped : int
        Runs already done before this call.
    batch_size : int
        Runs per task and per chunk.
    tasks : int
        Tasks submitted.
    workers : int
        Dask workers used.
    seconds : float
        Wall time of the call [s].
    task_seconds : float
        Wall time from the first task submitted to the last one finished [s] (the run phase,
        without cluster start-up, map preparation, pilot and template).
    resumed : bool
        True if the store existed.
    incomplete_tasks : list of str
        Tasks that failed as a whole (lost workers beyond Dask's retries, store errors); their
        runs are still pending and a re-run computes them.
    damaged : list of str
        Batches of a resumed store whose stored values failed their checksum (deleted, garbage
        or swapped chunks), put back to pending and computed again in this call, e.g.
        ``"batch 1 (runs 5-9): the stored values differ from their checksum"``.
    metadata_rebuilt : bool
        The store's consolidated metadata (``.zmetadata``) was missing or unreadable and was
        rebuilt from the per-variable metadata.
    """

    out: Path
    n_runs: int
    ok: int = 0
    failed: int = 0
    pending: int = 0
    computed: int = 0
    skipped: int = 0
    batch_size: int = 0
    tasks: int = 0
    workers: int = 0
    seconds: float = 0.0
    task_seconds: float = 0.0
    resumed: bool = False
    incomplete_tasks: list[str] = field(default_factory=list)
    damaged: list[str] = field(default_factory=list)
    metadata_rebuilt: bool = False


def sweep_digest(sweep: Sweep, evaluator: Evaluator) -> str:
    """Hash of the sweep definition and the evaluator (identifies a store's sweep)."""
    from ...cache import cache_key

    return cache_key({"definition": sweep.definition(), "evaluator": evaluator.identity()})


#: Loggers of the client's event loop and of Dask. On a Ctrl-C while the client waits,
#: ``distributed.utils.sync`` schedules a ``cancel`` of the call on the loop (dask/distributed
#: PR #5758, "Respect KeyboardInterrupt in sync"); when the call had not started, distributed
#: 2026.8.0 logs "Exception in callback ... NameError: cannot access free variable 'future'"
#: from the loop's thread, with a traceback, at any moment around the interrupt (seen once in
#: CI, in tests/sweep/test_kill_resume.py): Dask's own noise, not the user's business.
_LOOP_LOGGERS = ("tornado.application", "tornado.general", "asyncio", "distributed")


class _HeldRecords:
    """A logging filter that holds the records of the loggers it is attached to."""

    def __init__(self):
        self.records: list = []

    def filter(self, record) -> bool:
        self.records.append(record)
        return False


@contextlib.contextmanager
def _loop_logs_held() -> Iterator[None]:
    """Hold the records of :data:`_LOOP_LOGGERS` while the block runs (the client's use and
    its shutdown): a block that ends normally logs them afterwards, in order (nothing is lost);
    one that ends with an exception (Ctrl-C included) drops them, so the user sees the one line
    the CLI prints for it. The loggers are as they were afterwards."""
    import logging

    held = _HeldRecords()
    loggers = [logging.getLogger(name) for name in _LOOP_LOGGERS]
    for lg in loggers:
        lg.addFilter(held)
    try:
        yield
    finally:
        for lg in loggers:
            lg.removeFilter(held)
    for record in held.records:  # only after a normal end
        logging.getLogger(record.name).handle(record)


@contextlib.contextmanager
def _dask_client(scheduler: str | None, workers: int | None, client) -> Iterator[Any]:
    if client is not None:
        yield client
        return
    if scheduler:
        from distributed import Client

        try:
            cl = Client(scheduler, timeout="30s")
        except OSError as exc:
            raise InputError("--scheduler", scheduler, f"the address of a running Dask "
                                                       f"scheduler ({exc})") from None
        with _loop_logs_held():  # the shutdown included
            try:
                yield cl
            finally:
                cl.close()
        return
    from .local_workers import local_worker_settings

    n = workers or os.cpu_count() or 1
    # distributed's nannies write their workers' variables (OMP_NUM_THREADS=1, PYTHONHASHSEED,
    # MALLOC_TRIM_THRESHOLD_, ...) into this process's environment and leave them (and so does
    # the forkserver's start): put back what was there once the cluster is closed (a
    # notebook's later subprocesses inherit it)
    environ = dict(os.environ)
    try:
        with local_worker_settings(n) as method:  # Linux, 2+ workers: forked, preloaded
            yield from _local_client(n, method)
    finally:
        for key in set(os.environ) - set(environ):
            del os.environ[key]
        os.environ.update(environ)


@contextlib.contextmanager
def _interrupts_deferred(forked: bool) -> Iterator[None]:
    """Ctrl-C and the local cluster's start (the main thread only: signals are its business).

    SIGINT reaches the whole terminal process group; the worker processes must never act on it
    (this process cancels the tasks and closes the cluster, with no traceback from each worker).
    Workers forked by the forkserver (``forked``) inherit the server's disposition, ignored from
    its start (:func:`.local_workers._start_forkserver`), so this process only holds a Ctrl-C
    pressed while the cluster and its client are made (SIGINT blocked in this thread) and gets
    it when the block ends, as a ``KeyboardInterrupt`` with both to close. Spawned workers
    inherit the disposition at their start (a blocked signal mask does not reach a spawned
    interpreter), so SIGINT is ignored in this process meanwhile, as before, and a Ctrl-C
    pressed then is lost (0.7 s of a two-worker start here), as it is where threads cannot
    block signals (and one just after it can make the spawned workers print "Exception ignored
    in Client.__del__" at their exit: seen at 1.3-1.9 s on 2026-11-27, not mended)."""
    if threading.current_thread() is not threading.main_thread():
        yield
        return
    if forked and hasattr(signal, "pthread_sigmask"):
        old = signal.pthread_sigmask(signal.SIG_BLOCK, {signal.SIGINT})
        try:
            yield
        finally:
            signal.pthread_sigmask(signal.SIG_SETMASK, old)  # a pending Ctrl-C arrives here
        return
    handler = signal.signal(signal.SIGINT, signal.SIG_IGN)
    try:
        yield
    finally:
        signal.signal(signal.SIGINT, handler)


def _note_for_tests(line: str) -> None:
    """Append ``line`` to ``$GEARDYN_TEST_READY_FILE`` when it is set (as the CLI's stages
    do: the interrupt tests wait on it instead of sleeping)."""
    ready = os.environ.get("GEARDYN_TEST_READY_FILE")
    if ready:
        with open(ready, "a", encoding="utf-8") as fh:
            fh.write(line + "\n")


def _local_client(n: int, method: str) -> Iterator[Any]:
    import logging

    from distributed import Client, LocalCluster

    cluster = cl = None
    with _loop_logs_held():  # the start and the shutdown included
        try:
            with _interrupts_deferred(method == "forkserver"):  # (workers never see it)
                _note_for_tests("sweep: local cluster starting")
                # no dashboard, and the scheduler's HTTP server (health, metrics) on a free
                # port of this host: with dashboard_address=None it asks for 8787 and Dask
                # warns "Port 8787 is already in use" whenever another Dask runs here
                cluster = LocalCluster(n_workers=n, threads_per_worker=1, processes=True,
                                       dashboard_address="127.0.0.1:0",
                                       scheduler_kwargs={"dashboard": False},
                                       # a failed task is reported by the sweep itself ("task
                                       # lost: ..." with its error, the runs left pending):
                                       # the workers' own tracebacks of it were noise (a full
                                       # disk printed four, a user audit of 2026-11-27)
                                       silence_logs=logging.CRITICAL)
                cl = Client(cluster)
            yield cl
        finally:
            if cl is not None:
                cl.close()
            if cluster is not None:
                cluster.close()


def run_sweep(
    sweep: Sweep | str | os.PathLike,
    out: str | os.PathLike,
    *,
    scheduler: str | None = None,
    workers: int | None = None,
    client=None,
    retry_failed: bool = False,
    force: bool = False,
    evaluate: Evaluator | None = None,
    progress: Progress | None = None,
) -> SweepResult:
    """Run a sweep on Dask into a Zarr store, or resume it.

    Parameters
    ----------
    sweep : Sweep or path-like
        A :class:`Sweep` or a sweep file.
    out : path-like
        The Zarr store (a folder). It must be on a filesystem every worker sees.
    scheduler : str, optional
        Address of a running Dask scheduler (``tcp://host:port``); default a
        :class:`distributed.LocalCluster`.
    workers : int, optional
        Worker processes of the local cluster (one thread each); default the CPU count.
    client : distributed.Client, optional
        Use this client instead (not closed here).
    retry_failed : bool
        Compute failed runs again (default: they stay recorded).
    force : bool
        Overwrite a store holding a different sweep.
    evaluate : Evaluator, optional
        What each run computes; default :class:`GeardynEvaluator` with the ``[store]`` options.
    progress : callable, optional
        ``progress(done, total)`` in runs (done counts runs already in the store).

    Returns
    -------
    SweepResult
        On resume, :attr:`SweepResult.damaged` names the batches whose stored values failed
        their checksums (they were put back to pending and computed again).

    Raises
    ------
    InputError
        ``--out`` holds another sweep, a bad ``--scheduler``, no workers, or more runs than
        the sweep's limit (see :func:`~geardyn.studies.sweep.load_sweep`).
    DataFileError
        ``out`` is not a sweep store, or the workers cannot see it.
    """
    t_start = time.perf_counter()
    from ..._optional import require_extra

    require_extra("sweep")  # dask, distributed, zarr: a clear error naming the extra
    if not isinstance(sweep, Sweep):
        sweep = load_sweep(sweep)
    if workers is not None and (isinstance(workers, bool) or workers < 1):
        raise InputError("--workers", workers, "a positive number of worker processes")
    if workers is not None and (scheduler or client is not None):
        raise InputError("--workers", workers, "only with the local cluster (not with "
                                               "--scheduler)")
    if evaluate is None or isinstance(evaluate, GeardynEvaluator):
        check_runnable(sweep)  # again: --config/--set may have changed the base case
    evaluator = evaluate or GeardynEvaluator(sweep.spec.store)
    plan = sweep.plan()
    out = Path(out).absolute()
    digest = sweep_digest(sweep, evaluator)
    with _store_lock(out):
        return _run_locked(sweep, out, digest, evaluator, plan, force, retry_failed,
                           scheduler, workers, client, progress, t_start)


@contextlib.contextmanager
def _store_lock(out: Path):
    """One sweep at a time writes a store: a second command on the same store is refused
    (two computed all 20 pending runs each, a user audit of 2026-11-27). The lock is the
    hidden file ``.<store>.lock`` beside the store (``flock``)."""
    from filelock import FileLock, Timeout

    out.parent.mkdir(parents=True, exist_ok=True)
    lock = FileLock(str(out.with_name(f".{out.name}.lock")))
    try:
        lock.acquire(timeout=0)
    except Timeout:
        raise InputError("--out", str(out), "a store no other geardyn sweep is writing: another "
                                            "sweep is writing this one now (wait for it to "
                                            "end; the same command then resumes it)") from None
    try:
        yield
    finally:
        lock.release()
        with contextlib.suppress(OSError):  # nothing left beside the store
            os.unlink(lock.lock_file)


def _run_locked(sweep, out, digest, evaluator, plan, force, retry_failed, scheduler, workers,
                client, progress, t_start) -> SweepResult:
    """:func:`run_sweep` once the store's lock is held."""
    resumed = _check_out(out, digest, force, sweep.definition())
    result = SweepResult(out=out, n_runs=plan.n_runs, resumed=resumed)

    status = np.zeros(plan.n_runs, dtype=np.int8)
    batch, outputs = 0, ()
    if resumed:
        _remove_partials(out)
        check = verify_store(out, repair=True)  # damaged batches go back to pending
        if check.plan not in ("ok", "unchecked"):  # the inputs of the runs: nothing to redo
            raise DataFileError(out, f"holds a damaged plan: {check.plan}")
        result.damaged = [str(d) for d in check.damaged]
        result.metadata_rebuilt = check.metadata == "rebuilt"
        status = store_status(out, repair=True)
        batch = int(_read_attrs(out)["batch_size"])
        outputs = _outputs_from_store(out)
    todo = np.flatnonzero((status == STATUS_PENDING)
                          | ((status == STATUS_FAILED) if retry_failed else False))
    result.skipped = plan.n_runs - todo.size
    result.batch_size = batch
    if progress:
        progress(result.skipped, plan.n_runs)
    try:
        if todo.size:
            with _dask_client(scheduler, workers, client) as cl:
                _execute(cl, sweep, plan, evaluator, out, digest, resumed, todo, batch,
                         outputs, result, progress)
    except BaseException:
        restore_set_aside(out)  # --force over a store, stopped before the new one existed
        raise
    restore_set_aside(out)
    final = store_status(out)
    result.ok = int((final == STATUS_OK).sum())
    result.failed = int((final == STATUS_FAILED).sum())
    result.pending = int((final == STATUS_PENDING).sum())
    result.seconds = time.perf_counter() - t_start
    return result


def _execute(cl, sweep: Sweep, plan: SweepPlan, evaluator: Evaluator, out: Path, digest: str,
             resumed: bool, todo: np.ndarray, batch: int, outputs: tuple,
             result: SweepResult, progress: Progress | None) -> None:
    """Create the store if needed and run the batches of ``todo`` on the cluster."""
    from distributed import as_completed

    try:
        cl.wait_for_workers(1, timeout=120)
    except Exception as exc:  # TimeoutError and friends
        raise InputError("--scheduler", str(cl.scheduler.address),
                         f"a scheduler with at least one worker ({exc})") from None
    result.workers = len(cl.nthreads())
    base = sweep.base_case
    _prepare(cl, base, evaluator, plan, todo)
    if not resumed:
        pilot, seconds = None, math.nan
        spec_batch = sweep.spec.execution.batch_size
        if spec_batch == "auto" or evaluator.needs_pilot:
            cand = [(plan.overrides(r), int(plan.seeds[r])) for r in range(min(3, plan.n_runs))]
            pilot, seconds, msg = cl.submit(_pilot_task, base, evaluator, cand,
                                            pure=False).result()
            if pilot is None and evaluator.needs_pilot:
                raise InputError("store.raw", True, "a sweep whose first runs succeed (to size "
                                                    f"the stored series): {msg}")
        batch = spec_batch if spec_batch != "auto" else _auto_batch(
            seconds, sweep.spec.execution.task_seconds, plan.n_runs, result.workers)
        outputs = tuple(evaluator.outputs(base, pilot))
        ds = _template(sweep, plan, digest, evaluator, outputs, evaluator.coords(base, pilot),
                       batch)
        _create_store(out, ds, batch)
    result.batch_size = batch

    visible = cl.run(_store_visible, str(out), digest)
    blind = [w for w, ok in visible.items() if not ok]
    if blind:
        raise DataFileError(out, f"is not visible from worker(s) {', '.join(blind)}; the store "
                                 "must be on a filesystem shared by all workers")

    ctx = _Context(str(out), base, evaluator, tuple(outputs), batch, plan.n_runs)
    chunks: dict[int, list[tuple[int, dict, int]]] = {}
    for r in todo.tolist():
        chunks.setdefault(r // batch, []).append((r, plan.overrides(r), int(plan.seeds[r])))
    result.tasks = len(chunks)
    done = result.skipped
    tag = uuid.uuid4().hex[:8]
    futures = []
    t0 = time.perf_counter()
    try:
        futures = [cl.submit(_run_batch, ctx, c, items, pure=False,
                             key=f"geardyn-sweep-{digest[:8]}-{tag}-{c}")
                   for c, items in chunks.items()]
        for fut in as_completed(futures):
            try:
                r = fut.result()
            except Exception as exc:  # the whole task failed (lost workers, store error)
                result.incomplete_tasks.append(f"{fut.key}: {_message(exc)}")
                continue
            result.computed += r["ok"] + r["failed"]
            done += r["ok"] + r["failed"]
            if progress:
                progress(done, plan.n_runs)
    finally:
        result.task_seconds = time.perf_counter() - t0
        for f in futures:
            if not f.done():
                f.cancel()


def _auto_batch(run_seconds: float, task_seconds: float, n_runs: int, n_workers: int) -> int:
    """Runs per task so a task lasts about ``task_seconds`` (at least one run), with the number
    of tasks rounded up to whole rounds of ``n_workers`` so no worker idles at the end."""
    per = math.ceil(task_seconds / run_seconds) if run_seconds > 0 and math.isfinite(
        run_seconds) else 1
    w = max(1, n_workers)
    n_tasks = math.ceil(math.ceil(n_runs / max(1, per)) / w) * w
    return int(max(1, math.ceil(n_runs / n_tasks)))


def _prepare(cl, base: Case, evaluator: Evaluator, plan: SweepPlan, todo: np.ndarray) -> None:
    """Run :meth:`Evaluator.prepare` once per distinct key among the runs to do, in parallel."""
    reps: dict[str, dict] = {}
    for r in todo.tolist():
        ov = plan.overrides(r)
        try:
            key = evaluator.prepare_key(base.with_overrides(ov) if ov else base)
        except Exception:  # an invalid run: it will be recorded as failed
            continue
        if key is not None and key not in reps:
            reps[key] = ov
    if reps:
        futs = [cl.submit(_prepare_task, base, evaluator, ov, pure=False)
                for ov in reps.values()]
        cl.gather(futs)


