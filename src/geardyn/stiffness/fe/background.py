"""The faulty bodies of an FE map built by a second process while the first builds the healthy
ones (issue 16.3: "the bodies built in parallel where cores allow").

A cold pair of FE maps (healthy and faulty) solves three bodies one after the other: the healthy
pinion and gear, then the faulty body (the cracked pinion, loaded on every refined tooth, the
largest of the three). gmsh cannot mesh in two threads of one process at once, so threads
would not overlap the bodies' meshing; a second *process* overlaps all of a body's work.
:func:`faulty_bodies_in_background` starts one that builds the faulty map's bodies, faulty
body first, into the disk cache, while the caller builds the healthy map. Each
body's cache entry has a lock (:meth:`geardyn.cache.Cache.get_or_build`): whichever process comes
to a body first builds it, the other waits for it and loads it. So the results are the same
bytes as a one-process build, whatever the timing (``tests/fe/test_background_bodies.py``).

It costs memory: two bodies are factorised at once (each process about 360 MB at its peak for
the paper's 150,880-DOF pinion with CHOLMOD, 400-440 MB with SuperLU; docs/performance.md,
2026-11-27). The second process starts only when

* the case's stiffness method is ``fe``, its faulty map is not cached yet and it has a faulty
  body (a crack or a breakage), and the disk cache is on;
* ``GEARDYN_FE_PROCESSES`` allows it: ``0`` never, ``1`` always, unset (the default) when the
  machine has at least 2 cores and at least :data:`MIN_AVAILABLE_BYTES` of available memory.

The second process is spawned (a fresh interpreter, nothing of this one's threads or locks),
ignores Ctrl-C, and does not import the caller's main script: a user's script without an
``if __name__ == "__main__":`` guard runs once.

Without a second process (``GEARDYN_FE_PROCESSES=0``, one core, too little memory, or none to
be had) the same bodies are built first, in this process, before the block: the largest body
is factorised while the process is at its smallest, before the maps, their NetCDF writers
(xarray, pandas) and the contact kernels are loaded. Measured on the paper's case in one
process (``GEARDYN_FE_PROCESSES=0 geardyn run``, RSS sampled every 10 ms, 2026-11-26): the
FE stage's peak 634-657 MB with the cracked body built last, 455-534 MB with it first.
"""

from __future__ import annotations

import contextlib
from collections.abc import Callable

# the policy and the quiet start live in geardyn.processes (light to import: the CLI and the
# figure process ask it without importing the FE package); re-exported here
from ...processes import (  # noqa: F401 - re-exported
    FE_PROCESSES_ENV,
    MIN_AVAILABLE_BYTES,
    _available_memory,
    _without_main_module,
    fe_processes,
    skip_collection_at_exit,
    starting_quietly,
)

__all__ = ["faulty_bodies_in_background", "tasks_in_background", "BackgroundBodies",
           "fe_processes", "starting_quietly", "FE_PROCESSES_ENV",
           "MIN_AVAILABLE_BYTES"]

def _build_faulty_bodies(case, then: tuple = (), cache_root: str | None = None) -> None:
    """In the second process: the faulty map's bodies into the cache at ``cache_root`` (default
    :func:`geardyn.cache.cache_dir`), faulty body first; then each callable of ``then`` (e.g.
    :func:`geardyn.dynamics.warm.compile_kernels`).

    An error here ends this process quietly (exit status 1): the first process builds whatever
    is missing and reports the error itself, once.
    """
    import signal
    import sys

    signal.signal(signal.SIGINT, signal.SIG_IGN)  # Ctrl-C is the first process's business
    skip_collection_at_exit()  # the first process may wait for this one's exit
    try:
        from ...cache import Cache
        from .model import FEStiffness

        cache = None if cache_root is None else Cache(cache_root, enabled=True)
        FEStiffness.bodies_into_cache(case, cracked=True, faulty_first=True, cache=cache)
        if then:
            # the bodies' factorisations leave freed pages in this process's heap: 258 MB
            # resident after the paper's bodies, which drawing the mesh figure then grew to
            # 362 MB while the first process evaluated the maps (385 MB), a new peak of the run
            # (760 MB at 16 s against 735 MB at 10 s with both factorising; RSS of every process
            # every 0.1 s, 2026-11-28); given back to the operating system first
            from ...heap import release_free_memory

            release_free_memory()
        for task in then:
            task()
    except Exception:  # noqa: BLE001 - reported by the first process, which meets it too
        sys.exit(1)


def _run_tasks(tasks: tuple) -> None:
    """In a second process: call each of ``tasks``; an error ends the process quietly (exit
    status 1: the first process does the same work when it needs it, and reports its errors)."""
    import signal
    import sys

    signal.signal(signal.SIGINT, signal.SIG_IGN)  # Ctrl-C is the first process's business
    skip_collection_at_exit()  # the first process may wait for this one's exit
    try:
        for task in tasks:
            task()
    except Exception:  # noqa: BLE001 - met again, and reported, by the first process
        sys.exit(1)


