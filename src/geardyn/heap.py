"""Freed memory handed back to the operating system (glibc's ``malloc_trim``).

C's ``free`` returns memory to the allocator, not to the operating system: glibc keeps the
freed pages of its heap for the process's next allocations, so a process's resident set stays
near its highest point after a large temporary structure is gone. An FE body (mesh, assembly
blocks, stiffness matrix and CHOLMOD's factors; :mod:`geardyn.stiffness.fe.solve`) leaves
about 60 MB of such pages in the process that built it, and each stage of ``geardyn run``
40-75 MB (the paper's case, measured 2026-11-28, docs/performance.md). Where two processes
run at once (the FE bodies' second process, the figure process) their resident sets add up.

``malloc_trim(0)`` "attempts to release free memory from the heap (by calling sbrk(2) or
madvise(2) with suitable arguments) ... Since glibc 2.8 this function frees memory in all
arenas and in all chunks with whole free pages" (Linux man-pages, malloc_trim(3), 2020-08-13).
It frees nothing that is in use, so calling it changes no result, only the resident set and
the time of the next allocations that need fresh pages.

Other C libraries (macOS, musl, Windows) have no such function here; :func:`release_free_memory`
then does nothing and says so.

References
----------
malloc_trim(3), Linux man-pages (2020-08-13): https://man7.org/linux/man-pages/man3/malloc_trim.3.html
CPython 3.11, ``Modules/gcmodule.c``, ``gc_collect_generations``: a full collection is skipped
while ``long_lived_pending < long_lived_total / 4``.
"""

from __future__ import annotations

import functools
import gc

__all__ = ["release_free_memory"]


@functools.lru_cache(maxsize=1)
def _malloc_trim():
    """glibc's ``malloc_trim``, or None where the C library has none."""
    import ctypes
    import sys

    if not sys.platform.startswith("linux"):
        return None
    # the symbols the interpreter is linked with, glibc's among them (dlopen(NULL)); not
    # ctypes.util.find_library, which runs `ldconfig -p` as a child process: until it execs,
    # a child forked from a process of 400 MB shows that process's pages as its own, which
    # is probably how a benchmark's sampler, summing the processes' resident sets, saw a
    # `geardyn run --quick` at 911 MB (proportional set sizes 549 MB; 2026-11-28)
    try:
        fn = ctypes.CDLL(None).malloc_trim
    except (OSError, AttributeError):  # not glibc (musl has no malloc_trim)
        return None
    fn.argtypes = [ctypes.c_size_t]
    fn.restype = ctypes.c_int
    return fn


def release_free_memory(*, collect: bool = False) -> bool:
    """Give the pages the process has freed back to the operating system.

    Parameters
    ----------
    collect : bool
        Run Python's cyclic garbage collector first (objects in reference cycles are freed
        only by it). Costly in a long process, about 90 ms with ``geardyn run``'s imports
        (the trim of 60 MB about 13 ms), and not neutral: a collection after each FE body
        raised the later peak of a one-process ``geardyn run`` from 563-567 MB to 590 MB
        (2026-11-28). Probably because a full collection puts every surviving
        object in the oldest generation, which CPython collects again only once a quarter as
        many objects have joined it (``gc_collect_generations`` in CPython's
        ``Modules/gcmodule.c``), so the cyclic garbage made afterwards lives longer. geardyn
        collects only in the figure process, whose survivors it then freezes
        (:mod:`geardyn.studies.figure_process`).

    Returns
    -------
    bool
        True if glibc released memory, False if there was none to release or the C library
        has no ``malloc_trim`` (nothing is done then).
    """
    if collect:
        gc.collect()
    fn = _malloc_trim()
    return False if fn is None else bool(fn(0))
