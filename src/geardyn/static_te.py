r"""Loaded and unloaded static transmission error of a gear pair (what a single-flank tester
measures), with or without tooth errors and relief.

At pinion angle ``theta`` every pair ``j`` in contact has the stiffness ``k_j = s_j k_mb`` (the
stiffness map's load share ``s_j``, scaled so that the shares of the pairs in contact sum to 1 as
in the dynamics, and mesh stiffness, at the contact pattern's angle) and the
geometric error ``e_j`` (:mod:`geardyn.modifications`). With the gear held and the pinion loaded by
the torque ``T`` (mesh force ``N = T / r_b1``), the static transmission error along the line of
action is the mesh approach ``delta`` that solves

.. math:: \sum_j k_j \max(\delta - e_j, 0) = N,

piecewise linear in ``delta`` and solved exactly by adding pairs in the order of their ``e_j``
(a pair whose error exceeds ``delta`` does not touch: relief moves where contact starts under
load). Unloaded (``T = 0``) this gives ``delta = min_j e_j``, the kinematic transmission error of
the geometry. The angular transmission error is ``delta / r_b1`` of pinion rotation (gear fixed),
i.e. ``theta_p - (r_b2/r_b1) theta_g`` on a rigid tester.

The bearings and the centre distance are held fixed (a rigid single-flank tester); choose
``centre_distance_change`` to evaluate at another centre distance.
"""

from __future__ import annotations

import math
import numbers

import numpy as np

from .errors import InputError
from .modifications import ToothModifications
from .units import to_si

__all__ = ["static_transmission_error", "solve_approach", "static_te_of_case",
           "static_te_curves", "fig_static_te"]


def _quantity(value, dimension: str, field: str) -> float:
    """A number (SI) or a quantity string such as ``"100 N m"`` (as in case files,
    :func:`geardyn.units.to_si`) as an SI float; anything else raises :class:`InputError`
    naming ``field``. Range checks are the caller's."""
    if isinstance(value, str):
        return to_si(value, dimension, field)
    if isinstance(value, bool) or not isinstance(value, numbers.Real):
        example = {"torque": "100.0 or '100 N m'", "length": "0.001 or '1 mm'"}[dimension]
        raise InputError(field, value, f"a {dimension}: a number in SI units or a string with "
                                       f"a unit, e.g. {example}")
    return float(value)


def _check_case(case) -> None:
    from .config import Case

    if not isinstance(case, Case):
        raise InputError("case", case, "a geardyn.config.Case (geardyn.load_case(path) or "
                                       "geardyn.paper_case())")


def solve_approach(k: np.ndarray, e: np.ndarray, force: float) -> tuple[float, int]:
    """Approach ``delta`` [m] with ``sum k_j max(delta - e_j, 0) = force`` and the number of
    loaded pairs (``k`` [N/m], ``e`` [m] of the pairs in contact; ``force >= 0`` [N]).

    With ``force = 0``: ``min e`` and the pairs at that error.
    """
    order = np.argsort(e, kind="stable")
    k, e = np.asarray(k, float)[order], np.asarray(e, float)[order]
    kk = ke = 0.0
    n = e.size
    for m in range(n):
        kk += k[m]
        ke += k[m] * e[m]
        if kk <= 0.0:
            continue
        delta = (force + ke) / kk
        if m == n - 1 or delta <= e[m + 1]:
            return float(delta), m + 1
    return float(e[0]) if n else math.nan, 0


def _normalised(s: np.ndarray) -> np.ndarray:
    """Shares of the pairs in contact scaled to sum to 1 (equal shares if they sum to 0).

    An FE map gives part of the load to a pair in extended contact past the end of the path
    (``load_share_exiting``), which has no slot; the dynamics weight the slot pairs by
    ``s_j / sum s`` (:mod:`geardyn.modifications`, ``f = sum_active s_j / sum s``), so that with
    every pair loaded the mesh stiffness is ``k_mb``; the static TE does the same. PEM maps'
    shares already sum to 1."""
    tot = float(np.sum(s))
    if not tot > 0.0:
        return np.full(s.shape, 1.0 / max(s.size, 1))
    return s / tot