def tasks_in_background(tasks: tuple):
    """Start a second process that calls ``tasks`` (module-level functions without arguments,
    e.g. :func:`geardyn.dynamics.warm.compile_kernels`) and is left to run: a daemon, spawned
    and started like the bodies' process (:func:`_start_quietly`), stopped if this process
    ends first. Nothing is started where ``GEARDYN_FE_PROCESSES`` is 0, in a daemon process, or
    when no process can be had.

    Returns
    -------
    multiprocessing.Process or None
    """
    import multiprocessing

    if fe_processes() == 0 or multiprocessing.current_process().daemon or not tasks:
        return None
    proc = multiprocessing.get_context("spawn").Process(
        target=_run_tasks, args=(tuple(tasks),), name="geardyn-background", daemon=True)
    try:
        _start_quietly(proc)
    except (OSError, RuntimeError):
        return None
    return proc


def _start_quietly(proc) -> None:
    """Start ``proc`` as :func:`starting_quietly` says."""
    with starting_quietly():
        proc.start()


def _faulty_bodies_missing(case, cache, method: str) -> bool:
    """Whether the faulty map of ``case`` by ``method`` has FE bodies of its own (a crack or a
    breakage) and is not in the (enabled) cache yet."""
    if method != "fe" or not cache.enabled:
        return False
    from ...cache import cache_key
    from ...faults import faults_from_case
    from .. import map_inputs

    faults = [f for f in faults_from_case(case) if not f.is_null()]
    if not any(f.kind in ("root_crack", "breakage") for f in faults):
        return False  # no faulty body: the faulty map uses the healthy bodies
    key = cache_key(map_inputs(case, "fe", True))
    return not cache.path("stiffness", key, ".nc").exists()


def _wanted(case, cache, method: str) -> bool:
    """Whether a second process would build something: see the module docstring."""
    import multiprocessing

    if fe_processes() == 0 or multiprocessing.current_process().daemon:
        return False  # (a daemon process, a pool's worker, may not have children)
    return _faulty_bodies_missing(case, cache, method)


class BackgroundBodies:
    """What :func:`faulty_bodies_in_background` yields.

    Attributes
    ----------
    process : multiprocessing.Process or None
        The second process, None when none was started.
    """

    __slots__ = ("process",)

    def __init__(self, process):
        self.process = process

    @property
    def started(self) -> bool:
        """Whether a second process was started."""
        return self.process is not None

    def __bool__(self) -> bool:
        return self.started


@contextlib.contextmanager
def faulty_bodies_in_background(case, *, method: str | None = None, cache=None,
                                then: tuple = (),
                                progress: Callable[[int, int], None] | None = None,
                                second_process: bool = True):
    """While the block runs, a second process builds the FE bodies of ``case``'s faulty map
    into the cache (when that helps and is allowed: module docstring); without one, this
    process builds them before the block, faulty body first (``progress(done, total)`` over
    those bodies).

    ``method`` is the stiffness method the block builds its maps with (default the case's);
    anything but ``"fe"`` starts nothing. ``then``: callables without arguments (module-level
    functions, or a ``functools.partial`` of one with picklable arguments) the second process
    calls after the bodies, e.g. :func:`geardyn.dynamics.warm.compile_kernels` (compiled while
    the first process evaluates the maps and goes on) or a figure of the faulty body's mesh,
    which it holds then (:func:`geardyn.studies.stiffness_outputs.fe_mesh_png_task`). Yields a
    :class:`BackgroundBodies`. On leaving the block normally it waits for the process (whose
    bodies the block has then usually loaded already), unless there is ``then`` work, which goes
    on after the block; on an exception (Ctrl-C included) it stops the process at once. The
    process's own errors are not raised here: the block builds whatever the process did not,
    and raises the error itself. ``second_process=False`` builds the bodies in this process
    (before the block) whatever the machine allows.
    """
    from ...cache import default_cache

    cache = cache or default_cache()
    proc = None
    if second_process and _wanted(case, cache, method or case.stiffness.method):
        import multiprocessing

        proc = multiprocessing.get_context("spawn").Process(
            target=_build_faulty_bodies, args=(case, tuple(then), str(cache.root)),
            name="geardyn-fe-bodies", daemon=True)
        try:
            _start_quietly(proc)
        except (OSError, RuntimeError):  # no process to be had (limits, a frozen program...):
            proc = None                  # this one builds everything, as with 0
    if proc is None and _faulty_bodies_missing(case, cache, method or case.stiffness.method):
        from .model import FEStiffness  # the largest body while this process is smallest

        if progress is not None:
            progress(0, 0)  # shown at once: the first body's mesh comes before any count
        FEStiffness.bodies_into_cache(case, cracked=True, faulty_first=True, cache=cache,
                                      progress=progress)
    try:
        yield BackgroundBodies(proc)
    except BaseException:
        if proc is not None:
            proc.terminate()
            proc.join(timeout=10)
        raise
    if proc is not None and not then:
        proc.join()
    # with ``then`` it goes on after the block (that is its point); a daemon, it is stopped if
    # this process ends first (multiprocessing's exit handler), its unfinished work lost
