"""The signals a sweep can diagnose (``[store] signals``) and the checks of a sweep that need
no run: the signals its model records, and a record long enough for the synchronous average.

:data:`RECORD_SIGNALS` is the unit of every time series of a simulation record, as the record
itself states it (the ``units`` attribute of each variable of
:func:`geardyn.dynamics.simulate`'s Dataset; ``tests/sweep/test_store_units.py`` simulates the
6-DOF and the transverse models and checks this table against them, both ways).
"""

from __future__ import annotations

import math
from collections.abc import Iterable
from typing import Any

from ...errors import DataFileError, InputError

__all__ = ["RECORD_SIGNALS", "TRANSVERSE_SIGNALS", "check_signal_names", "check_sweep_signals",
           "check_record_length", "check_demodulation_band", "short_record_error"]

#: Every time series of a simulation record -> its unit (the record's ``units`` attribute).
RECORD_SIGNALS: dict[str, str] = {
    # the six degrees of freedom and their velocities (geardyn.dynamics.newmark._VARS)
    "theta_m": "rad", "y_p": "m", "theta_p": "rad", "y_g": "m", "theta_g": "rad",
    "theta_out": "rad",
    "omega_m": "rad/s", "v_yp": "m/s", "omega_p": "rad/s", "v_yg": "m/s", "omega_g": "rad/s",
    "omega_out": "rad/s",
    # mesh and operating quantities
    "transmission_error": "rad", "mesh_deflection": "m", "mesh_force": "N",
    "centre_distance_change": "m", "pressure_angle": "rad", "contact_ratio": "1",
    "contact_ratio_eq8": "1", "mesh_stiffness": "N/m", "contact": "1", "iterations": "1",
    "residual_before": "m", "residual_after": "m",
    "mesh_error": "m",  # with tooth errors, relief or runout ([modifications])
    # the transverse model (simulation.dynamics = "transverse")
    "x_p": "m", "x_g": "m", "v_xp": "m/s", "v_xg": "m/s", "line_of_action_angle": "rad",
    "friction_force": "N", "friction_torque_pinion": "N m", "friction_torque_gear": "N m",
    "friction_power": "W",
}

#: Signals only the transverse model records.
TRANSVERSE_SIGNALS = frozenset({"x_p", "x_g", "v_xp", "v_xg", "line_of_action_angle",
                                "friction_force", "friction_torque_pinion",
                                "friction_torque_gear", "friction_power"})

#: Case keys that make the steady pinion speed something other than ``load.speed``.
_SPEED_KEYS = ("load.law", "load.coefficient", "motor.profile_times", "motor.profile_speeds")


def _get(case, key: str) -> Any:
    obj = case
    for p in key.split("."):
        obj = obj[int(p)] if p.isdigit() else getattr(obj, p)
    return obj


def _values_of(sweep, key: str) -> list[tuple[Any, str]]:
    """The values a case key takes in the sweep, each with where the sweep file sets it (the
    bounds of a sampled dimension; the source's values for a linked key)."""
    src = sweep.links.get(key, key)
    via = f"link.{key}" if key in sweep.links else None
    for a in sweep.axes:
        if a.key == src:
            return [(v, via or f"axes.{key}[{i}]") for i, v in enumerate(a.values)]
    for d in sweep.dimensions:
        if d.key == src:
            return [(d.low, via or f"sample.dimensions.{key}.low"),
                    (d.high, via or f"sample.dimensions.{key}.high")]
    base = sweep.base_case
    if base.provenance.get(key) == "--set":  # geardyn sweep --set (cli.sweep.with_base_case)
        where = f"--set {key}"
    else:
        where = f"set.{key}" if key in sweep.spec.set else key
    return [(_get(base, key), where)]


def _swept(sweep) -> set[str]:
    return {a.key for a in sweep.axes} | {d.key for d in sweep.dimensions} | set(sweep.links)


def check_signal_names(signals: Iterable[str]) -> None:
    """Refuse ``[store] signals`` that no simulation record has (InputError naming them)."""
    import difflib

    bad = [s for s in signals if s not in RECORD_SIGNALS]
    if not bad:
        return
    close = difflib.get_close_matches(bad[0], list(RECORD_SIGNALS), n=1)
    hint = f" (did you mean {close[0]!r}?)" if close else ""
    raise InputError("store.signals", bad,
                     f"signals of the simulation record{hint}, e.g. v_yg, omega_p, "
                     "transmission_error, mesh_force, centre_distance_change, y_p, theta_g; "
                     "transverse model: x_p, v_xp, friction_force (all: "
                     "geardyn.studies.sweep.RECORD_SIGNALS)")


