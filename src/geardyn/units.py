"""Unit strings at the boundary, SI floats inside.

Case files, ``--set`` overrides and unit-bearing CLI options may give a quantity as a number
(taken as SI) or as a string ``"<number> <unit expression>"``, e.g. ``"6 mm"``, ``"20 deg"``,
``"1e6 N/m"``, ``"100 N m"``, ``"0.0025 kg m^2"``, ``"1090 rpm"``, ``"18.17 Hz"``.

Parsing is bounded and strict (issues 13 and 17):

* The text is read by a small grammar of our own before `pint <https://pint.readthedocs.io>`_
  sees anything: one decimal number, then unit names joined by spaces, ``*``, ``·`` or ``/``,
  each with an optional small integer power (``^2``, ``**-1``, ``|p| <= 4``), at most
  :data:`MAX_UNIT_TERMS` names and :data:`MAX_TEXT` characters. pint only resolves single unit
  names (``"mm"``, ``"kHz"``), so no expression is ever evaluated (``"10**10**10 mm"`` is refused
  at once instead of hanging).
* Every field has a declared :class:`Dimension`, checked with pint's dimensionality *and* with the
  power of the angle in the units (pint treats the radian as dimensionless, so without this
  ``"18.17 Hz"`` would pass for 18.17 rad/s and ``"20 percent"`` for an angle of 0.2 rad):

  - angles accept ``deg`` or ``rad`` (or ``turn``/``rev``) only, never a bare ratio like
    ``percent``;
  - angular velocities accept ``rad/s``, ``deg/s``, ``rpm``, ``rps``, and ``Hz`` (cycles per
    second, converted with 2 pi rad per cycle: ``"18.17 Hz"`` -> 114.16 rad/s); a bare ``1/s``
    is refused as ambiguous;
  - frequencies (sampling rates) accept ``Hz``, ``kHz``, ``MHz``, ``1/s``, never ``rpm`` or
    ``rad/s``;
  - torsional quantities (``N m/rad``, ``N m s/rad``, ``N m s^2/rad^2``) may omit the radian;
  - ratios such as ``percent`` are accepted for dimensionless values only.

* The result must be finite and of magnitude at most :data:`MAX_MAGNITUDE` (SI), so a value such
  as ``1e300`` m is refused here instead of overflowing later in the geometry.
"""

from __future__ import annotations

import functools
import math
import re
from dataclasses import dataclass

from .errors import InputError

__all__ = ["Dimension", "DIMENSIONS", "MAX_TEXT", "MAX_MAGNITUDE", "MAX_UNIT_TERMS", "to_si",
           "format_si", "parse_frequency", "parse_angular_velocity", "hz_note"]

