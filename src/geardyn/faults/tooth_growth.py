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

From a case: :func:`grow_case_crack` takes the gear, material, initial crack (:func:`case_crack`:
the ``[crack]`` section or one through-face ``root_crack`` entry) and tooth load
(:func:`tooth_load`, ``motor.torque``) from a :class:`geardyn.config.Case` and returns the path as
an xarray Dataset with units (:func:`growth_dataset`); the vibration indicators against cycles
are a study on top of it (:mod:`geardyn.studies.crack_growth`).

Published path (qualitative comparison). Lewicki & Ballarini (NASA TM-107229 / ARL-TR-1110,
1996; the ASME J. Mech. Des. 1997 paper), read as its abstract only: "gears with backup ratios
of 3.3 and 1.0 produced tooth fractures while a backup ratio of 0.3 produced rim fractures"
(backup ratio = rim thickness / tooth height), in FE predictions (FRANC, quarter-point
elements, automated remeshing) and in tests. Their path coordinates could not be read from this
workplace, so the comparison is the failure mode only: the paper's pinion (backup ratio ~3)
and the same pinion with a rim one tooth height thick (backup ratio 1.0) must grow the root
crack through the tooth, not down into the rim (``tests/faults/test_sif.py``). Thinner rims
(0.5, 0.3) are outside this model: a rim thinner than a module is refused by
:func:`geardyn.stiffness.fe.mesh.crack_segment`, and the sector is clamped on the bore, which a
thin rim on a web is not.
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

__all__ = ["ToothCrackPath", "grow_tooth_crack", "tooth_sector_outline", "hpstc_roll",
           "CaseCrack", "case_crack", "tooth_load", "equivalent_crack", "grow_case_crack",
           "growth_dataset", "crack_at"]


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


def hpstc_roll(pair, centre_distance_change: float = 0.0, gear: str = "pinion") -> float:
    """Roll length of the highest point of single tooth contact on ``gear``'s flank [m].

    A tooth carries the load alone while ``s`` (along the line of action from the pinion's
    tangency point) runs from ``s_end - p_b`` to ``s_start + p_b``. On the pinion the highest
    point is ``u = s_start + p_b``; on the gear (roll length from the gear's tangency point,
    ``u = T1T2 - s``) it is ``u = T1T2 - (s_end - p_b)``.
    """
    op = pair.operating(centre_distance_change)
    if gear == "pinion":
        return float(op.s_start + op.base_pitch)
    if gear == "gear":
        return float(op.t1t2 - (op.s_end - op.base_pitch))
    raise InputError("gear", gear, "'pinion' or 'gear'")


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


