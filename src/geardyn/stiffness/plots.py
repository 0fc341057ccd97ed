"""Figures of stiffness maps: analogues of Xue & Howard (2018) Figs. 5 and 6.

Every function takes :class:`~geardyn.stiffness.map.StiffnessMap` objects, whatever method made
them (PEM, FE, a user's table). The ``fig_*`` functions return a
:class:`matplotlib.figure.Figure` without touching pyplot's global state; each is
:func:`geardyn.line_figure.draw_line_figure` of its ``*_curves`` function, which evaluates the
maps and returns the curves as plain arrays and text (what ``geardyn run`` hands its figure
process, which then draws without the map code).

Labels follow the paper: ``K00``, ``K05``, ``K10`` for the centre distance changes 0, 0.5 and
1.0 mm (Fig. 5a), ``L00``... for the load sharing ratios (Fig. 5b), and ``KC005`` / ``KC105`` for
the cracked pair at 0 and 1 mm with a 5 mm crack (Fig. 6).
"""

from __future__ import annotations

import json
import math
from collections.abc import Sequence

import numpy as np
from matplotlib.figure import Figure

from ..errors import InputError
from ..line_figure import draw_line_figure
from .map import StiffnessMap

__all__ = ["pair_load_share", "crack_angle", "fig_stiffness", "fig_load_sharing", "fig_crack",
           "dd_label", "stiffness_curves", "load_sharing_curves", "crack_curves"]

DEFAULT_DD = (0.0, 0.5e-3, 1.0e-3)

#: Axis labels of the figures against the pinion angle.
_THETA_LABEL = r"pinion rolling angle $\theta$ [deg]"
_KT_LABEL = r"combined torsional mesh stiffness $K_t$ [N m/rad]"


def dd_label(prefix: str, dd: float) -> str:
    """The paper's curve label: ``K`` + tenths of a millimetre, e.g. ``K05`` for 0.5 mm."""
    return f"{prefix}{round(dd * 1e4):02d}"


def _covered(m: StiffnessMap, dds: Sequence[float]) -> list[float]:
    out = [float(d) for d in dds if m.covers(float(d))]
    if not out:
        raise InputError("dds", list(dds), f"centre distance changes inside the map's range "
                                           f"[{m.dd[0]:.4g}, {m.dd[-1]:.4g}] m")
    return out


