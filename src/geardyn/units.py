"""Unit strings at the boundary, SI floats inside.

Case files and ``--set`` overrides may give a quantity as a number (taken as SI) or as a string with
a unit, e.g. ``"6 mm"``, ``"20 deg"``, ``"1e6 N/m"``, ``"100 N m"``, ``"0.0025 kg m^2"``,
``"1090 rpm"``. Parsing uses `pint <https://pint.readthedocs.io>`_ (loaded lazily, on the first
string), and every quantity is checked against the dimension its field expects, so ``"0.7 m"``
given for a mass is refused with a message that names the field, the value and an example of an
accepted unit.
"""

from __future__ import annotations

import functools
import math
from dataclasses import dataclass

from .errors import InputError

__all__ = ["Dimension", "DIMENSIONS", "to_si", "format_si"]


@dataclass(frozen=True)
class Dimension:
    """A physical dimension a config field expects.

    Attributes
    ----------
    name : str
        Human name, used in error messages (``"length"``).
    pint_dim : str
        pint dimensionality string (``"[length]"``); ``""`` for dimensionless.
    si_unit : str
        The SI unit geardyn stores the value in (``"m"``).
    example : str
        An example of an accepted string (``"6 mm"``).
    """

    name: str
    pint_dim: str
    si_unit: str
    example: str


DIMENSIONS: dict[str, Dimension] = {
    d.name: d
    for d in [
        Dimension("length", "[length]", "m", "6 mm"),
        Dimension("angle", "", "rad", "20 deg"),
        Dimension("mass", "[mass]", "kg", "0.7 kg"),
        Dimension("inertia", "[mass] * [length] ** 2", "kg m^2", "0.0025 kg m^2"),
        Dimension("stiffness", "[mass] / [time] ** 2", "N/m", "1e6 N/m"),
        Dimension("damping", "[mass] / [time]", "N s/m", "84 N s/m"),
        Dimension("torsional stiffness", "[mass] * [length] ** 2 / [time] ** 2", "N m/rad",
                  "1e5 N m/rad"),
        Dimension("torsional damping", "[mass] * [length] ** 2 / [time]", "N m s/rad",
                  "0.87 N m s/rad"),
        Dimension("torque", "[mass] * [length] ** 2 / [time] ** 2", "N m", "100 N m"),
        Dimension("pressure", "[mass] / [length] / [time] ** 2", "Pa", "69 GPa"),
        Dimension("time", "[time]", "s", "1e-5 s"),
        Dimension("frequency", "1 / [time]", "Hz", "100 kHz"),
        Dimension("angular velocity", "1 / [time]", "rad/s", "114.14 rad/s"),
        Dimension("quadratic torque coefficient", "[mass] * [length] ** 2", "N m s^2/rad^2",
                  "0.0077 N m s^2"),
        Dimension("density", "[mass] / [length] ** 3", "kg/m^3", "2700 kg/m^3"),
        Dimension("dimensionless", "", "1", "0.05"),
    ]
}


@functools.lru_cache(maxsize=1)
def _registry():
    import pint

    ureg = pint.UnitRegistry(autoconvert_offset_to_baseunit=True)
    return ureg


@functools.lru_cache(maxsize=1)
def _dimensionalities():
    ureg = _registry()
    out = {}
    for name, dim in DIMENSIONS.items():
        out[name] = ureg.Quantity(1.0).dimensionality if not dim.pint_dim else \
            ureg.get_dimensionality(dim.pint_dim)
    return out


def to_si(value: object, dimension: str, field: str) -> float:
    """Convert a number or a unit string to an SI float of the given dimension.

    Parameters
    ----------
    value : float, int or str
        A bare number (already SI) or a string such as ``"6 mm"``.
    dimension : str
        Key of :data:`DIMENSIONS` the field expects.
    field : str
        Dotted name of the field, for error messages.

    Returns
    -------
    float
        The value in the SI unit of ``dimension`` (``DIMENSIONS[dimension].si_unit``).

    Raises
    ------
    InputError
        If the string does not parse, has the wrong dimension, or the number is not finite.
    """
    dim = DIMENSIONS[dimension]
    allowed = f"a {dim.name} as a number in {dim.si_unit} or a string with a unit, e.g. {dim.example!r}"
    if isinstance(value, bool):
        raise InputError(field, value, allowed)
    if isinstance(value, int | float):
        out = float(value)
    elif isinstance(value, str):
        text = value.strip()
        try:
            out = float(text)
        except ValueError:
            out = _parse(text, dim, field, allowed)
    else:
        raise InputError(field, value, allowed)
    if not math.isfinite(out):
        raise InputError(field, value, "a finite number")
    return out


def _parse(text: str, dim: Dimension, field: str, allowed: str) -> float:
    import pint

    ureg = _registry()
    try:
        q = ureg.Quantity(text)
    except Exception as exc:  # pint's parser raises many types on bad text
        raise InputError(field, text, allowed + f" (could not read the unit: {exc})") from None
    if not isinstance(q, pint.Quantity):  # a bare number expression such as "2*3"
        return float(q)
    want = _dimensionalities()[dim.name]
    have = q.dimensionality
    if have != want:
        raise InputError(field, text, allowed + f" (this has dimension {have or 'none'})")
    try:
        if dim.name in ("angle", "dimensionless"):
            return float(q.to("radian").magnitude if dim.name == "angle" else
                         q.to("dimensionless").magnitude)
        if dim.name == "angular velocity":
            return float(q.to("radian / second").magnitude)
        return float(q.to_base_units().magnitude)
    except pint.errors.PintError as exc:  # pragma: no cover - dimension already checked
        raise InputError(field, text, allowed + f" ({exc})") from None


def format_si(value: float, dimension: str) -> str:
    """Format an SI float with its SI unit, e.g. ``format_si(0.006, "length") == "0.006 m"``."""
    unit = DIMENSIONS[dimension].si_unit
    if unit == "1":
        return repr(float(value))
    return f"{float(value)!r} {unit}"
