"""The faulty bodies of an FE map built by a second process while the first builds the healthy
ones (issue 16.3: "the bodies built in parallel where cores allow").

A cold pair of FE maps (healthy and faulty) solves three bodies one after the other: the healthy
pinion and gear, then the faulty body (the cracked pinion, loaded on every refined tooth, the
largest of the three). SuperLU holds the interpreter lock, so threads cannot overlap them; a
second *process* can. :func:`faulty_bodies_in_background` starts one that builds the faulty map's
bodies, faulty body first, into the disk cache, while the caller builds the healthy map. Each
body's cache entry has a lock (:meth:`geardyn.cache.Cache.get_or_build`): whichever process comes
to a body first builds it, the other waits for it and loads it. So the results are the same
bytes as a one-process build, whatever the timing (``tests/fe/test_background_bodies.py``).

It costs memory: two bodies are factorised at once (about 400 MB each for the paper's 150,880-DOF
pinion). The second process starts only when

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
import os
from collections.abc import Callable

__all__ = ["faulty_bodies_in_background", "tasks_in_background", "BackgroundBodies",
           "fe_processes", "starting_quietly", "FE_PROCESSES_ENV",
           "MIN_AVAILABLE_BYTES"]

#: Environment variable: 0 (one process), 1 (a second process builds the faulty bodies).
FE_PROCESSES_ENV = "GEARDYN_FE_PROCESSES"

#: Available memory [bytes] below which the default is one process (two paper bodies factorised
#: at once peak at about 1.2 GB for the whole ``geardyn run``, measured 2026-11-26).
MIN_AVAILABLE_BYTES = 3 * 1024 ** 3


def _available_memory() -> int | None:
    """``MemAvailable`` of ``/proc/meminfo`` [bytes], or None where there is none."""
    try:
        with open("/proc/meminfo", encoding="ascii") as fh:
            for line in fh:
                if line.startswith("MemAvailable:"):
                    return int(line.split()[1]) * 1024
    except (OSError, ValueError, IndexError):
        return None
    return None


def fe_processes() -> int:
    """1 if a second process may build FE bodies, else 0 (see the module docstring).

    Raises
    ------
    ValueError
        ``GEARDYN_FE_PROCESSES`` set to anything but 0 or 1 (the message names the variable,
        its value and what is allowed).
    """
    raw = os.environ.get(FE_PROCESSES_ENV)
    if raw is not None and raw.strip() != "":
        if raw.strip() not in ("0", "1"):
            raise ValueError(f"{FE_PROCESSES_ENV}={raw!r} is not allowed: 0 (build the FE "
                             "bodies in one process) or 1 (a second process builds the faulty "
                             "map's bodies)")
        return int(raw.strip())
    if (os.cpu_count() or 1) < 2:
        return 0
    avail = _available_memory()
    return 0 if avail is not None and avail < MIN_AVAILABLE_BYTES else 1


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
    try:
        from ...cache import Cache
        from .model import FEStiffness

        cache = None if cache_root is None else Cache(cache_root, enabled=True)
        FEStiffness(case, cracked=True, faulty_first=True, cache=cache)
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


@contextlib.contextmanager
def _without_main_module():
    """While starting a spawned process, hide where ``__main__`` came from.

    A spawned process imports the parent's main script (as ``__mp_main__``) unless told
    nothing about it; a user's script without an ``if __name__ == "__main__":`` guard would run
    again there and fail with multiprocessing's bootstrapping error. The second process runs
    geardyn's code only, so it needs nothing from ``__main__``: its ``__spec__`` and
    ``__file__`` (what :func:`multiprocessing.spawn.get_preparation_data` reads) are set aside
    while the process starts, then put back.
    """
    import sys

    main = sys.modules.get("__main__")
    saved = {}
    if main is not None:
        for name in ("__spec__", "__file__"):
            if name in vars(main):
                saved[name] = vars(main)[name]
        if "__spec__" in saved:
            main.__spec__ = None
        if "__file__" in saved:
            del main.__file__
    try:
        yield
    finally:
        for name, value in saved.items():
            setattr(main, name, value)


@contextlib.contextmanager
def starting_quietly():
    """While the block starts a spawned process (``Process.start()``, or the first ``submit``
    of a spawning process pool): the parent's main script hidden (:func:`_without_main_module`)
    and Ctrl-C ignored, so the new interpreter ignores it from its first instruction (an ignored
    SIGINT stays ignored across ``exec``) and a Ctrl-C while it imports prints no traceback of
    it (the first process reports the interruption and stops it). Outside the main thread
    signals cannot be changed, and the block runs with only the main script hidden."""
    import signal

    unchanged = object()
    with _without_main_module():
        try:
            old = signal.signal(signal.SIGINT, signal.SIG_IGN)
        except ValueError:  # not the main thread
            old = unchanged
        try:
            yield
        finally:
            if old is not unchanged:
                signal.signal(signal.SIGINT, old)


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
    anything but ``"fe"`` starts nothing. ``then``: module-level functions (no arguments) the
    second process calls after the bodies, e.g. :func:`geardyn.dynamics.warm.compile_kernels`
    (compiled while the first process evaluates the maps and goes on). Yields a
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
        FEStiffness(case, cracked=True, faulty_first=True, cache=cache, progress=progress)
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