def check_step(step: float, depth: float, field: str = "step") -> None:
    """Refuse a growth step outside ``(0, 4 depth)`` [m] (``depth`` the initial crack length): a
    first step four times the crack would jump past the region the initial crack's ``K``
    describes."""
    if not (math.isfinite(step) and 0 < step < depth * 4):
        raise InputError(field, step, f"a crack extension in (0, {4 * depth:g}) m (below four "
                                      "times the initial crack length)")


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
        ``Delta K_th`` [Pa m^0.5]. With ``paris``, the growth stops at the first length whose
        ``Delta K_eq`` is at or below it (the crack arrests: the Paris rate is zero there, so
        no load cycle takes the crack further and the path beyond would never be reached).
    progress : callable, optional
        ``progress(done, total)`` per analysed tip.

    Returns
    -------
    ToothCrackPath
    """
    if not (math.isfinite(load) and load > 0):
        raise InputError("load", load, "a force per unit face width > 0 [N/m]")
    check_step(step, crack.depth)
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
        if paris is not None and rec["K_eq"][-1] <= paris_threshold:
            stop = (f"Delta K_eq {rec['K_eq'][-1] / 1e6:.3g} MPa m^0.5 at or below the "
                    f"threshold {paris_threshold / 1e6:.3g} MPa m^0.5: the crack arrests")
            break
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


# ---------------------------------------------------------------------------- from a case
@dataclass(frozen=True)
class CaseCrack:
    """The initial crack a case gives: its ``[crack]`` section or one ``root_crack`` entry of its
    ``faults`` list.

    Attributes
    ----------
    gear : {"pinion", "gear"}
        Which gear is cracked.
    tooth : int
        Cracked tooth (0-based, mesh order).
    depth : float
        Crack length from the mouth [m].
    angle : float
        Angle to the tooth centreline [rad].
    field : str
        Its name in messages: ``"crack"`` or ``"faults[i]"``.
    key : str
        Its dotted key for case overrides: ``"crack"`` or ``"faults.i"``.
    """

    gear: str
    tooth: int
    depth: float
    angle: float
    field: str
    key: str


def case_crack(case) -> CaseCrack:
    """The case's initial crack (see :class:`CaseCrack`).

    Raises
    ------
    InputError
        No crack (an enabled ``[crack]`` or a ``root_crack`` entry), more than one, a crack of
        zero length, or a ``root_crack`` entry across part of the face only (the growth model is
        plane: a crack through the whole face width with a uniform front).
    """
    found: list[CaseCrack] = []
    c = getattr(case, "crack", None)
    if c is not None and c.enabled:
        found.append(CaseCrack(c.gear, int(c.tooth), float(c.depth), float(c.angle), "crack",
                               "crack"))
    L = case.pair.face_width
    for i, f in enumerate(getattr(case, "faults", None) or ()):
        if f.type != "root_crack":
            continue
        field = f"faults[{i}]"
        if f.width is not None and f.width < L * (1 - 1e-12):
            raise InputError(f"{field}.width", f.width, f"the whole face width ({L:g} m) or no "
                             "width: crack growth is modelled in the plane (a through-face crack)")
        if f.front not in (None, "uniform"):
            raise InputError(f"{field}.front", f.front, "'uniform' (or none): crack growth is "
                                                        "modelled in the plane")
        angle = math.radians(45) if f.angle is None else float(f.angle)
        found.append(CaseCrack(f.gear, int(f.tooth), float(f.depth or 0.0), angle, field,
                               f"faults.{i}"))
    if not found:
        raise InputError("crack", None, "an initial crack to grow: an enabled [crack] section or "
                                        "a [[faults]] entry with type = 'root_crack'")
    if len(found) > 1:
        raise InputError(found[1].field, "a second root crack", f"one initial crack only "
                         f"({found[0].field} is one; disable or remove the other)")
    crack = found[0]
    if not crack.depth > 0:
        raise InputError(f"{crack.field}.depth", crack.depth, "an initial crack length > 0 m "
                                                              "(growth starts from a crack)")
    return crack


def tooth_load(case) -> float:
    """Tooth load of the growth model per unit face width [N/m]: the whole mesh force of the
    pinion torque on one tooth, ``W = T / (r_b1 b)`` (``T = motor.torque`` [N m], ``r_b1`` the
    pinion's base radius, ``b`` the face width). The same normal force acts on the gear's
    tooth."""
    pair = case.gear_pair()
    return float(case.motor.torque / (pair.pinion.base_radius * case.pair.face_width))


def initial_geometry(case):
    """Validate the case's initial crack on its gear; returns ``(CaseCrack, Gear,
    CrackGeometry, mouth, tip)`` (mouth and tip [m] in the body frame of tooth 0).

    Raises
    ------
    InputError
        As :func:`case_crack`, or a crack deeper than the tooth (it leaves the tooth section),
        naming ``crack.depth`` or ``faults[i].depth``.
    """
    from .base import gear_of

    c = case_crack(case)
    gear = gear_of(case.gear_pair(), c.gear)
    try:
        geom = CrackGeometry(c.depth, c.angle)
        mouth, tip = crack_segment(gear, geom)
    except InputError as exc:
        key = str(exc.field).rsplit(".", 1)[-1]
        raise InputError(f"{c.field}.{key}", exc.value, exc.allowed) from None
    return c, gear, geom, mouth, tip


def crack_at(growth, k: int, depth: float, angle: float) -> CrackGeometry:
    """The grown crack at crack length index ``k`` of ``growth`` (:func:`growth_dataset`) as a
    polyline :class:`geardyn.stiffness.fe.mesh.CrackGeometry` for the FE mesh stiffness: the
    path from the mouth through the tips of steps ``0..k``; ``depth`` [m] and ``angle`` [rad]
    record the initial crack it grew from."""
    n = growth.sizes["crack_length"]
    if not 0 <= int(k) < n:
        raise InputError("k", k, f"a crack length index in [0, {n - 1}]")
    x, y = growth["path_x"].values, growth["path_y"].values
    pts = tuple((float(a), float(b)) for a, b in zip(x[1:int(k) + 2], y[1:int(k) + 2],
                                                      strict=True))
    return CrackGeometry(depth=float(depth), angle=float(angle), path=pts)


def equivalent_crack(mouth, tip) -> tuple[float, float]:
    """The straight crack of the chord from the mouth to a tip: ``(depth [m], angle [rad])``.

    In the body frame of :mod:`geardyn.stiffness.fe.mesh` (tooth on ``+y``, loaded flank at
    ``x < 0``) a straight crack of length ``q`` at angle ``v`` to the centreline runs along
    ``(sin v, -cos v)``, so the chord ``d = tip - mouth`` gives ``q = |d|`` and
    ``v = atan2(d_x, -d_y)``. ``v`` outside ``(0, pi/2)`` (a tip above its mouth, or on the
    loaded side of it) has no straight-crack equivalent in the PEM.
    """
    d = np.asarray(tip, float) - np.asarray(mouth, float)
    return float(np.hypot(*d)), float(math.atan2(d[0], -d[1]))


def grow_case_crack(case, *, paris_c: float, paris_m: float, paris_threshold: float = 0.0,
                    step: float | None = None, n_steps: int = 60, teeth: int = 3,
                    progress: Callable[[int, int], None] | None = None):
    """Grow the case's root crack (module docstring) and return the path as a Dataset.

    The gear, its outline and bore come from the case; the material from ``[material]`` with
    ``stiffness.fe.plane``; the initial crack from :func:`case_crack`; the tooth load from
    :func:`tooth_load` (``motor.torque``) at the highest point of single tooth contact of the
    cracked gear (:func:`hpstc_roll`, design centre distance). Paris constants are required:
    geardyn ships none (:mod:`geardyn.faults.growth`).

    Parameters
    ----------
    case : geardyn.config.Case
    paris_c : float
        Paris ``C`` [m/cycle/(Pa m^0.5)^m] (:func:`geardyn.faults.growth.paris_c_from_mpa`
        converts one quoted per MPa m^0.5).
    paris_m : float
        Paris exponent ``m`` [-].
    paris_threshold : float
        ``Delta K_th`` [Pa m^0.5].
    step : float, optional
        Crack extension per step [m] (default ``module / 6``).
    n_steps : int
        Largest number of extensions (growth stops earlier when the tip comes within one step
        of the outline).
    teeth : int
        Teeth in the FE sector (odd).
    progress : callable, optional
        ``progress(done, total)`` per analysed tip.

    Returns
    -------
    xarray.Dataset
        Over ``crack_length`` [m] (along the path from the mouth): ``tip_x``, ``tip_y`` [m];
        ``K_I``, ``K_II``, ``K_eq`` [Pa m^0.5]; ``kink_angle`` [rad]; ``cycles`` [-] (from the
        initial crack, one zero-to-peak load cycle per revolution of the cracked gear);
        ``compliance`` [m^2/N] (load-point compliance per unit face width). Over
        ``path_point``: the crack polyline ``path_x``, ``path_y`` [m] (mouth first). Over
        ``outline_point``: the FE sector's outline ``outline_x``, ``outline_y`` [m]. Inputs,
        the stop reason and the model's assumptions in the attributes.
    """
    from .growth import _check_paris

    _check_paris(float(paris_c), float(paris_m), float(paris_threshold))
    c, gear, geom, mouth, _ = initial_geometry(case)
    pair = case.gear_pair()
    material = ElasticMaterial(case.material.youngs_modulus, case.material.poisson_ratio,
                               case.stiffness.fe.plane)
    load = tooth_load(case)
    roll = hpstc_roll(pair, 0.0, c.gear)
    step = gear.module / 6 if step is None else float(step)
    check_step(step, c.depth)
    if isinstance(n_steps, bool) or int(n_steps) != n_steps or not 0 <= n_steps <= 1000:
        raise InputError("n_steps", n_steps, "an integer from 0 to 1000")
    path = grow_tooth_crack(gear, material, geom, load=load, load_roll=roll, step=step,
                            n_steps=int(n_steps), teeth=teeth,
                            paris=(float(paris_c), float(paris_m)),
                            paris_threshold=float(paris_threshold), progress=progress)
    outline, _ = tooth_sector_outline(gear, mouth, teeth=teeth)
    ds = growth_dataset(path, outline, case=case, crack=c, gear=gear)
    ds.attrs["paris_threshold"] = float(paris_threshold)
    ds.attrs["paris_threshold_units"] = "Pa m^0.5"
    return ds


def growth_dataset(path: ToothCrackPath, outline: np.ndarray, *, case=None,
                   crack: CaseCrack | None = None, gear: Gear | None = None):
    """A :class:`ToothCrackPath` as an xarray Dataset with units and long names on every
    variable (layout in :func:`grow_case_crack`)."""
    import xarray as xr

    n = path.length.shape[0]
    cyc = np.full(n, np.nan) if path.cycles is None else np.asarray(path.cycles, float)
    pts = np.asarray(path.points, float)

    def v(dim, data, units, long):
        return (dim, np.asarray(data, float), {"units": units, "long_name": long})

    L = "crack_length"
    ds = xr.Dataset(
        {
            "tip_x": v(L, pts[1:n + 1, 0], "m", "crack tip abscissa (body frame: cracked tooth "
                                                "on +y, loaded flank at x < 0)"),
            "tip_y": v(L, pts[1:n + 1, 1], "m", "crack tip ordinate (body frame)"),
            "K_I": v(L, path.K_I, "Pa m^0.5", "mode I stress intensity factor at the tip "
                                               "(interaction integral) under the tooth load"),
            "K_II": v(L, path.K_II, "Pa m^0.5", "mode II stress intensity factor at the tip"),
            "kink_angle": v(L, path.theta_c, "rad", "kink angle of the next extension (maximum "
                                                    "tangential stress), from the crack "
                                                    "direction, positive to its left"),
            "K_eq": v(L, path.K_eq, "Pa m^0.5", "equivalent mode I factor K_theta(theta_c) "
                                                "(Delta K of the Paris law, R = 0)"),
            "cycles": v(L, cyc, "1", "load cycles from the initial crack (Paris law, "
                                     "trapezoidal rule; one zero-to-peak cycle per revolution "
                                     "of the cracked gear)"),
            "compliance": v(L, path.compliance, "m^2/N", "load-point compliance of the tooth "
                                                         "along the line of action, per unit "
                                                         "face width"),
            "path_x": v("path_point", pts[:, 0], "m", "crack polyline abscissa, mouth first "
                                                      "(body frame)"),
            "path_y": v("path_point", pts[:, 1], "m", "crack polyline ordinate, mouth first"),
            "outline_x": v("outline_point", outline[:, 0], "m", "FE sector outline abscissa "
                                                                "(body frame)"),
            "outline_y": v("outline_point", outline[:, 1], "m", "FE sector outline ordinate"),
        },
        coords={L: (L, np.asarray(path.length, float),
                    {"units": "m", "long_name": "crack length along the path from the mouth"})},
    )
    a = path.attrs
    paris = a.get("paris")
    attrs = {
        "title": "geardyn crack growth: path, stress intensity factors, Paris cycles",
        "stop": path.stop,
        "tooth_load_N_per_m": a["load"][0],
        "load_roll_length_m": a["load_roll"][0],
        "step_m": a["step"][0],
        "load_patch_half_length_m": a["patch"][0],
        "initial_depth_m": a["initial_depth"][0],
        "initial_angle_rad": a["initial_angle"][0],
        "sector_teeth": int(a["teeth"]),
        "plane": a["plane"],
        "youngs_modulus_Pa": float(a["youngs_modulus"][0]),
        "poisson_ratio": float(a["poisson_ratio"]),
        "model": "plane LEFM, quasi-static: a sector of the cracked gear clamped at the bore "
                 "and the radial cuts, the tooth load along the line of action at the highest "
                 "point of single tooth contact at the design centre distance (the static "
                 "operating centre distance moves it up the flank: not modelled); K by the "
                 "interaction integral, direction by "
                 "the maximum tangential stress criterion, remeshed each step "
                 "(geardyn.faults.tooth_growth)",
    }
    if paris is not None:
        attrs["paris_C"] = float(paris[0])
        attrs["paris_C_units"] = "m/cycle/(Pa m^0.5)^m"
        attrs["paris_m"] = float(paris[1])
    if case is not None:
        attrs["case"] = case.name
        attrs["motor_torque_N_m"] = float(case.motor.torque)
    if crack is not None:
        attrs["cracked_gear"] = crack.gear
        attrs["cracked_tooth"] = crack.tooth
        attrs["initial_crack_from"] = crack.field
    if gear is not None:
        attrs["gear_teeth"] = int(gear.teeth)
        attrs["module_m"] = float(gear.module)
    ds.attrs.update(attrs)
    return ds