def static_transmission_error(stiffness_map, torque: float, *,
                              modifications: ToothModifications,
                              theta=None, centre_distance_change: float = 0.0, n: int = 2048):
    r"""Static transmission error over pinion angles, as an :class:`xarray.Dataset`.

    Parameters
    ----------
    stiffness_map : StiffnessMap
        ``k_mb`` and (if present) ``load_share`` of the pair (equal shares otherwise).
    torque : float or str
        Pinion torque [N m], ``>= 0`` (0: unloaded TE); a number, or a string with a unit
        as in a case file (``"100 N m"``).
    modifications : ToothModifications
        Errors and relief (``ToothModifications.none(pair)`` for perfect involutes).
    theta : array_like, optional
        Pinion angles [rad]; default ``n`` points over one hunting period.
    centre_distance_change : float or str
        ``d' - d`` [m] (must lie in the map's range); a number, or a string with a unit
        (``"0.5 mm"``).
    n : int
        Points of the default grid.

    Returns
    -------
    xarray.Dataset
        ``transmission_error`` along the LOA [um], ``transmission_error_angle`` (pinion, gear
        held) [rad], ``loaded_pairs`` [-], ``mesh_stiffness`` the map's ``k_mb`` at the pattern's
        angle [N/m]; coordinate ``theta`` [rad].

    Raises
    ------
    InputError
        Negative or non-finite torque, a centre distance outside the map.
    """
    import xarray as xr

    torque_in = torque
    torque = _quantity(torque, "torque", "torque")
    if not (math.isfinite(torque) and torque >= 0):
        raise InputError("torque", torque_in, "a finite pinion torque >= 0 [N m]")
    if not (callable(stiffness_map) and hasattr(stiffness_map, "covers")):  # duck maps allowed
        raise InputError("stiffness_map", stiffness_map,
                         "a geardyn.stiffness.StiffnessMap (e.g. geardyn.stiffness.build_map(case))")
    if not hasattr(modifications, "pair_errors"):
        raise InputError("modifications", modifications, "a geardyn.modifications."
                         "ToothModifications (ToothModifications.none(pair) for perfect involutes)")
    centre_distance_change = _quantity(centre_distance_change, "length", "centre_distance_change")
    if not (math.isfinite(centre_distance_change)
            and stiffness_map.covers(centre_distance_change)):
        raise InputError("centre_distance_change", centre_distance_change,
                         f"a value in the map's range [{stiffness_map.dd[0]:.6g}, "
                         f"{stiffness_map.dd[-1]:.6g}] m (the case's "
                         f"stiffness.centre_distance_min and _max)")
    mods = modifications
    pair = mods.pair
    rb1 = pair.pinion.base_radius
    if theta is None:
        if isinstance(n, bool) or not isinstance(n, int | np.integer) or n < 1:
            raise InputError("n", n, "a whole number of points >= 1")
        theta = np.arange(n) * mods.hunting_period / n
    th = np.atleast_1d(np.asarray(theta, float))
    dd = float(centre_distance_change)
    pe = mods.pair_errors(th, dd)
    kmb = np.asarray(stiffness_map(pe["theta_eff"], np.full(th.shape, dd)), float)
    shares = mods.shares(stiffness_map, pe["theta_eff"], dd, pe["in_contact"])
    force = torque / rb1
    te = np.empty(th.shape)
    loaded = np.empty(th.shape, dtype=np.int64)
    for i in range(th.size):
        m = pe["in_contact"][i]
        te[i], loaded[i] = solve_approach(_normalised(shares[i, m]) * kmb[i], pe["e"][i, m],
                                          force)
    ds = xr.Dataset(
        {"transmission_error": ("theta", te * 1e6, {
            "units": "um", "long_name": "static transmission error along the line of action "
                                        "(mesh approach, gear held)"}),
         "transmission_error_angle": ("theta", te / rb1, {
             "units": "rad", "long_name": "static transmission error as pinion rotation "
                                         "(gear held), delta / r_b1"}),
         "loaded_pairs": ("theta", loaded, {"units": "1", "long_name": "tooth pairs carrying "
                                                                       "load"}),
         "mesh_stiffness": ("theta", kmb, {"units": "N/m", "long_name": "k_mb of the map at the "
                                                                       "contact pattern's angle"})},
        coords={"theta": ("theta", th, {"units": "rad", "long_name": "pinion angle"})},
        attrs={"torque": float(torque), "torque_units": "N m", "mesh_force": float(force),
               "mesh_force_units": "N", "centre_distance_change": dd,
               "centre_distance_change_units": "m", "tooth_errors": mods.describe(),
               "title": "static transmission error (rigid single-flank tester)"})
    return ds


