"""geardyn: dynamics and vibration diagnostics of flexibly supported spur gears.

Implements Xue & Howard (2018), "Dynamic modelling of flexibly supported gears using iterative
convergence of tooth mesh stiffness", end to end: geometry, mesh stiffness, the 6-DOF model I / II
dynamics and gear diagnostics.

Where to start (each documented with its units; ``help(geardyn.simulate)``)::

    case = geardyn.paper_case()               # or geardyn.load_case("my_case.toml")
    k = geardyn.build_map(case)               # mesh stiffness K(theta, centre distance) [N/m]
    record = geardyn.simulate(case, k)        # model II by default: an xarray Dataset, SI units
    result = geardyn.diagnose_file("rec.nc")  # TSA, residual, FM0/FM4/NA4..., as the CLI does
    m = geardyn.measure(case)                 # a housing accelerometer and a tachometer
    te = geardyn.static_te_of_case(case)      # loaded static transmission error

``geardyn.diagnose`` takes signals already in memory; ``geardyn.run_paper_study`` is
``geardyn run`` as a function.

The names below are imported on first use (PEP 562): ``import geardyn`` alone loads neither
the case models (pydantic) nor the geometry, so that a process that needs one part of geardyn
(the report's figure process, the kernel's compiler, a CLI refusal) does not import the rest.
``from geardyn import Case`` and ``geardyn.Case`` work as before.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

from ._version import __version__

if TYPE_CHECKING:  # for type checkers and IDEs; at run time see __getattr__
    from .config import Case, load_case, paper_case
    from .diagnostics import diagnose, diagnose_file
    from .dynamics import simulate
    from .errors import DataFileError, GeardynError, GeometryError, InputError, NumericalError
    from .geometry import Gear, GearPair, OperatingGeometry, centre_distance_from_displacements
    from .static_te import static_te_of_case
    from .stiffness import build_map
    from .studies.measure import measure
    from .studies.paper import run_paper_study

#: Public name -> the submodule that defines it.
_LAZY = {
    "Case": "config", "load_case": "config", "paper_case": "config",
    "Gear": "geometry", "GearPair": "geometry", "OperatingGeometry": "geometry",
    "centre_distance_from_displacements": "geometry",
    "GeardynError": "errors", "InputError": "errors", "GeometryError": "errors",
    "NumericalError": "errors", "DataFileError": "errors",
    "build_map": "stiffness", "simulate": "dynamics", "diagnose": "diagnostics",
    "diagnose_file": "diagnostics", "measure": "studies.measure",
    "static_te_of_case": "static_te", "run_paper_study": "studies.paper",
}

__all__ = [
    "__version__",
    "Case",
    "load_case",
    "paper_case",
    "Gear",
    "GearPair",
    "OperatingGeometry",
    "centre_distance_from_displacements",
    "GeardynError",
    "InputError",
    "GeometryError",
    "NumericalError",
    "DataFileError",
    "build_map",
    "simulate",
    "diagnose",
    "diagnose_file",
    "measure",
    "static_te_of_case",
    "run_paper_study",
]


def __getattr__(name: str):
    module = _LAZY.get(name)
    if module is None:
        raise AttributeError(f"module 'geardyn' has no attribute {name!r}")
    import importlib

    value = getattr(importlib.import_module(f".{module}", __name__), name)
    globals()[name] = value  # imported once
    return value


def __dir__() -> list[str]:
    return sorted(set(globals()) | set(__all__))