def pair_load_share(m: StiffnessMap, theta, dd: float, pinion_tooth: int) -> np.ndarray:
    """Load sharing ratio of the pair holding ``pinion_tooth`` at pinion angles ``theta`` [-].

    Zero where that tooth is out of mesh. Needs a map with ``load_share`` and ``slot_tooth``.

    Parameters
    ----------
    m : StiffnessMap
    theta : array_like
        Pinion angles [rad].
    dd : float
        Centre distance change [m].
    pinion_tooth : int
        Pinion tooth number.
    """
    if "load_share" not in m.extra or m.slot_tooth is None:
        raise InputError("map", m.attrs.get("method", "?"), "a map with load sharing ratios")
    theta = np.atleast_1d(np.asarray(theta, float))
    a = float(np.interp(dd, m.dd, m.phase_a)) if m.dd.size > 1 else float(m.phase_a[0])
    r = np.mod(theta - a, m.period)
    c = np.minimum((r // m.mesh_angle).astype(np.int64), m.n_cycles - 1)
    out = np.zeros(theta.shape)
    for k in range(m.slot_tooth.shape[1]):
        sel = m.slot_tooth[c, k] == pinion_tooth
        if np.any(sel):
            out[sel] = m(theta[sel], dd, variable="load_share", slot=k)
    if "load_share_exiting" in m.extra:  # FE: extended contact of the previous cycle's slot 0
        sel = m.slot_tooth[(c - 1) % m.n_cycles, 0] == pinion_tooth
        if np.any(sel):
            out[sel] += m(theta[sel], dd, variable="load_share_exiting")
    return out


def crack_angle(healthy: StiffnessMap, cracked: StiffnessMap, dd: float = 0.0,
                n: int = 4096) -> float:
    """Pinion angle where the cracked map falls furthest below the healthy one [rad]."""
    return fault_dip(healthy, cracked, dd, n)[0]


def fault_dip(healthy: StiffnessMap, faulty: StiffnessMap, dd: float = 0.0,
              n: int = 4096) -> tuple[float, float]:
    """Where the faulty map falls furthest below the healthy one, relative to it: the pinion
    angle [rad] (``n`` points over the faulty map's period, centre distance change ``dd`` [m])
    and the ratio ``faulty / healthy`` there [-] (1 where the fault leaves the map
    unchanged)."""
    th = np.linspace(0.0, faulty.period, n, endpoint=False)
    ratio = faulty(th, dd) / healthy(th, dd)
    k = int(np.argmin(ratio))
    return float(th[k]), float(ratio[k])


def _parameters(m: StiffnessMap) -> dict:
    """The map's ``parameters`` attribute as a dict (stored as JSON text), or {}."""
    p = m.attrs.get("parameters")
    if isinstance(p, str):
        try:
            p = json.loads(p)
        except ValueError:
            return {}
    return p if isinstance(p, dict) else {}


def _crack_depth(m: StiffnessMap) -> float | None:
    try:
        return float(_parameters(m)["crack"]["depth_m"])
    except (TypeError, KeyError, ValueError):
        return None


def stiffness_curves(m: StiffnessMap, dds: Sequence[float] = DEFAULT_DD, *,
                     theta_range: tuple[float, float] | None = None, n: int = 2000) -> dict:
    """The curves of :func:`fig_stiffness` as a plain specification
    (:mod:`geardyn.line_figure`): ``K_t`` [N m/rad] against the pinion angle [deg]."""
    tm = m.mesh_angle
    lo, hi = theta_range or (-tm, 2 * tm)
    th = np.linspace(lo, hi, n)
    lines = [{"y": m.torsional(th, d),
              "label": f"{dd_label('K', d)} ($\\Delta d$ = {d * 1e3:g} mm)"}
             for d in _covered(m, dds)]
    return {"x": np.degrees(th), "lines": lines,
            "xlabel": _THETA_LABEL, "ylabel": _KT_LABEL,
            "title": f"Mesh stiffness for several centre distances "
                     f"({m.attrs.get('method', '?')})",
            "legend_columns": 3, "figsize": (7.5, 4.8)}


def fig_stiffness(m: StiffnessMap, dds: Sequence[float] = DEFAULT_DD, *,
                  theta_range: tuple[float, float] | None = None, n: int = 2000) -> Figure:
    """Fig. 5a analogue: combined torsional mesh stiffness against pinion angle for several
    centre distance changes.

    Parameters
    ----------
    m : StiffnessMap
    dds : sequence of float
        Centre distance changes [m] (default 0, 0.5, 1.0 mm: K00, K05, K10).
    theta_range : (float, float), optional
        Pinion angles shown [rad]; default three mesh cycles from ``-Theta_m``.
    n : int
        Points per curve.
    """
    return draw_line_figure(stiffness_curves(m, dds, theta_range=theta_range, n=n))


def load_sharing_curves(m: StiffnessMap, dds: Sequence[float] = DEFAULT_DD, *,
                        pinion_tooth: int = 0, n: int = 2000) -> dict:
    """The curves of :func:`fig_load_sharing` as a plain specification
    (:mod:`geardyn.line_figure`): the load sharing ratio [-] against the pinion angle [deg]."""
    tm = m.mesh_angle
    t0 = pinion_tooth * tm
    th = np.linspace(t0 - 1.5 * tm, t0 + 1.5 * tm, n)
    lines = [{"y": pair_load_share(m, th, d, pinion_tooth),
              "label": f"{dd_label('L', d)} ($\\Delta d$ = {d * 1e3:g} mm)"}
             for d in _covered(m, dds)]
    return {"x": np.degrees(th), "lines": lines,
            "xlabel": _THETA_LABEL,
            "ylabel": f"load sharing ratio of pinion tooth {pinion_tooth}'s pair [-]",
            "ylim": (-0.05, 1.05), "title": "Load sharing ratio through one engagement",
            "legend_columns": 3, "figsize": (7.5, 4.8)}


def fig_load_sharing(m: StiffnessMap, dds: Sequence[float] = DEFAULT_DD, *,
                     pinion_tooth: int = 0, n: int = 2000) -> Figure:
    """Fig. 5b analogue: load sharing ratio of one tooth pair through its engagement.

    Parameters
    ----------
    m : StiffnessMap
        A map with ``load_share`` (PEM or FE).
    dds : sequence of float
        Centre distance changes [m] (L00, L05, L10).
    pinion_tooth : int
        The pinion tooth whose pair is followed; the angle axis is centred on the moment it
        passes the design pitch point.
    n : int
        Points per curve.
    """
    return draw_line_figure(load_sharing_curves(m, dds, pinion_tooth=pinion_tooth, n=n))


def _on_gear(m: StiffnessMap) -> bool:
    """Whether the map's crack or faults are all on the gear (its ``parameters`` attribute)."""
    p = _parameters(m)
    gears = [f.get("gear") for f in p.get("faults") or [] if isinstance(f, dict)]
    if isinstance(p.get("crack"), dict):
        gears.append(p["crack"].get("gear"))
    return bool(gears) and all(g == "gear" for g in gears)


def crack_curves(healthy: StiffnessMap, cracked: StiffnessMap,
                 dds: Sequence[float] = (0.0, 1.0e-3), *, theta_center: float | None = None,
                 n: int = 2000, faulty: str = "cracked") -> dict:
    """The curves of :func:`fig_crack` as a plain specification (:mod:`geardyn.line_figure`):
    ``K_t`` [N m/rad] of the healthy and the faulty pair against the pinion angle [deg]."""
    tm = healthy.mesh_angle
    dds = _covered(cracked, dds)
    if theta_center is None:
        theta_center = crack_angle(healthy, cracked, dds[0])
    # show the cycles of the cracked tooth's engagement and one cycle either side
    th = np.linspace(theta_center - 2 * tm, theta_center + 2 * tm, n)
    depth = _crack_depth(cracked)
    dlab = f"{round(depth * 1e3):02d}" if depth is not None else ""
    lines = [{"y": healthy.torsional(th, 0.0), "color": "0.3",
              "label": "K00 (healthy, " r"$\Delta d$ = 0 mm)"}]
    for d in dds:
        name = f"KC{round(d * 1e3)}{dlab}" if math.isclose(d * 1e3, round(d * 1e3),
                                                            abs_tol=1e-9) else "KC"
        extra = f", {depth * 1e3:g} mm crack" if depth is not None else ""
        lines.append({"y": cracked.torsional(th, d),
                      "label": f"{name} ({faulty}, $\\Delta d$ = {d * 1e3:g} mm{extra})"})
    where = ", fault on the gear" if _on_gear(cracked) else ""
    return {"x": np.degrees(th), "lines": lines,
            "xlabel": _THETA_LABEL, "ylabel": _KT_LABEL,
            "title": f"Healthy and {faulty} mesh stiffness ({cracked.attrs.get('method', '?')}"
                     f"{where})",
            "legend_columns": 2, "figsize": (7.5, 4.8)}


def fig_crack(healthy: StiffnessMap, cracked: StiffnessMap,
              dds: Sequence[float] = (0.0, 1.0e-3), *, theta_center: float | None = None,
              n: int = 2000, faulty: str = "cracked") -> Figure:
    """Fig. 6 analogue: healthy ``K00`` against the cracked pair at two centre distances.

    Parameters
    ----------
    healthy, cracked : StiffnessMap
    dds : sequence of float
        Centre distance changes of the cracked curves [m] (KC005 at 0, KC105 at 1 mm).
    theta_center : float, optional
        Pinion angle to centre on [rad]; default where the crack lowers the stiffness most
        (:func:`crack_angle`).
    n : int
        Points per curve.
    faulty : str
        The legend's and title's word for the faulty pair: "cracked", or "faulty" where the
        map holds other faults besides (or instead of) the crack.
    """
    return draw_line_figure(crack_curves(healthy, cracked, dds, theta_center=theta_center, n=n,
                                         faulty=faulty))