def static_te_of_case(case, torque: float | None = None, *, cracked: bool = False,
                      errors: bool = True, stiffness_map=None, theta=None,
                      centre_distance_change: float = 0.0, n: int = 2048):
    """:func:`static_transmission_error` of a case: its map (healthy by default, unlike
    :func:`geardyn.stiffness.build_map` and :func:`geardyn.simulate`, whose ``cracked``
    defaults to True), its ``[modifications]`` (``errors=False``: perfect involutes) and
    ``torque`` (default: the motor torque) [N m]. ``cracked`` and ``errors`` are booleans;
    ``theta``, ``centre_distance_change`` and ``n`` as for :func:`static_transmission_error`
    (named here, so that a misspelt argument is refused before a map is built, by this
    function's name).

    ``torque`` and ``centre_distance_change`` may be a number in SI units or a string with a
    unit as in a case file (``"100 N m"``, ``"0.5 mm"``), like the case's own values; anything
    else raises :class:`geardyn.errors.InputError` naming the argument.
    """
    _check_case(case)
    from .errors import check_flag

    cracked = check_flag(cracked, "cracked")
    errors = check_flag(errors, "errors")  # "no" was taken as True (a user audit)
    if torque is not None:  # refused by name before a map is built
        torque = _quantity(torque, "torque", "torque")
    centre_distance_change = _quantity(centre_distance_change, "length",
                                       "centre_distance_change")
    if stiffness_map is None:
        from .stiffness import build_map

        stiffness_map = build_map(case, cracked=cracked)
    mods = ToothModifications.from_case(case) if errors else \
        ToothModifications.none(case.gear_pair())
    t = case.motor.torque if torque is None else torque
    return static_transmission_error(stiffness_map, t, modifications=mods, theta=theta,
                                     centre_distance_change=centre_distance_change, n=n)


def static_te_curves(case, torque: float | None = None, *, cracked: bool = False,
                     errors: bool = True, stiffness_map=None,
                     centre_distance_change: float = 0.0, n: int = 2048):
    """Unloaded and loaded static transmission error of a case in one Dataset.

    :func:`static_te_of_case` at ``0`` and at ``torque`` (default the motor torque) [N m]
    (``0`` alone when ``torque`` is 0),
    stacked along a ``torque`` coordinate [N m], with the case's provenance in the attributes
    (what ``geardyn static-te`` writes). ``torque`` and ``centre_distance_change`` take numbers
    in SI units or strings with a unit, as :func:`static_te_of_case`.

    Returns
    -------
    xarray.Dataset
        The variables of :func:`static_transmission_error` over ``(torque, theta)``.
    """
    import xarray as xr

    from ._version import __version__
    from .config import case_to_toml

    _check_case(case)
    from .errors import check_flag

    cracked = check_flag(cracked, "cracked")
    errors = check_flag(errors, "errors")
    if torque is not None:
        torque = _quantity(torque, "torque", "torque")
    centre_distance_change = _quantity(centre_distance_change, "length", "centre_distance_change")
    if stiffness_map is None:
        from .stiffness import build_map

        stiffness_map = build_map(case, cracked=cracked)
    t = float(case.motor.torque if torque is None else torque)
    torques = [0.0, t] if t != 0.0 else [0.0]  # an unloaded request is the one curve
    parts = [static_te_of_case(case, tq, cracked=cracked, errors=errors,
                               stiffness_map=stiffness_map,
                               centre_distance_change=centre_distance_change, n=n)
             for tq in torques]
    ds = xr.concat(parts, dim="torque", data_vars="all", coords="minimal",
                   combine_attrs="drop_conflicts")
    ds = ds.assign_coords(torque=("torque", torques, {"units": "N m",
                                                       "long_name": "pinion torque"}))
    ds.attrs.update({
        "title": "static transmission error, unloaded and loaded (rigid single-flank tester)",
        "case": case.name, "case_toml": case_to_toml(case),
        "stiffness_method": str(stiffness_map.attrs.get("method", case.stiffness.method)),
        "stiffness_cracked": int(bool(cracked)),
        # 1 where the curves hold tooth errors: asked for (errors) and the case has some (the
        # healthy default said 1 while the case had none, a user audit of 2026-11-27)
        "tooth_errors_included": int(bool(errors)
                                     and ToothModifications.from_case(case).active),
        "geardyn_version": __version__})
    for k in ("torque", "torque_units", "mesh_force", "mesh_force_units"):
        ds.attrs.pop(k, None)
    return ds


def fig_static_te(ds):
    """Figure of :func:`static_te_curves`: the transmission error along the line of action
    [um] against the pinion angle [deg], one line per torque.

    Returns
    -------
    matplotlib.figure.Figure
    """
    from matplotlib.figure import Figure

    fig = Figure(figsize=(9.0, 4.2), layout="constrained")
    ax = fig.subplots()
    deg = np.degrees(ds["theta"].values)
    for i, tq in enumerate(ds["torque"].values):
        te = ds["transmission_error"].values[i]
        ax.plot(deg, te, lw=0.9, label=f"{'unloaded' if tq == 0 else 'loaded'}, "
                                       f"T = {tq:g} N m (p-p {np.ptp(te):.3g} um)")
    ax.set_xlabel("pinion angle [deg]")
    ax.set_ylabel("static TE along the line of action [um]")
    ax.set_title(f"{ds.attrs.get('case', '')}: static transmission error "
                 f"({ds.attrs.get('stiffness_method', '')} map, "
                 f"{'with' if ds.attrs.get('tooth_errors_included') else 'without'} tooth "
                 "errors)", fontsize=9)
    ax.grid(alpha=0.3)
    ax.legend(fontsize=8)
    return fig
