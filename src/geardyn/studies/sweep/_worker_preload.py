"""Imported by the forkserver of a local sweep cluster before it forks the workers
(:mod:`.local_workers`): what a worker of a PEM or FE-map sweep imports for its tasks (the FE
mesher and solver too: 0.08 s and 17 MB here, shared, against every worker of an FE sweep
importing them in its preparation task).

The list was read from a worker's ``sys.modules`` before and after a sweep (``Client.run``).
numba's typing and lowering registries, which numba loads on the first compile or cache load in
a process (``numba.cpython.charseq``, ``listobj``, ``arraymath``, ...), are loaded here too.
Nothing is compiled and no thread is started: a worker forked from this process is as one that
imported these modules itself.
"""

from __future__ import annotations

import importlib

MODULES = ("numpy", "scipy.sparse", "scipy.interpolate", "scipy.signal", "pandas", "xarray",
           "dask.array", "zarr", "h5netcdf", "pint", "filelock", "numba",
           "geardyn.studies.sweep.execute", "geardyn.studies.sweep.evaluate", "geardyn.cache",
           "geardyn.faults", "geardyn.stiffness.pem", "geardyn.stiffness.map",
           "geardyn.dynamics.newmark", "geardyn.dynamics.results",
           "geardyn.diagnostics.pipeline", "skfem", "gmsh", "geardyn.stiffness.fe.model",
           "geardyn.stiffness.fe.substructure")


def _preload() -> None:
    for name in MODULES:
        try:
            importlib.import_module(name)
        except ImportError:  # an optional library missing: the worker imports what it needs
            continue
    from geardyn.io import netcdf_engine

    netcdf_engine()  # netCDF4 where geardyn uses it (not where its HDF5 clashes with h5py's)
    try:
        from numba.core.registry import cpu_target

        cpu_target.typing_context.refresh()
        cpu_target.target_context.refresh()
    except Exception:  # a warm-up only: a worker loads what numba still needs itself
        return


_preload()
