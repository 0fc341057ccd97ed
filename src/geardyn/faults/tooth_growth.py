r"""Root crack growth on a gear tooth: the crack path, ``K`` along it, Paris cycles and the
tooth compliance per crack length (the prognostics indicator versus cycles).

Model (plane, LEFM, quasi-static, one load position)
----------------------------------------------------
* Body: a sector of the gear with ``teeth`` teeth centred on the cracked tooth 0 (body frame
  of :mod:`geardyn.stiffness.fe.mesh`: tooth 0 on ``+y``, loaded flank on ``x < 0``), from the
  rack-generated outline (:meth:`geardyn.geometry.Gear.outline`, polygons through
  ``n_points`` points per involute and per fillet) down to the bore radius; clamped on the bore
  arc and on the two radial cuts (a modelling choice: the neighbouring body is taken as rigid
  there; the cuts are one tooth away from the cracked tooth).
* Load: a force per unit face width ``load`` [N/m] along the line of action (the inward
  involute normal, :func:`geardyn.stiffness.fe.solve.flank_points`) at roll length
  ``load_roll`` on tooth 0's loaded flank, spread uniformly over ``+-patch`` [m] of flank.
  :func:`hpstc_roll` gives the highest point of single tooth contact of a pair, where a single
  tooth carries the whole load furthest from its root (the usual worst position for root
  bending).
* Crack: starts as the straight root crack of :class:`geardyn.stiffness.fe.mesh.CrackGeometry`
  (mouth at the 30 deg tangent point of the loaded fillet). At each step
  :func:`geardyn.stiffness.fe.sif.interaction_integral` gives ``K_I``, ``K_II`` at the tip, the
  maximum tangential stress criterion (:func:`geardyn.faults.growth.mts_angle`) the kink angle,
  and the crack is extended by ``step`` [m] in that direction and the body remeshed (gmsh).
  Growth stops after ``n_steps``, when ``K_I <= 0`` or when the next tip would come within
  ``step`` of the outline (the tooth is about to break off, or the crack to leave the body).
* Cycles: with Paris constants, ``N(a)`` by :func:`geardyn.faults.growth.paris_cycles` with
  ``Delta K = K_eq`` (one zero-to-peak load cycle per mesh of the tooth, ``R = 0``).
* Indicator: the tooth's compliance at the load point per unit face width,
  ``c = mean(u . n) / load`` over the patch [m^2/N], for each crack length.

Published path (qualitative comparison). Lewicki & Ballarini (NASA TM-107229 / ARL-TR-1110,
1996; the ASME J. Mech. Des. 1997 paper), read as its abstract only: "gears with backup ratios
of 3.3 and 1.0 produced tooth fractures while a backup ratio of 0.3 produced rim fractures"
(backup ratio = rim thickness / tooth height), in FE predictions (FRANC, quarter-point
elements, automated remeshing) and in tests. Their path coordinates could not be read from this
workplace, so the comparison is the failure mode only: a solid gear (backup ratio > 1) must
grow its root crack through the tooth, not down into the rim.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass, field

import numpy as np

from ..errors import InputError
from ..geometry import Gear
from ..stiffness.fe.crack_mesh import mesh_cracked_polygon, solve_plane
from ..stiffness.fe.mesh import CrackGeometry, _rot, crack_segment
from ..stiffness.fe.sif import interaction_integral
from ..stiffness.fe.solve import ElasticMaterial, flank_points
from .growth import equivalent_k, mts_angle, paris_cycles

__all__ = ["ToothCrackPath", "grow_tooth_crack", "tooth_sector_outline", "hpstc_roll"]


@dataclass(frozen=True)
class ToothCrackPath:
    """A grown tooth root crack.

    Attributes
    ----------
    points : ndarray, shape (n + 1, 2)
        Crack polyline in the body frame [m]: the mouth, then the tip after each step
        (``points[1]`` the initial tip).
    length : ndarray, shape (n,)
        Crack length along the path at each analysed tip [m].
    K_I, K_II : ndarray, shape (n,)
        Stress intensity factors at each tip [Pa m^0.5] under ``load``.
    theta_c : ndarray, shape (n,)
        Maximum tangential stress kink angle at each tip [rad].
    K_eq : ndarray, shape (n,)
        Equivalent mode-I factor ``K_theta(theta_c)`` [Pa m^0.5].
    compliance : ndarray, shape (n,)
        Load-point compliance of the tooth per unit face width [m^2/N].
    cycles : ndarray or None, shape (n,)
        Paris cycles from the initial crack [-] (``None`` without Paris constants).
    stop : str
        Why growth stopped.
    attrs : dict
        Inputs and units.
    """

    points: np.ndarray
    length: np.ndarray
    K_I: np.ndarray
    K_II: np.ndarray
    theta_c: np.ndarray
    K_eq: np.ndarray
    compliance: np.ndarray
    cycles: np.ndarray | None
    stop: str
    attrs: dict = field(default_factory=dict)


def hpstc_roll(pair, centre_distance_change: float = 0.0) -> float:
    """Pinion roll length of the highest point of single tooth contact [m]:
    ``u = s_start + p_b`` (the pinion's tooth carries the load alone from ``s_end - p_b`` to
    ``s_start + p_b`` along the line of action, ``s`` from the pinion's tangency point)."""
    op = pair.operating(centre_distance_change)
    return float(op.s_start + op.base_pitch)


def _insert(poly: np.ndarray, q: np.ndarray) -> tuple[np.ndarray, int]:
    """Insert point ``q`` into the polyline ``poly`` (form -> root fillet) on its nearest
    segment; returns the new polyline and the index of ``q``."""
    a, b = poly[:-1], poly[1:]
    d = b - a
    s = np.clip(np.sum((q - a) * d, axis=1) / np.sum(d * d, axis=1), 0, 1)
    dist = np.hypot(*(a + s[:, None] * d - q).T)
    k = int(np.argmin(dist))
    keep_a = poly[:k + 1]
    keep_b = poly[k + 1:]
    tol = 1e-3 * float(np.hypot(*d[k]))
    keep_a = keep_a[np.hypot(*(keep_a - q).T) > tol] if keep_a.shape[0] > 1 else keep_a
    keep_b = keep_b[np.hypot(*(keep_b - q).T) > tol] if keep_b.shape[0] > 1 else keep_b
    return np.vstack([keep_a, q[None], keep_b]), keep_a.shape[0]


def tooth_sector_outline(gear: Gear, mouth: np.ndarray, *, teeth: int = 3,
                         n_points: int = 40, bore_points: int = 24):
    """Counter-clockwise polygon of a gear sector of ``teeth`` teeth centred on tooth 0, with the
    crack ``mouth`` inserted as a vertex of tooth 0's loaded fillet.

    Returns
    -------
    outline : ndarray, shape (k, 2) [m]
    names : dict of str -> list of int
        Polygon sides of ``"flank0"`` (tooth 0's loaded involute), ``"bore"`` (the bore arc)
        and ``"cuts"`` (the two radial cuts).
    """
    if teeth < 1 or teeth % 2 == 0:
        raise InputError("teeth", teeth, "an odd number of teeth >= 1 (centred on tooth 0)")
    z = gear.teeth
    if teeth > z - 1:
        raise InputError("teeth", teeth, f"fewer than the gear's {z} teeth")
    o = gear.outline(n_involute=n_points, n_fillet=n_points)
    inv_l = o.involute * [-1.0, 1.0]  # loaded (x < 0) side, form -> tip
    fil_l = o.fillet * [-1.0, 1.0]  # form -> root
    inv_r, fil_r = o.involute, o.fillet
    half = teeth // 2
    pts: list[np.ndarray] = []
    names: dict[str, list[int]] = {"flank0": [], "bore": [], "cuts": []}
    rb = gear.bore_radius
    rr = gear.root_radius
    rt = gear.tip_radius
    for j in range(-half, half + 1):
        R = _rot(2 * math.pi * j / z)
        right = np.vstack([fil_r[::-1], inv_r[1:]])  # root -> tip
        tip_a = math.atan2(inv_r[-1, 1], inv_r[-1, 0])
        tip_b = math.atan2(inv_l[-1, 1], inv_l[-1, 0])
        arc = np.linspace(tip_a, tip_b, 6)[1:-1]
        tip = rt * np.stack([np.cos(arc), np.sin(arc)], axis=1)
        lfil = fil_l
        k_m = None
        if j == 0:
            lfil, k_m = _insert(fil_l, np.asarray(mouth, float))
        left = np.vstack([inv_l[::-1], lfil[1:]])  # tip -> root
        tooth = np.vstack([right, tip, left]) @ R.T
        if j == -half:
            a0 = math.atan2(tooth[0, 1], tooth[0, 0])
            pts.append(np.array([rb * math.cos(a0), rb * math.sin(a0)]))
        else:
            # root circle arc from the previous tooth's left root to this right root
            a1 = math.atan2(pts[-1][1], pts[-1][0])
            a2 = math.atan2(tooth[0, 1], tooth[0, 0])
            if a2 < a1:
                a2 += 2 * math.pi
            for a in np.linspace(a1, a2, 5)[1:-1]:
                pts.append(rr * np.array([math.cos(a), math.sin(a)]))
        base = len(pts)
        if j == 0:
            n_right = right.shape[0] + tip.shape[0]
            i_flank0 = base + n_right  # tip end of the loaded involute
            names["flank0"] = list(range(i_flank0, i_flank0 + inv_l.shape[0] - 1))
            mouth_index = base + n_right + inv_l.shape[0] - 1 + k_m
        pts.extend(list(tooth))
    last = len(pts) - 1  # the last tooth's left root
    a_end = math.atan2(pts[-1][1], pts[-1][0])
    a_start = math.atan2(pts[0][1], pts[0][0])
    if a_start > a_end:
        a_start -= 2 * math.pi
    for a in np.linspace(a_end, a_start, bore_points)[:-1]:  # the last one is pts[0]
        pts.append(rb * np.array([math.cos(a), math.sin(a)]))
    outline = np.array(pts)
    n = outline.shape[0]
    names["cuts"] = [0, last]  # sides pts[0] -> first root, last root -> bore
    names["bore"] = list(range(last + 1, n))  # bore arc sides (the last one closes on pts[0])
    if np.hypot(*(outline[mouth_index] - mouth)) > 1e-12:
        raise InputError("mouth", np.asarray(mouth).tolist(), "a point on tooth 0's fillet")
    return outline, names


def _distance_to_outline(outline: np.ndarray, q: np.ndarray) -> float:
    a = outline
    b = np.roll(outline, -1, axis=0)
    d = b - a
    s = np.clip(np.sum((q - a) * d, axis=1) / np.sum(d * d, axis=1), 0, 1)
    dist = np.hypot(*(a + s[:, None] * d - q).T)
    return float(dist.min())


def _inside(outline: np.ndarray, q: np.ndarray) -> bool:
    from matplotlib.path import Path

    return bool(Path(outline).contains_point(q))


def grow_tooth_crack(gear: Gear, material: ElasticMaterial, crack: CrackGeometry, *,
                     load: float, load_roll: float, step: float, n_steps: int,
                     patch: float | None = None, teeth: int = 3, n_points: int = 40,
                     size: float | None = None, paris: tuple[float, float] | None = None,
                     paris_threshold: float = 0.0,
                     progress: Callable[[int, int], None] | None = None) -> ToothCrackPath:
    """Grow a root crack on tooth 0 by the maximum tangential stress criterion (module
    docstring).

    Parameters
    ----------
    gear : Gear
    material : ElasticMaterial
    crack : CrackGeometry
        Initial straight crack (depth [m], angle to the centreline [rad]).
    load : float
        Force per unit face width along the line of action [N/m].
    load_roll : float
        Roll length of the load point on the loaded involute [m] (e.g. :func:`hpstc_roll`).
    step : float
        Crack extension per step [m].
    n_steps : int
        Largest number of extensions.
    patch : float, optional
        Half-length of the loaded flank patch [m] (default ``gear.module / 10``).
    teeth : int
        Teeth in the sector (odd).
    n_points : int
        Polygon points per involute and per fillet.
    size : float, optional
        Element size far from the crack [m] (default ``gear.module / 3``).
    paris : (C, m), optional
        Paris constants, ``C`` in m/cycle/(Pa m^0.5)^m; no default.
    paris_threshold : float
        ``Delta K_th`` [Pa m^0.5].
    progress : callable, optional
        ``progress(done, total)`` per analysed tip.

    Returns
    -------
    ToothCrackPath
    """
    if not (math.isfinite(load) and load > 0):
        raise InputError("load", load, "a force per unit face width > 0 [N/m]")
    if not (math.isfinite(step) and 0 < step < crack.depth * 4):
        raise InputError("step", step, f"a crack extension in (0, {4 * crack.depth:g}) m")
    if n_steps < 0:
        raise InputError("n_steps", n_steps, "an integer >= 0")
    rbase = gear.base_radius
    u_tip = math.sqrt(gear.tip_radius ** 2 - rbase ** 2)
    u_form = math.sqrt(max(gear.form_radius ** 2 - rbase ** 2, 0.0))
    if not u_form < load_roll < u_tip:
        raise InputError("load_roll", load_roll, f"a roll length on the involute "
                         f"({u_form:.6g}, {u_tip:.6g}) m")
    patch = gear.module / 10 if patch is None else patch
    size = gear.module / 3 if size is None else size
    mouth, tip0 = crack_segment(gear, crack)
    outline, names = tooth_sector_outline(gear, mouth, teeth=teeth, n_points=n_points)
    xl, nl = flank_points(gear, 0, np.array([load_roll]))
    xl, nl = xl[:, 0], nl[:, 0]
    path = [np.asarray(mouth, float), np.asarray(tip0, float)]
    rec: dict[str, list[float]] = {k: [] for k in ("length", "K_I", "K_II", "theta", "K_eq",
                                                    "compliance")}
    stop = f"n_steps = {n_steps} reached"
    total = n_steps + 1
    for k in range(n_steps + 1):
        poly = np.array(path)
        seg = float(np.hypot(*(poly[-1] - poly[-2])))
        d_b = _distance_to_outline(outline, poly[-1])
        r_out = 0.5 * min(seg, d_b)
        tip_size = r_out / 15
        mesh = mesh_cracked_polygon(outline, poly, tip_size=tip_size, size=size,
                                    growth=1.25, names=names,
                                    refine=[(xl, min(patch / 4, size))])
        f = mesh.edges["flank0"]
        mid = 0.5 * (mesh.p[:, f[0]] + mesh.p[:, f[1]])
        on = np.hypot(*(mid - xl[:, None])) <= patch
        covered = float(np.sum(np.hypot(*(mesh.p[:, f[0]] - mesh.p[:, f[1]]))[on]))
        if covered <= 0:
            raise InputError("patch", patch, "a load patch longer than the flank elements")
        traction = load / covered * nl
        sol = solve_plane(mesh, material, tractions={"flank0": tuple(traction)},
                          masks={"flank0": on}, fixed=("bore", "cuts"))
        d = (poly[-1] - poly[-2]) / seg
        sif = interaction_integral(sol.basis.mesh, sol.u, material, poly[-1], d, r_out=r_out)
        nodal = sol.nodal_displacements()
        w = np.hypot(*(mesh.p[:, f[0]] - mesh.p[:, f[1]]))[on]
        un = nl @ (0.5 * (nodal[:, f[0, on]] + nodal[:, f[1, on]]))
        rec["length"].append(float(np.sum(np.hypot(*np.diff(poly, axis=0).T))))
        rec["K_I"].append(sif.K_I)
        rec["K_II"].append(sif.K_II)
        rec["compliance"].append(float(np.sum(un * w) / covered / load))
        if progress is not None:
            progress(k + 1, total)
        if sif.K_I <= 0:
            rec["theta"].append(float("nan"))
            rec["K_eq"].append(float("nan"))
            stop = "K_I <= 0 (the crack closes under the load)"
            break
        th = mts_angle(sif.K_I, sif.K_II)
        rec["theta"].append(th)
        rec["K_eq"].append(float(equivalent_k(sif.K_I, sif.K_II)))
        if k == n_steps:
            break
        c, s = math.cos(th), math.sin(th)
        new_d = np.array([c * d[0] - s * d[1], s * d[0] + c * d[1]])
        nxt = poly[-1] + step * new_d
        if not _inside(outline, nxt) or _distance_to_outline(outline, nxt) < step:
            stop = "the tip reached the outline (within one step): the tooth or rim breaks"
            break
        path.append(nxt)
    n = len(rec["K_I"])
    arr = {k: np.array(v) for k, v in rec.items()}
    cycles = None
    if paris is not None:
        good = np.isfinite(arr["K_eq"])
        cycles = np.full(n, np.nan)
        cycles[good] = paris_cycles(arr["length"][good], arr["K_eq"][good], paris[0], paris[1],
                                    paris_threshold)
    attrs = {"load": (float(load), "N/m"), "load_roll": (float(load_roll), "m"),
             "step": (float(step), "m"), "patch": (float(patch), "m"),
             "initial_depth": (float(crack.depth), "m"),
             "initial_angle": (float(crack.angle), "rad"), "teeth": teeth,
             "plane": material.plane, "youngs_modulus": (material.youngs_modulus, "Pa"),
             "poisson_ratio": material.poisson_ratio,
             "paris": None if paris is None else (float(paris[0]), float(paris[1]))}
    return ToothCrackPath(points=np.array(path[:n + 1]), length=arr["length"], K_I=arr["K_I"],
                          K_II=arr["K_II"], theta_c=arr["theta"], K_eq=arr["K_eq"],
                          compliance=arr["compliance"], cycles=cycles, stop=stop, attrs=attrs)
