"""Compile the time-step kernels ahead of need, in a process that would otherwise wait.

numba compiles the 6-DOF kernel (:func:`geardyn.dynamics._kernel.advance` and the functions it
calls) on its first call after an install or an upgrade, about 5-7 s on the 2-core machine, and
caches the machine code on disk (``cache=True``); every later process loads it in about 0.1 s.
:func:`compile_kernels` makes that first call on a 2 ms simulation of a small PEM map, so that
a second process can compile while the first is busy elsewhere (``geardyn run`` does this in
the process that builds the faulty FE bodies, :mod:`geardyn.stiffness.fe.background`). The
kernel's argument types do not depend on the case's sizes, so this one call compiles the
signature every simulation uses; a process that calls the kernel before the compiled code is
on disk compiles it itself, with the same result.
"""

from __future__ import annotations

import time

__all__ = ["compile_kernels", "kernels_compiled"]


def compile_kernels() -> float:
    """Compile (or load from numba's cache) the 6-DOF time-step kernel.

    Returns
    -------
    float
        Wall time [s] it took (about 0.3 s when the kernel was already cached).
    """
    t0 = time.perf_counter()
    from ..config import paper_case
    from ..stiffness import centre_distance_grid
    from ..stiffness.pem import pem_map
    from .newmark import simulate

    case = paper_case().with_overrides({
        "stiffness.method": "pem", "stiffness.centre_distances": 3,
        "stiffness.nodes_per_segment": 8, "simulation.record_time": "0.002 s",
        "simulation.settle_time": "0 s"})
    stiffness_map = pem_map(case, centre_distance_grid(case), cracked=False)
    simulate(case, stiffness_map, model="II")
    return time.perf_counter() - t0


def kernels_compiled() -> bool:
    """Whether numba's disk cache holds the time-step kernel compiled from these sources for
    this machine's CPU (then :func:`compile_kernels` only loads it).

    Reads the cache index of :func:`geardyn.dynamics._kernel.advance` (numba invalidates an
    index whose source file changed) and looks for an entry of this CPU's code generator.
    Any surprise in numba's internals answers False: the caller then compiles, which is only
    slower.
    """
    try:
        from ._kernel import advance

        index = advance._cache._cache_file._load_index()
        magic = advance.targetctx.codegen().magic_tuple()
        return any(key[1] == magic for key in index)
    except Exception:  # noqa: BLE001 - numba internals: unknown means not compiled
        return False