#: Longest quantity string accepted [characters].
MAX_TEXT = 100
#: Largest magnitude accepted, in the field's SI unit (no gear quantity comes near it; it keeps
#: squares and cubes of lengths, stiffnesses and moduli far from float overflow).
MAX_MAGNITUDE = 1e30
#: Most unit names in one expression.
MAX_UNIT_TERMS = 8
#: Largest absolute integer power of one unit name.
MAX_POWER = 4


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
    target : str
        The SI unit as a pint expression (``"N * m / rad"``).
    angle_power : int
        Power of the plane angle in the SI unit (1 for rad/s, -1 for N m/rad, 0 for a length).
    units : str
        The accepted units in words, for error messages.
    """

    name: str
    pint_dim: str
    si_unit: str
    example: str
    target: str = ""
    angle_power: int = 0
    units: str = ""


DIMENSIONS: dict[str, Dimension] = {
    d.name: d
    for d in [
        Dimension("length", "[length]", "m", "6 mm", "m", 0, "m, mm, um, ..."),
        Dimension("angle", "", "rad", "20 deg", "rad", 1, "deg or rad"),
        Dimension("mass", "[mass]", "kg", "0.7 kg", "kg", 0, "kg, g, ..."),
        Dimension("inertia", "[mass] * [length] ** 2", "kg m^2", "0.0025 kg m^2", "kg * m ** 2",
                  0, "kg m^2, ..."),
        Dimension("stiffness", "[mass] / [time] ** 2", "N/m", "1e6 N/m", "N / m", 0,
                  "N/m, N/mm, ..."),
        Dimension("damping", "[mass] / [time]", "N s/m", "84 N s/m", "N * s / m", 0, "N s/m, ..."),
        Dimension("torsional stiffness", "[mass] * [length] ** 2 / [time] ** 2", "N m/rad",
                  "1e5 N m/rad", "N * m / rad", -1, "N m/rad (or N m), N m/deg, ..."),
        Dimension("torsional damping", "[mass] * [length] ** 2 / [time]", "N m s/rad",
                  "0.87 N m s/rad", "N * m * s / rad", -1, "N m s/rad (or N m s), ..."),
        Dimension("torque", "[mass] * [length] ** 2 / [time] ** 2", "N m", "100 N m", "N * m", 0,
                  "N m, kN m, ..."),
        Dimension("pressure", "[mass] / [length] / [time] ** 2", "Pa", "69 GPa", "Pa", 0,
                  "Pa, MPa, GPa, ..."),
        Dimension("time", "[time]", "s", "1e-5 s", "s", 0, "s, ms, us, ..."),
        Dimension("frequency", "1 / [time]", "Hz", "100 kHz", "Hz", 0, "Hz, kHz, MHz or 1/s"),
        Dimension("angular velocity", "1 / [time]", "rad/s", "114.14 rad/s", "rad / s", 1,
                  "rad/s, deg/s, rpm, rps or Hz (cycles per second, times 2 pi rad)"),
        Dimension("quadratic torque coefficient", "[mass] * [length] ** 2", "N m s^2/rad^2",
                  "0.0077 N m s^2", "N * m * s ** 2 / rad ** 2", -2,
                  "N m s^2/rad^2 (or N m s^2), ..."),
        Dimension("density", "[mass] / [length] ** 3", "kg/m^3", "2700 kg/m^3", "kg / m ** 3", 0,
                  "kg/m^3, g/cm^3, ..."),
        Dimension("acceleration", "[length] / [time] ** 2", "m/s^2", "50 g_n", "m / s ** 2", 0,
                  "m/s^2 or g_n (standard gravity)"),
        Dimension("dimensionless", "", "1", "0.05", "dimensionless", 0, "a plain number or %"),
    ]
}

_NUMBER = re.compile(r"[+-]?(?:\d+(?:\.\d*)?|\.\d+)(?:[eE][+-]?\d+)?")
_TOKEN = re.compile(r"\s+|\*\*|\^|\*|·|/|[+-]?\d+|[^\W\d]+|%|°|.", re.UNICODE)
_NAME = re.compile(r"(?:[^\W\d]+|%|°)", re.UNICODE)
_CYCLE_UNITS = frozenset({"hertz"})
_BASE_NAMES = {"gram": "mass", "meter": "length", "second": "time", "kelvin": "temperature",
               "ampere": "current", "mole": "substance", "candela": "luminosity"}


@functools.lru_cache(maxsize=1)
def _registry():
    import pint

    return pint.UnitRegistry(autoconvert_offset_to_baseunit=True)


_G, _M, _S, _R = "gram", "meter", "second", "radian"
_FORCE = ((_G, 1), (_M, 1), (_S, -2))
_PRESSURE = ((_G, 1), (_M, -1), (_S, -2))
#: pint's answers for the unit names of the shipped cases and the everyday ones, so that reading a
#: case does not pay pint's import and registry set-up (about 0.75 s per command). Not a second
#: unit system: ``tests/config/test_units.py`` asserts that every entry equals pint's answer, and
#: any other name goes to pint.
_KNOWN_UNITS: dict[str, tuple[float, tuple[tuple[str, float], ...], str]] = {
    "m": (1.0, ((_M, 1),), "meter"), "meter": (1.0, ((_M, 1),), "meter"),
    "mm": (1e-3, ((_M, 1),), "millimeter"), "cm": (1e-2, ((_M, 1),), "centimeter"),
    "um": (1e-6, ((_M, 1),), "micrometer"), "km": (1e3, ((_M, 1),), "kilometer"),
    "deg": (math.pi / 180, ((_R, 1),), "degree"), "degree": (math.pi / 180, ((_R, 1),), "degree"),
    "rad": (1.0, ((_R, 1),), "radian"), "radian": (1.0, ((_R, 1),), "radian"),
    "kg": (1e3, ((_G, 1),), "kilogram"), "g": (1.0, ((_G, 1),), "gram"),
    "N": (1e3, _FORCE, "newton"), "kN": (1e6, _FORCE, "kilonewton"),
    "Pa": (1e3, _PRESSURE, "pascal"), "MPa": (1e9, _PRESSURE, "megapascal"),
    "GPa": (1e12, _PRESSURE, "gigapascal"),
    "s": (1.0, ((_S, 1),), "second"), "second": (1.0, ((_S, 1),), "second"),
    "ms": (1e-3, ((_S, 1),), "millisecond"), "us": (1e-6, ((_S, 1),), "microsecond"),
    "Hz": (1.0, ((_S, -1),), "hertz"), "kHz": (1e3, ((_S, -1),), "kilohertz"),
    "MHz": (1e6, ((_S, -1),), "megahertz"),
    "rpm": (2 * math.pi / 60, ((_R, 1), (_S, -1)), "revolutions_per_minute"),
    "rps": (2 * math.pi, ((_R, 1), (_S, -1)), "revolutions_per_second"),
    "g_n": (9.80665, ((_M, 1), (_S, -2)), "standard_gravity"),
    "percent": (0.01, (), "percent"), "%": (0.01, (), "percent"),
}
#: pint's root form of each dimension's target unit (asserted equal to pint in the same test).
_KNOWN_TARGETS: dict[str, tuple[float, dict[str, float]]] = {
    "length": (1.0, {_M: 1}), "angle": (1.0, {_R: 1}), "mass": (1e3, {_G: 1}),
    "inertia": (1e3, {_G: 1, _M: 2}), "stiffness": (1e3, {_G: 1, _S: -2}),
    "damping": (1e3, {_G: 1, _S: -1}),
    "torsional stiffness": (1e3, {_G: 1, _M: 2, _S: -2, _R: -1}),
    "torsional damping": (1e3, {_G: 1, _M: 2, _S: -1, _R: -1}),
    "torque": (1e3, {_G: 1, _M: 2, _S: -2}), "pressure": (1e3, {_G: 1, _M: -1, _S: -2}),
    "time": (1.0, {_S: 1}), "frequency": (1.0, {_S: -1}),
    "angular velocity": (1.0, {_R: 1, _S: -1}),
    "quadratic torque coefficient": (1e3, {_G: 1, _M: 2, _R: -2}),
    "density": (1e3, {_G: 1, _M: -3}), "acceleration": (1.0, {_M: 1, _S: -2}),
    "dimensionless": (1.0, {}),
}


@functools.lru_cache(maxsize=512)
def _unit_root(name: str) -> tuple[float, tuple[tuple[str, float], ...], str] | None:
    """``(factor, root units, canonical name)`` of one unit name, or None if pint does not know it.

    The name is a single identifier (letters only, at most 30 characters), so pint's lookup is
    bounded. Everyday names come from :data:`_KNOWN_UNITS` (pint's own answers, tested).
    """
    if name in _KNOWN_UNITS:
        return _KNOWN_UNITS[name]
    return _pint_unit_root(name)


def _pint_unit_root(name: str) -> tuple[float, tuple[tuple[str, float], ...], str] | None:
    """:func:`_unit_root` asked of pint."""
    ureg = _registry()
    try:
        unit = ureg.Unit(name)
    except Exception:  # pint raises several types for unknown names
        return None
    items = list((1.0 * unit).unit_items())
    if len(items) != 1:  # a name pint expands to a product: not a plain unit name
        return None
    root = (1.0 * unit).to_root_units()
    return float(root.magnitude), tuple(sorted(root.unit_items())), str(items[0][0])


@functools.lru_cache(maxsize=64)
def _target_root(dimension: str) -> tuple[float, dict[str, float]]:
    if dimension in _KNOWN_TARGETS:
        return _KNOWN_TARGETS[dimension]
    return _pint_target_root(dimension)


def _pint_target_root(dimension: str) -> tuple[float, dict[str, float]]:
    """The root form of a dimension's target unit, asked of pint."""
    ureg = _registry()
    root = (1.0 * ureg.Unit(DIMENSIONS[dimension].target)).to_root_units()
    return float(root.magnitude), dict(root.unit_items())


def _short(text: str, n: int = 60) -> str:
    return text if len(text) <= n else text[: n - 1] + "…"


def _dimension_of_root(root: dict[str, float]) -> str | None:
    """The name of the dimension (of :data:`DIMENSIONS`) whose SI unit has the root units
    ``root`` (``{"radian": 1}``: an angle), or None."""
    for name in DIMENSIONS:
        if name == "dimensionless":
            continue
        try:
            if _target_root(name)[1] == root:
                return name
        except Exception:  # noqa: BLE001 - a dimension pint cannot express: not this one
            continue
    return None


def _a(name: str) -> str:
    return ("an " if name[0] in "aeiou" else "a ") + name


def _allowed(dim: Dimension) -> str:
    return (f"{_a(dim.name)} as a number in {dim.si_unit} or a string with a unit "
            f"({dim.units}), e.g. {dim.example!r}")


def _parse_units(text: str, field: str, allowed: str, value: str):
    """Tokenise a unit expression into ``[(name, power)]`` under the bounded grammar."""
    terms: list[tuple[str, int]] = []
    sign = 1
    expect = True  # a unit name is expected next
    tokens = _TOKEN.findall(text.strip())
    i = 0
    # "1/s": a leading 1 as the numerator of the unit
    if tokens and tokens[0] == "1":
        j = 1
        while j < len(tokens) and tokens[j].isspace():
            j += 1
        if j < len(tokens) and tokens[j] == "/":
            i, sign = j + 1, -1

    def bad(why: str) -> InputError:
        return InputError(field, value, f"{allowed} ({why})")

    while i < len(tokens):
        tok = tokens[i]
        if tok.isspace():
            i += 1
            continue
        if _NAME.fullmatch(tok):
            if len(tok) > 30:
                raise bad("a unit name of at most 30 letters")
            power = 1
            k = i + 1
            if k < len(tokens) and tokens[k] in ("^", "**"):
                if k + 1 >= len(tokens) or not re.fullmatch(r"[+-]?\d+", tokens[k + 1]):
                    raise bad(f"a small whole power after {tokens[k]!r}")
                p = int(tokens[k + 1]) if len(tokens[k + 1]) <= 3 else MAX_POWER + 1
                if not 1 <= abs(p) <= MAX_POWER:
                    raise bad(f"unit powers between -{MAX_POWER} and {MAX_POWER}")
                power = p
                k += 2
                if k < len(tokens) and tokens[k] in ("^", "**"):
                    raise bad("one power per unit, no chains such as '10**10**10'")
            terms.append((tok, sign * power))
            if len(terms) > MAX_UNIT_TERMS:
                raise bad(f"at most {MAX_UNIT_TERMS} unit names")
            sign, expect = 1, False
            i = k
            continue
        if tok in ("*", "·", "/") and not expect:
            sign = -1 if tok == "/" else 1
            expect = True
            i += 1
            continue
        raise bad(f"a number followed by unit names, '*', '/' and small powers; "
                  f"cannot read {_short(tok, 12)!r}")
    if expect and terms:
        raise bad("a unit name after the last operator")
    if not terms:
        raise bad("a unit after the number")
    return terms


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
        If the string does not parse under the bounded grammar, has the wrong dimension or
        angle, or the number is not finite or exceeds :data:`MAX_MAGNITUDE`.
    """
    dim = DIMENSIONS[dimension]
    allowed = _allowed(dim)
    if isinstance(value, bool):
        raise InputError(field, value, allowed)
    if isinstance(value, int):
        if abs(value) > MAX_MAGNITUDE:
            raise InputError(field, value, f"a number of magnitude <= {MAX_MAGNITUDE:g} "
                                           f"({dim.si_unit})")
        out = float(value)
    elif isinstance(value, float):
        out = value
    elif isinstance(value, str):
        out = _parse(value, dim, field, allowed)
    else:
        raise InputError(field, value, allowed)
    if not math.isfinite(out):
        raise InputError(field, value, f"a finite number ({allowed})")
    if abs(out) > MAX_MAGNITUDE:
        raise InputError(field, value, f"{_a(dim.name)} of magnitude <= {MAX_MAGNITUDE:g} "
                                       f"{dim.si_unit}")
    return float(out)


def _parse(value: str, dim: Dimension, field: str, allowed: str) -> float:
    if len(value) > MAX_TEXT:
        raise InputError(field, value, f"{allowed} (at most {MAX_TEXT} characters)")
    text = value.strip()
    m = _NUMBER.match(text)
    if text.lower().lstrip("+-").startswith(("nan", "inf")):
        raise InputError(field, value, f"a finite number ({allowed})")
    if m is None:
        raise InputError(field, value, f"{allowed} (it must start with a number)")
    number = float(m.group(0))  # decimal text of <= MAX_TEXT characters: bounded
    rest = text[m.end():]
    if not rest.strip():
        return number
    if not (rest[0].isspace() or rest[0] in "*·/%" or _NAME.match(rest[0])):
        raise InputError(field, value, f"{allowed} (cannot read {_short(rest, 12)!r} after the "
                                       "number)")
    terms = _parse_units(rest, field, allowed, value)
    factor = 1.0
    root: dict[str, float] = {}
    cycles = False
    for name, power in terms:
        info = _unit_root(name)
        if info is None:
            raise InputError(field, value, f"{allowed} (unknown unit {_short(name, 30)!r})")
        f, units, canonical = info
        if not units and dim.name != "dimensionless":  # percent, ppm, ...: a bare ratio
            raise InputError(field, value, f"{allowed} ({canonical!r} is a plain ratio, not a "
                                           f"unit of {dim.name})")
        factor *= f ** power
        for u, p in units:
            root[u] = root.get(u, 0) + p * power
        cycles |= canonical.endswith(tuple(_CYCLE_UNITS))  # hertz, kilohertz, ...
    root = {u: p for u, p in root.items() if p != 0}
    t_factor, t_units = _target_root(dim.name)
    angle = root.pop("radian", 0)
    want_angle = t_units.get("radian", 0)
    t_root = {u: p for u, p in t_units.items() if u != "radian"}
    if root != t_root:
        given = _dimension_of_root({**root, **({"radian": angle} if angle else {})})
        if given is not None:  # "5 deg" for a length: "'deg' is an angle, not a length"
            raise InputError(field, value, f"{allowed} ({_short(rest.strip(), 20)!r} is "
                                           f"{_a(given)}, not {_a(dim.name)})")
        have = " ".join(f"{_BASE_NAMES.get(u, u)}^{p:g}" for u, p in sorted(root.items())) \
            or "no dimension"
        raise InputError(field, value, f"{allowed} (this has units {have}, not {_a(dim.name)})")
    note = 1.0
    if angle != want_angle:
        if angle == 0 and dim.name == "angular velocity" and cycles:
            note = 2 * math.pi  # Hz = cycles per second, one cycle = 2 pi rad
        elif angle == 0 and want_angle < 0:
            pass  # N m for N m/rad: per radian is implied
        elif angle == 0 and dim.name == "angular velocity":
            raise InputError(field, value, f"{allowed} ('1/s' is ambiguous for an angular "
                                           "velocity: write rad/s, or Hz for cycles per second)")
        elif angle == 0:
            raise InputError(field, value, f"{allowed} (no angle unit: {_a(dim.name)} needs one)")
        else:
            raise InputError(field, value, f"{allowed} (an angle unit does not belong in "
                                           f"{_a(dim.name)})")
    with_unit = number * (factor / t_factor) * note
    return with_unit


def hz_note(value: object) -> str | None:
    """``"x 2 pi rad/cycle"`` if a value string is an angular velocity given in Hz, else None.

    Used by ``geardyn config show`` to state the conversion beside the value.
    """
    if not isinstance(value, str) or len(value) > MAX_TEXT:
        return None
    return "Hz = cycles/s, x 2 pi rad/cycle" if re.search(r"(?<![A-Za-z])[kMG]?Hz\b", value) \
        else None


def parse_frequency(value: object, field: str = "--fs") -> float:
    """A frequency or sampling rate in Hz from a number (Hz) or a string (``"20 kHz"``).

    Accepts ``Hz``, ``kHz``, ``MHz`` and ``1/s``; refuses ``rpm``, ``rad/s`` and anything else
    with the allowed units in the message. Must be > 0.

    Parameters
    ----------
    value : float, int or str
    field : str
        Option or field name for messages (``"--fs"``).

    Returns
    -------
    float
        Frequency [Hz].
    """
    out = to_si(value, "frequency", field)
    if not out > 0:
        raise InputError(field, value, "a frequency > 0 (Hz, kHz, MHz or 1/s), e.g. '20 kHz'")
    return out


def parse_angular_velocity(value: object, field: str) -> float:
    """An angular velocity in rad/s from a number (rad/s) or a string.

    ``"1090 rpm"`` -> 114.14 rad/s; ``"18.17 Hz"`` -> 114.16 rad/s (cycles per second times
    2 pi rad per cycle); ``"100 deg/s"``; a bare ``1/s`` is refused as ambiguous.

    Returns
    -------
    float
        Angular velocity [rad/s].
    """
    return to_si(value, "angular velocity", field)


def format_si(value: float, dimension: str) -> str:
    """Format an SI float with its SI unit, e.g. ``format_si(0.006, "length") == "0.006 m"``."""
    unit = DIMENSIONS[dimension].si_unit
    if unit == "1":
        return repr(float(value))
    return f"{float(value)!r} {unit}"
