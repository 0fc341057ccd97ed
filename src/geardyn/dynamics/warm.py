"""Compile the time-step kernels ahead of need, in a process that would otherwise wait.

numba compiles the 6-DOF kernel (:func:`geardyn.dynamics._kernel.advance` and the functions it
calls) on its first call after an install or an upgrade, about 5-7 s on the 2-core machine, and
caches the machine code on disk (``cache=True``); every later process loads it in about 0.1 s.
:func:`compile_kernels` makes that first call on a 2 ms simulation of a constant-stiffness
table map, so that a second process can compile while the first is busy elsewhere
(``geardyn run`` does this in the process that builds the faulty FE bodies,
:mod:`geardyn.stiffness.fe.background`). The kernel's argument types depend neither on the
case's sizes nor on the map's method, so this one call compiles the signature every simulation
uses (``tests/dynamics/test_compile_kernels.py``: a PEM run after it compiles nothing); a
process that calls the kernel before the compiled code is on disk compiles it itself, with the
same result. The call runs the steps only (:func:`geardyn.dynamics.newmark.integrate`): no
record, so the compiling process imports neither xarray nor the PEM code (0.9 s of a first
``geardyn run --quick``, measured 2026-11-27).

It then compiles the resampling kernel of the time-synchronous average
(:func:`geardyn.diagnostics.tsa.tsa`) on a four-revolution sine: every diagnosis of a run
calls it, and the first run's first process compiled it itself, 0.45 s before its diagnostics
stage (``py-spy`` of a first ``geardyn run --quick``, 2026-11-27), when the compiling process
had ended seconds earlier. Its argument types are those of every call (float64 arrays, C order:
:func:`~geardyn.diagnostics.tsa.tsa` makes them so), whatever the signal count and length.
"""

from __future__ import annotations

import time

__all__ = ["compile_kernels", "kernels_compiled"]


def compile_kernels() -> float:
    """Compile (or load from numba's cache) the 6-DOF time-step kernel, then the TSA's
    resampling kernel.

    Returns
    -------
    float
        Wall time [s] it took (about 0.3 s when the kernel was already cached).
    """
    t0 = time.perf_counter()
    import numpy as np

    from ..config import paper_case
    from ..stiffness import centre_distance_grid
    from ..stiffness.map import StiffnessMap
    from .newmark import integrate

    case = paper_case().with_overrides({
        "stiffness.method": "pem", "stiffness.centre_distances": 3,
        "simulation.record_time": "0.002 s", "simulation.settle_time": "0 s"})
    pair = case.gear_pair()
    theta = np.linspace(0.0, pair.mesh_angle, 16, endpoint=False)
    stiffness_map = StiffnessMap.from_table(pair, theta, np.full((3, theta.size), 4.0e8),
                                            dd=centre_distance_grid(case), n_seg=8)
    integrate(case, stiffness_map, "II", cracked=False)
    _compile_tsa()
    return time.perf_counter() - t0


def _compile_tsa() -> None:
    """A TSA of two signals over four revolutions with the numba kernel (the default engine):
    the signature every diagnosis uses, compiled or loaded from numba's cache."""
    import numpy as np

    from ..diagnostics.tsa import tsa

    angle = np.linspace(0.0, 8.0 * np.pi, 257)
    x = np.stack([np.sin(angle), np.cos(3.0 * angle)])
    tsa(x, angle=angle, samples_per_rev=16)


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
