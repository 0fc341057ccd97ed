"""Second processes: whether geardyn may use them, and how it starts one.

``geardyn run`` and ``geardyn stiffness`` use a second process where the machine allows it: one
builds a faulty FE map's bodies (:mod:`geardyn.stiffness.fe.background`), one draws the report's
figures (:mod:`geardyn.studies.figure_process`). :func:`fe_processes` is the one policy for
both; :func:`starting_quietly` the one way to start them (spawned, without the caller's main
script, Ctrl-C ignored); :func:`skip_collection_at_exit` shortens the exit of every process
geardyn owns. This module imports nothing heavy, so the CLI can check the setting
before it claims an output folder.
"""

from __future__ import annotations

import contextlib
import os

__all__ = ["fe_processes", "starting_quietly", "skip_collection_at_exit", "FE_PROCESSES_ENV",
           "MIN_AVAILABLE_BYTES"]

#: Environment variable: 0 (one process), 1 (second processes for the faulty FE bodies and the
#: report's figures).
FE_PROCESSES_ENV = "GEARDYN_FE_PROCESSES"

#: Available memory [bytes] below which the default is one process (two paper bodies factorised
#: at once peak at about 1.2 GB for the whole ``geardyn run``, measured 2026-11-26).
MIN_AVAILABLE_BYTES = 3 * 1024 ** 3


def skip_collection_at_exit() -> None:
    """Let this process exit without the garbage collector's last passes: :func:`gc.freeze`
    from an :mod:`atexit` handler.

    An interpreter that has imported numba, matplotlib, xarray and SciPy spends most of its exit
    in the collector's passes over every object still alive: about 0.4 s of a warm ``geardyn
    run`` (3.58-3.72 s against 4.00-4.10 s, four alternating runs, 2026-11-26), and as long in
    the figure process, whose exit the first process waits for (``--quick``: 12.5-13.5 s against
    14.4-14.8 s). The other exit handlers run as before (temporary folders,
    multiprocessing's finalizers, logging); only the collection is skipped, so an object left
    in a reference cycle is not finalised at exit, which Python does not promise anyway (geardyn
    closes its files itself and writes them under a temporary name, then renames). For
    processes that exit after their work (the console script, the second processes), never in
    a library call.
    """
    import atexit
    import gc

    atexit.register(gc.freeze)


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
    """1 if geardyn may use a second process (FE bodies, figures), else 0.

    ``GEARDYN_FE_PROCESSES``: ``0`` never, ``1`` always; unset (the default) when the machine
    has at least 2 cores and at least :data:`MIN_AVAILABLE_BYTES` of available memory (or does
    not say how much it has).

    Raises
    ------
    geardyn.errors.InputError
        ``GEARDYN_FE_PROCESSES`` set to anything but 0 or 1 (the message names the variable,
        its value and what is allowed; a ``ValueError``).
    """
    raw = os.environ.get(FE_PROCESSES_ENV)
    if raw is not None and raw.strip() != "":
        if raw.strip() not in ("0", "1"):
            from .errors import InputError  # a user's setting: exit 2 and one line in the CLI

            raise InputError(FE_PROCESSES_ENV, raw, "0 (everything in one process) or 1 (a "
                             "second process builds the faulty FE map's bodies, and one draws "
                             "the report's figures)")
        return int(raw.strip())
    if (os.cpu_count() or 1) < 2:
        return 0
    avail = _available_memory()
    return 0 if avail is not None and avail < MIN_AVAILABLE_BYTES else 1


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
