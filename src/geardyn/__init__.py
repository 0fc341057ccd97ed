"""geardyn: dynamics and vibration diagnostics of flexibly supported spur gears.

Implements Xue & Howard (2018), "Dynamic modelling of flexibly supported gears using iterative
convergence of tooth mesh stiffness", end to end: geometry, mesh stiffness, the 6-DOF model I / II
dynamics and gear diagnostics.
"""

from __future__ import annotations

from ._version import __version__
from .config import Case, load_case, paper_case
from .errors import DataFileError, GeardynError, GeometryError, InputError, NumericalError
from .geometry import Gear, GearPair, OperatingGeometry, centre_distance_from_displacements

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
]