def check_sweep_signals(sweep, signals: Iterable[str]) -> None:
    """Refuse signals that no run of the sweep records: names of no record, and
    transverse-model signals when every run has ``simulation.dynamics = '6-dof'``."""
    signals = list(signals)
    check_signal_names(signals)
    dynamics = {v for v, _ in _values_of(sweep, "simulation.dynamics")}
    if "transverse" in dynamics:
        return
    bad = [s for s in signals if s in TRANSVERSE_SIGNALS]
    if bad:
        raise InputError("store.signals", bad, "signals the 6-DOF model records (every run "
                                               "has simulation.dynamics = '6-dof'; "
                                               f"{', '.join(bad)}: the transverse model, "
                                               "simulation.dynamics = 'transverse')")


def check_record_length(sweep) -> None:
    """Refuse a ``simulation.record_time`` shorter than one pinion revolution at the case's
    speed (``load.speed``) in some run: those runs have no whole revolution to average.

    Checked when the steady speed is ``load.speed`` for every run (a calibrated load law, no
    motor speed profile); the record time and the speed may be swept (their smallest values
    are checked together). Runs between one and two revolutions may or may not hold a whole
    revolution (it depends on the phase): they are left to run, and those that prove too short
    fail with :func:`short_record_error`.
    """
    base = sweep.base_case
    if set(_SPEED_KEYS) & _swept(sweep):
        return
    if (base.load.law == "table" or base.load.coefficient is not None
            or base.motor.profile_times is not None):
        return
    speeds = _values_of(sweep, "load.speed")
    if any(w is None for w, _ in speeds):
        return
    records = _values_of(sweep, "simulation.record_time")
    t_min, where = min(records, key=lambda r: float(r[0]))
    w_min = min(float(w) for w, _ in speeds)
    per_rev = 2.0 * math.pi / w_min
    revs = float(t_min) / per_rev
    if revs >= 1.0:
        return
    lowest = " (the lowest in the sweep)" if len(speeds) > 1 else ""
    raise InputError(where, f"{float(t_min):.6g} s",
                     f"at least {2.0 * per_rev:.3g} s: 2 revolutions of the pinion at load.speed "
                     f"= {w_min:.6g} rad/s{lowest} (this record spans {revs:.3g} revolutions; "
                     "the synchronous average needs one whole revolution)")


_BAND_KEYS = ("pinion.teeth", "diagnostics.harmonic", "diagnostics.bandwidth",
              "diagnostics.samples_per_rev")


def check_demodulation_band(sweep) -> None:
    """Refuse a ``[diagnostics]`` demodulation band that no run can use
    (:func:`geardyn.diagnostics.demodulation.band_limits`: inside the orders of
    ``samples_per_rev``, narrower than the tooth count), when none of its keys is swept."""
    import warnings

    from ...diagnostics.demodulation import band_limits

    if set(_BAND_KEYS) & _swept(sweep):
        return  # per run: the runs that fail say why
    case = sweep.base_case
    d = case.diagnostics
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")  # a shared band is a run's warning, not an error
        try:
            band_limits(case.pinion.teeth, d.harmonic, d.bandwidth, d.samples_per_rev)
        except InputError as exc:
            (_, where), = _values_of(sweep, f"diagnostics.{exc.field}") \
                if exc.field in ("bandwidth", "harmonic") else [(None, exc.field)]
            raise InputError(where, exc.value,
                             f"{exc.allowed} (pinion.teeth = {case.pinion.teeth}, "
                             f"diagnostics.harmonic = {d.harmonic}, diagnostics.samples_per_rev "
                             f"= {d.samples_per_rev})") from None


def short_record_error(exc, ds, case) -> DataFileError:
    """A :class:`~geardyn.diagnostics.ShortRecordError` of a run in the sweep's terms:
    ``simulation.record_time``, its value and the shortest record that works (the message
    ``geardyn diagnose`` gives for a short simulation file, from the same function)."""
    import numpy as np

    from ...diagnostics.loading import Measurement
    from ...diagnostics.pipeline import _short_record

    t = np.asarray(ds["time"].values, dtype=np.float64)
    m = Measurement(signals={"theta_p": np.asarray(ds["theta_p"].values)}, time=t)
    where = f"simulation.record_time = {float(case.simulation.record_time):.6g} s"
    return _short_record(where, m, exc, simulation=True)
