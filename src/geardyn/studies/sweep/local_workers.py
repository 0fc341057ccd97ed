"""The worker processes of a local Dask cluster (``geardyn sweep`` without ``--scheduler``):
how they start and what they do besides the runs.

*How they start.* Dask's nanny starts each worker with ``multiprocessing``'s *spawn* method by
default: a fresh interpreter per worker, which imports NumPy, SciPy, xarray, pandas, numba, zarr
and geardyn's run code itself before its first task (2-3 s of CPU a worker on the 2-core test
machine). On Linux, with two workers or more, geardyn starts them with the *forkserver* method
instead (Dask's setting ``distributed.worker.multiprocessing-method``): one server process
imports those modules once (:mod:`._worker_preload`) and each worker is forked from it, sharing
the imported pages copy-on-write. The nanny's variables for its workers
(``OMP_NUM_THREADS=1``, ...) are in the environment before the server starts (Dask sets them
before it starts the first worker, and the server starts with the first worker), and the worker
runs the same code, so a sweep stores the same bits either way
(``tests/sweep/test_local_workers.py``). One worker is spawned: there is nothing to share.
``GEARDYN_WORKER_START=spawn`` keeps Dask's default; spawn is also what other systems get (on
macOS, forking after the system's libraries have started threads is not safe; Windows has no
fork).

*What they do besides the runs.* Each worker samples its own stack every 10 ms for the Dask
dashboard's profile (``distributed.worker.profile.enabled``); geardyn's local cluster has no
dashboard, so that is switched off.

*How they allocate.* Dask's nanny starts its workers with ``MALLOC_TRIM_THRESHOLD_=65536``
(``distributed.nanny.pre-spawn-environ``), which makes glibc hand freed memory back to the
system at once and fixes its thresholds: every array of a run's record is then mapped and
faulted in afresh. A run of the sweep benchmark's case (model II, 1.5 s simulated, with its
diagnostics) took 0.088-0.089 s in such a worker against 0.067 s without the variable, in the
same process tree (2026-11-27, two alternating pairs; the bare loop in the first process
0.060 s). Left to itself, glibc still mapped a run's largest arrays afresh (16-32 MB: a
worker's run took 0.075-0.083 s). geardyn's local cluster sets
:data:`WORKER_MALLOC`: glibc's mmap threshold at 32 MB and its trim threshold at 64 MB, the
values its own adaptive threshold stops at on 64-bit systems, from the start: 0.061-0.064 s a
run, for 10 MB more peak memory (a worker's ``VmHWM``: 384 MB against 374 MB; 16 MB / 32 MB
gave no gain; 64 MB / 128 MB the same as 32 MB / 64 MB; measured 2026-11-27, three sweeps of
the benchmark's 64 runs each). A value the user has set is kept (Dask lets the environment
win); other C libraries ignore the variables.

Measured on 2026-11-27 (AMD EPYC, 2 cores, ``geardyn sweep
examples/faults/sweep_spall_width.toml``: four runs on two workers, fresh geardyn cache, numba's
cache filled; CPU time summed over every process of the command, read from ``/proc``): see
``docs/performance.md``, "2026-11-27 (08:50-10:30): the sweep's worker processes; the
suite's CPU".
"""

from __future__ import annotations

import os
import sys
from collections.abc import Iterator
from contextlib import contextmanager

__all__ = ["WORKER_PRELOAD", "WORKER_MALLOC", "worker_start_method", "local_worker_settings"]

#: What the forkserver imports before it forks a worker (module names, imported in this order).
WORKER_PRELOAD = ("distributed", "geardyn.studies.sweep._worker_preload")

#: glibc's allocator settings for the workers [bytes] (read when a process starts; see above).
WORKER_MALLOC = {"MALLOC_MMAP_THRESHOLD_": 32 * 1024 ** 2, "MALLOC_TRIM_THRESHOLD_": 64 * 1024 ** 2}

_METHODS = ("forkserver", "spawn")


def worker_start_method(n_workers: int = 2) -> str:
    """``"forkserver"`` on Linux for two workers or more; ``"spawn"`` for one worker (there is
    nothing to share, and the server would import, before the worker starts, what a worker of
    that sweep may not need: 2.3 s against 1.3 s for a small sweep's one worker, measured
    2026-11-27), on other systems, or with ``GEARDYN_WORKER_START=spawn``.

    Parameters
    ----------
    n_workers : int
        Workers of the local cluster.

    Raises
    ------
    geardyn.errors.InputError
        ``GEARDYN_WORKER_START`` set to something else.
    """
    from ...errors import InputError

    asked = os.environ.get("GEARDYN_WORKER_START", "").strip().lower()
    if asked and asked not in _METHODS:
        raise InputError("GEARDYN_WORKER_START", asked, " or ".join(_METHODS))
    if asked == "spawn" or n_workers < 2 or not sys.platform.startswith("linux"):
        return "spawn"
    return "forkserver"


@contextmanager
def local_worker_settings(n_workers: int) -> Iterator[str]:
    """Dask's settings for a local cluster of ``n_workers`` workers, for the ``with`` block (the
    cluster's lifetime, so that a worker the nanny restarts starts the same way); yields the
    start method (:func:`worker_start_method`).

    With ``"forkserver"``, the server's preload is :data:`WORKER_PRELOAD`, set after Dask's
    own list (Dask's dependencies, set once per process); a server already running keeps its
    preload.
    """
    import multiprocessing

    import dask
    from distributed.utils import get_mp_context

    method = worker_start_method(n_workers)
    malloc = {f"distributed.nanny.pre-spawn-environ.{k}": v for k, v in WORKER_MALLOC.items()}
    with dask.config.set({"distributed.worker.multiprocessing-method": method,
                          "distributed.worker.profile.enabled": False, **malloc}):
        if method == "forkserver":
            get_mp_context()  # Dask's preload first, then geardyn's
            multiprocessing.get_context("forkserver").set_forkserver_preload(
                list(WORKER_PRELOAD))
            _start_forkserver()
        yield method


def _start_forkserver() -> None:
    """Start the forkserver now (a no-op when it runs already), ignoring Ctrl-C from its first
    instruction, with the variables Dask's nanny sets for its workers.

    The server keeps the disposition it was started with and gives it to every worker it
    forks, so the workers never act on a terminal's Ctrl-C (the first process cancels the
    tasks and closes the cluster) however the first process treats SIGINT when they are
    forked. Dask's nanny would start the server with its first worker, with
    ``distributed.nanny.pre-spawn-environ`` (``OMP_NUM_THREADS=1``, ...: variables a library
    reads when it is loaded, so they must be in place before the server imports NumPy) already
    in the environment; they are put there here the same way (a variable already set keeps its
    value, as Dask documents), and the caller's environment is restored when the cluster is
    closed (:func:`geardyn.studies.sweep.execute._dask_client`).
    """
    import multiprocessing.forkserver
    import signal
    import threading

    import dask

    for key, value in dask.config.get("distributed.nanny.pre-spawn-environ").items():
        if value is not None:
            os.environ.setdefault(key, str(value))
    main = threading.current_thread() is threading.main_thread()
    old = signal.signal(signal.SIGINT, signal.SIG_IGN) if main else None
    try:
        multiprocessing.forkserver.ensure_running()
    finally:
        if main:
            signal.signal(signal.SIGINT, old)
