"""Every physical check of a case that needs no simulation (``geardyn config validate``).

:func:`check_case` runs, in order, the checks the later stages would run anyway, so that a case
``config validate`` accepts is not refused by ``simulate`` (issue 13: a 50 mm crack passed
validation and failed at simulation). It adds no physics of its own; each check is the stage's
own code:

1. the gear pair (:meth:`geardyn.config.Case.gear_pair`: teeth, radii, bore, profile shift);
2. the operating geometry over the stiffness map's centre-distance range
   (:meth:`geardyn.geometry.GearPair.operating`: contact ratio >= 1, centre distance above the
   base-radius sum), reported on ``stiffness.centre_distance_min``/``_max``;
3. the stiffness method's own model: for ``pem``, :class:`geardyn.stiffness.pem.PEMModel` (crack
   tooth number, the crack geometry of :func:`geardyn.stiffness.pem.crack_geometry` through the
   cracked tooth section, pointed teeth) and its ``check_range`` (interference over the range);
   for ``fe``, :class:`geardyn.stiffness.fe.model.FESettings` (mesh size resolves the Hertz
   patch, element sizes) and :func:`geardyn.stiffness.fe.mesh.crack_segment` (the crack stays in
   the tooth and the rim);
4. the load laws (the steady speed and the calibration of the output law of
   :mod:`geardyn.dynamics.model`);
5. the bounded-work check of the simulation (step count and record size,
   :func:`geardyn.dynamics.newmark.check_bounded_work`).

What needs the stiffness map (the time-step limit from the largest mesh stiffness, the static
operating point) is checked by ``simulate`` itself.
"""

from __future__ import annotations

__all__ = ["check_case"]


def _relabel(exc, field: str):
    """The same error on a case field (keeps GeometryError vs InputError)."""
    return type(exc)(field, exc.value, exc.allowed)


def check_case(case) -> None:
    """Run every check of ``case`` that needs no simulation; return None if all pass.

    Parameters
    ----------
    case : geardyn.config.Case

    Raises
    ------
    geardyn.errors.InputError
        (or its subclass GeometryError) naming the case field (``crack.depth``,
        ``stiffness.fe.mesh_size``, ``stiffness.centre_distance_max``, ...), the value and what is
        allowed.
    """
    from .errors import GeometryError, InputError
    from .stiffness import centre_distance_grid

    pair = case.gear_pair()
    dd = centre_distance_grid(case)
    ends = (("stiffness.centre_distance_min", float(dd[0])),
            ("stiffness.centre_distance_max", float(dd[-1])))
    for field, d in ends:
        try:
            pair.operating(d)
        except GeometryError as exc:
            raise _relabel(exc, field) from None

    crack = case.crack if (case.crack is not None and case.crack.active) else None
    if crack is not None:
        z = pair.pinion.teeth if crack.gear == "pinion" else pair.gear.teeth
        if crack.tooth >= z:
            raise InputError("crack.tooth", crack.tooth,
                             f"a tooth number in [0, {z - 1}] of the {crack.gear}")
    if case.stiffness.method == "pem":
        _check_pem(case, dd, ends)
    else:
        _check_fe(case, pair, crack)

    _check_loads(case, pair)
    from .dynamics.newmark import check_bounded_work

    check_bounded_work(case)


def _check_pem(case, dd, ends) -> None:
    from .errors import GeometryError
    from .stiffness.pem import PEMModel

    pem = PEMModel.from_case(case, cracked=True)  # builds the cracked section: crack geometry
    try:
        pem.check_range(dd)
    except GeometryError as exc:
        field = ends[0][0] if exc.value is not None and float(exc.value) <= ends[0][1] \
            else ends[1][0]
        raise _relabel(exc, field) from None


def _check_fe(case, pair, crack) -> None:
    from .stiffness.fe.mesh import CrackGeometry, crack_segment
    from .stiffness.fe.model import FESettings

    settings = FESettings.from_case(case)
    settings.check()
    settings.mesh_settings()  # element sizes in order
    if crack is not None:
        gear = pair.pinion if crack.gear == "pinion" else pair.gear
        crack_segment(gear, CrackGeometry(depth=float(crack.depth), angle=float(crack.angle)))


def _check_loads(case, pair) -> None:
    from .dynamics import model as dm

    law_in = dm._input_law(case)
    dm._output_law_and_speed(case, law_in, pair.pinion.base_radius, pair.gear.base_radius,
                             case.pinion.torsional_damping, case.gear.torsional_damping)
