r"""Substructuring of a gear body: a new tooth fault without re-solving the healthy body (opt-in).

Idea (static condensation, exact)
---------------------------------
The body is split by a fixed interface curve ``Gamma`` into the *fault region* ``R`` (model tooth 0
and its rim sector: between the middles of its two tooth gaps, at polar angles
``pi/2 -+ pi/z``, down to the radius ``r_Gamma``) and the *healthy part* ``H`` (the rest, with the
bore). Both are meshed by gmsh with ``Gamma`` discretised transfinitely (a fixed number of equally
spaced nodes on each of its three curves: two radial lines and an arc), so ``R`` can be re-meshed
for any crack or cut while the nodes on ``Gamma`` stay the same (checked to 1e-12 of the tip radius).

``H`` is condensed once onto the ``Gamma`` DOFs ``g``, the bore fixed (static condensation, exact
because the loads of ``H``'s condensed DOFs ``i`` are condensed with it):

.. math:: S_H = K_{gg} - K_{gi} K_{ii}^{-1} K_{ig},

together with the Hertzian patch loads on the loaded flanks of ``H``'s refined teeth and the
readouts there (:class:`HealthySuperelement`). For a fault, only ``R`` is meshed, assembled and
factorised, with ``S_H`` added on its ``Gamma`` block; one sparse solve per load gives the
displacements of ``R`` and of ``Gamma``, from which the readouts of ``H``'s teeth follow.
The displacements are those of the full-body solve of the glued mesh ``H + R`` up to round-off
(the tests compare the influence coefficients to :func:`.solve.influence_matrices` on the glued
mesh). The method is textbook substructuring (e.g. Guyan 1965 condensation, applied to
superelements); no geardyn-specific source was used.

The meshes here are not those of :func:`.mesh.build_body_mesh` (that mesh has no interface curve),
so the coefficients differ from the cached full-body map by the discretisation error only; this
path is opt-in and does not change :class:`.model.FEStiffness`.

References
----------
Guyan, R. J. (1965). Reduction of stiffness and mass matrices. AIAA J. 3(2):380 (not re-read for
this module; cited for the name of the method).
"""

from __future__ import annotations

import math
import time

import numpy as np
import scipy.sparse as sp

from ...errors import InputError, NumericalError
from ...geometry import Gear
from .factor import factorise
from .mesh import (
    _GMSH_LOCK,
    BodyMesh,
    CrackGeometry,
    MeshSettings,
    _initialize_gmsh,
    _orient_by_radius,
    _rot,
    check_cut,
    crack_polyline,
    crack_segment,
    cut_flank,
    embed_crack,
    loaded_flank,
    split_body_crack,
    tooth_offsets,
)
from .solve import (
    BodyInfluence,
    ElasticBody,
    ElasticMaterial,
    stats_from_array,
    stats_to_array,
)

__all__ = ["build_part_mesh", "glue_meshes", "HealthySuperelement", "interface_radius"]


def interface_radius(gear: Gear, fraction: float = 0.5) -> float:
    """Radius of the arc of ``Gamma`` [m]: ``r_bore + fraction (r_root - r_bore)``."""
    if not 0.05 <= fraction <= 0.95:
        raise InputError("substructure.fraction", fraction, "a fraction in [0.05, 0.95]")
    _, fil = loaded_flank(gear, 16)
    r_root = float(np.hypot(*fil[-1]))
    return gear.bore_radius + fraction * (r_root - gear.bore_radius)


def build_part_mesh(gear: Gear, settings: MeshSettings, part: str, *,
                    crack: CrackGeometry | None = None, cut_radius: float | None = None,
                    n_points: int = 150, fraction: float = 0.5) -> BodyMesh:
    """Mesh the healthy part ``H`` (``part="H"``) or the fault region ``R`` (``part="R"``).

    Same outline and size fields as :func:`.mesh.build_body_mesh`; ``Gamma`` (edge ``"gamma"``)
    carries equally spaced nodes at about ``settings.tooth_size`` spacing [m], identical in both
    parts. ``crack`` and ``cut_radius`` [m] apply to ``R`` only. ``H`` has edges ``"bore"``,
    ``"gamma"`` and ``"flank{j}"`` for its refined teeth; ``R`` has ``"gamma"``, ``"flank0"`` and
    ``"crack+"``/``"crack-"`` for a crack, and an empty ``"bore"``.
    """
    import gmsh

    if part not in ("H", "R"):
        raise InputError("part", part, "'H' or 'R'")
    if part == "H" and (crack is not None or cut_radius is not None):
        raise InputError("part", part, "'R' for a crack or a cut (faults live in R)")
    z = gear.teeth
    offsets = tooth_offsets(settings.refined_teeth)
    if len(offsets) > z - 1:
        raise InputError("stiffness.fe.teeth_in_model", settings.refined_teeth,
                         f"at most the number of teeth - 1 ({z - 1}) for substructuring")
    inv_r, fil_r = loaded_flank(gear, n_points)
    inv_c, fil_c = loaded_flank(gear, 16)
    r_root = float(np.hypot(*fil_r[-1]))
    r_g = interface_radius(gear, fraction)
    mouth = tip = None
    if crack is not None:
        mouth, tip = crack_segment(gear, crack)
        poly = crack_polyline(gear, crack)
        polar = np.arctan2(poly[:, 1], poly[:, 0])
        outside = np.any((polar <= math.pi / 2 - math.pi / z) | (polar >= math.pi / 2 + math.pi / z))
        if np.min(np.hypot(*poly.T)) < r_g + settings.tooth_size or outside:
            raise InputError("crack.path" if crack.path else "crack.depth",
                             crack.path or crack.depth,
                             f"a crack that stays above the interface radius {r_g:.4g} m (plus "
                             "one tooth element) and within the faulty tooth's sector for "
                             "substructuring")
    inv_cut = None
    if cut_radius is not None:
        check_cut(gear, cut_radius)
        inv_cut = cut_flank(gear, cut_radius, n_points)
    phi_m, phi_p = math.pi / 2 - math.pi / z, math.pi / 2 + math.pi / z
    h_g = settings.tooth_size
    n_line = max(2, int(math.ceil((r_root - r_g) / h_g))) + 1
    n_arc = max(2, int(math.ceil(r_g * 2 * math.pi / z / h_g))) + 1

    with _GMSH_LOCK:
        _initialize_gmsh()
        try:
            gmsh.option.setNumber("General.Terminal", 0)
            gmsh.option.setNumber("General.Verbosity", 1)
            gmsh.option.setNumber("General.NumThreads", 1)
            gmsh.option.setNumber("Mesh.MeshSizeFromPoints", 0)
            gmsh.option.setNumber("Mesh.MeshSizeFromCurvature", 0)
            gmsh.option.setNumber("Mesh.MeshSizeExtendFromBoundary", 0)
            gmsh.option.setNumber("Mesh.Algorithm", 6)
            gmsh.option.setNumber("Mesh.RandomFactor", 1e-9)
            gmsh.model.add("gear_part")
            geo = gmsh.model.geo
            lc = settings.body_size

            def point(xy) -> int:
                return geo.addPoint(float(xy[0]), float(xy[1]), 0.0, lc)

            centre = geo.addPoint(0.0, 0.0, 0.0, lc)
            # the interface: A -> Pm (right radial line), B -> Pp (left), arc A -> B
            pa = point((r_g * math.cos(phi_m), r_g * math.sin(phi_m)))
            pb = point((r_g * math.cos(phi_p), r_g * math.sin(phi_p)))
            pm = point((r_root * math.cos(phi_m), r_root * math.sin(phi_m)))
            pp = point((r_root * math.cos(phi_p), r_root * math.sin(phi_p)))
            line_r = geo.addLine(pa, pm)
            line_l = geo.addLine(pb, pp)
            arc_g = geo.addCircleArc(pa, centre, pb)
            geo.mesh.setTransfiniteCurve(line_r, n_line)
            geo.mesh.setTransfiniteCurve(line_l, n_line)
            geo.mesh.setTransfiniteCurve(arc_g, n_arc)
            named: dict[str, list[int]] = {"gamma": [line_r, line_l, arc_g]}
            curves: list[int] = []
            crack_mouth_tag = None
            js = [0] if part == "R" else [k if k <= z // 2 else k - z for k in range(1, z)]
            prev_end = pm if part == "R" else pp
            for j in js:
                refined = j in offsets
                inv, fil = (inv_r, fil_r) if refined else (inv_c, fil_c)
                if inv_cut is not None and j == 0:
                    inv = inv_cut
                rot = _rot(2 * math.pi * j / z)
                r_fil = (rot @ (fil * [-1, 1]).T).T
                r_inv = (rot @ (inv * [-1, 1]).T).T
                l_fil = (rot @ fil.T).T
                l_inv = (rot @ inv.T).T
                p_rroot = point(r_fil[-1])
                p_rform = point(r_fil[0])
                p_rtip = point(r_inv[-1])
                p_ltip = point(l_inv[-1])
                p_lform = point(l_fil[0])
                p_lroot = point(l_fil[-1])
                curves.append(geo.addCircleArc(prev_end, centre, p_rroot))
                curves.append(geo.addSpline([p_rroot, *[point(q) for q in r_fil[-2:0:-1]],
                                             p_rform]))
                curves.append(geo.addSpline([p_rform, *[point(q) for q in r_inv[1:-1]],
                                             p_rtip]))
                tipc = geo.addCircleArc(p_rtip, centre, p_ltip)
                curves.append(tipc)
                flank = geo.addSpline([p_ltip, *[point(q) for q in l_inv[-2:0:-1]], p_lform])
                curves.append(flank)
                if refined:
                    named[f"flank{j}"] = [flank]
                    named[f"tip{j}"] = [tipc]
                if crack is not None and j == 0:
                    pts = l_fil
                    i_m = int(np.argmin(np.hypot(*(pts - mouth).T)))
                    rm = np.hypot(*mouth)
                    upper = [q for q in pts[1:i_m + 1]
                             if np.hypot(*(q - mouth)) > 1e-3 * lc and np.hypot(*q) > rm]
                    lower = [q for q in pts[i_m:-1]
                             if np.hypot(*(q - mouth)) > 1e-3 * lc and np.hypot(*q) < rm]
                    crack_mouth_tag = point(mouth)
                    c1 = geo.addSpline([p_lform, *[point(q) for q in upper], crack_mouth_tag])
                    c2 = geo.addSpline([crack_mouth_tag, *[point(q) for q in lower], p_lroot])
                    curves += [c1, c2]
                    named["fillet0"] = [c1, c2]
                else:
                    c = geo.addSpline([p_lform, *[point(q) for q in l_fil[1:-1]], p_lroot])
                    curves.append(c)
                    if refined:
                        named[f"fillet{j}"] = [c]
                prev_end = p_lroot
            if part == "R":
                curves += [geo.addCircleArc(prev_end, centre, pp), -line_l, -arc_g, line_r]
                surf = geo.addPlaneSurface([geo.addCurveLoop(curves)])
            else:
                curves += [geo.addCircleArc(prev_end, centre, pm), -line_r, arc_g, line_l]
                outer = geo.addCurveLoop(curves)
                b = gear.bore_radius
                pbore = [point((b * math.cos(a), b * math.sin(a)))
                         for a in (0, 2 * math.pi / 3, 4 * math.pi / 3)]
                bore = [geo.addCircleArc(pbore[i], centre, pbore[(i + 1) % 3]) for i in range(3)]
                named["bore"] = bore
                surf = geo.addPlaneSurface([outer, geo.addCurveLoop(bore)])
            crack_lines, p_tip = [], None
            if crack is not None:
                crack_lines, p_tip = embed_crack(geo, gear, crack, crack_mouth_tag, lc)
            geo.synchronize()
            if crack_lines:
                gmsh.model.mesh.embed(1, crack_lines, 2, surf)
                named["crack"] = crack_lines

            fld = gmsh.model.mesh.field
            g = settings.growth
            hf, ht, hb = settings.flank_size, settings.tooth_size, settings.body_size
            mine = [j for j in offsets if (j == 0) == (part == "R")]
            fields = []
            if mine:
                flen = gear.outline(4, 4).involute[-1] - gear.outline(4, 4).involute[0]
                sampling = int(min(20000, max(100, 4 * np.hypot(*flen) * 3 / hf)))
                f1 = fld.add("Distance")
                fld.setNumbers(f1, "CurvesList", [named[f"flank{j}"][0] for j in mine])
                fld.setNumber(f1, "Sampling", sampling)
                t1 = fld.add("Threshold")
                fld.setNumber(t1, "InField", f1)
                fld.setNumber(t1, "SizeMin", hf)
                fld.setNumber(t1, "SizeMax", hb)
                fld.setNumber(t1, "DistMin", 2 * hf)
                fld.setNumber(t1, "DistMax", 2 * hf + (hb - hf) / (g - 1))
                tooth_curves = []
                for j in mine:
                    tooth_curves += named[f"flank{j}"] + named[f"tip{j}"] + named[f"fillet{j}"]
                f2 = fld.add("Distance")
                fld.setNumbers(f2, "CurvesList", tooth_curves)
                fld.setNumber(f2, "Sampling", 400)
                t2 = fld.add("Threshold")
                fld.setNumber(t2, "InField", f2)
                fld.setNumber(t2, "SizeMin", ht)
                fld.setNumber(t2, "SizeMax", hb)
                fld.setNumber(t2, "DistMin", gear.module)
                fld.setNumber(t2, "DistMax", gear.module + (hb - ht) / (g - 1))
                fields += [t1, t2]
            if crack_lines:
                f3 = fld.add("Distance")
                fld.setNumbers(f3, "PointsList", [p_tip])
                t3 = fld.add("Threshold")
                fld.setNumber(t3, "InField", f3)
                fld.setNumber(t3, "SizeMin", hf)
                fld.setNumber(t3, "SizeMax", hb)
                fld.setNumber(t3, "DistMin", 2 * hf)
                fld.setNumber(t3, "DistMax", 2 * hf + (hb - hf) / (g - 1))
                f4 = fld.add("Distance")
                fld.setNumbers(f4, "CurvesList", crack_lines)
                fld.setNumber(f4, "Sampling", 200)
                t4 = fld.add("Threshold")
                fld.setNumber(t4, "InField", f4)
                fld.setNumber(t4, "SizeMin", min(ht, 4 * hf))
                fld.setNumber(t4, "SizeMax", hb)
                fld.setNumber(t4, "DistMin", 0.0)
                fld.setNumber(t4, "DistMax", (hb - min(ht, 4 * hf)) / (g - 1) + hf)
                fields += [t3, t4]
            if fields:
                fmin = fld.add("Min")
                fld.setNumbers(fmin, "FieldsList", fields)
                fld.setAsBackgroundMesh(fmin)
            gmsh.model.mesh.generate(2)

            tags, coords, _ = gmsh.model.mesh.getNodes()
            index = np.full(int(tags.max()) + 1, -1, dtype=np.int64)
            index[tags.astype(np.int64)] = np.arange(tags.size)
            p = coords.reshape(-1, 3)[:, :2].T.copy()
            etypes, _, enodes = gmsh.model.mesh.getElements(2, surf)
            tri = None
            for et, en in zip(etypes, enodes, strict=True):
                if et == 2:
                    tri = index[en.astype(np.int64)].reshape(-1, 3).T.copy()
            if tri is None:
                raise NumericalError("gmsh produced no triangles for the body part")
            edges: dict[str, np.ndarray] = {}
            for name, tags_c in named.items():
                segs = []
                for c in tags_c:
                    et, _, en = gmsh.model.mesh.getElements(1, c)
                    for e, n in zip(et, en, strict=True):
                        if e == 1:
                            segs.append(index[n.astype(np.int64)].reshape(-1, 2).T)
                edges[name] = np.hstack(segs) if segs else np.zeros((2, 0), dtype=np.int64)
        finally:
            gmsh.finalize()

    used = np.zeros(p.shape[1], bool)
    used[tri.ravel()] = True
    new = np.cumsum(used) - 1
    p = p[:, used]
    tri = new[tri]
    edges = {k: new[v] for k, v in edges.items()}
    d1 = p[:, tri[1]] - p[:, tri[0]]
    d2 = p[:, tri[2]] - p[:, tri[0]]
    cw = d1[0] * d2[1] - d1[1] * d2[0] < 0
    tri[1:, cw] = tri[2:0:-1, cw]
    for j in mine:
        edges[f"flank{j}"] = _orient_by_radius(p, edges[f"flank{j}"])
    edges.setdefault("bore", np.zeros((2, 0), dtype=np.int64))
    if crack is not None:
        p, tri, plus, minus = split_body_crack(p, tri, edges.pop("crack"), gear, crack)
        edges["crack+"] = plus
        edges["crack-"] = minus
    return BodyMesh(p=p, t=tri, edges=edges, offsets=tuple(mine), gear=gear, crack=crack,
                    crack_mouth=mouth, crack_tip=tip, settings=settings,
                    info={"part": part, "r_gamma": r_g},
                    cut_radius=None if cut_radius is None else float(cut_radius))


def _match(xa: np.ndarray, xb: np.ndarray, scale: float, what: str) -> np.ndarray:
    """Index into ``xb`` (2, n) of each point of ``xa`` (2, m); coincidence to 1e-12 scale."""
    from scipy.spatial import cKDTree

    d, k = cKDTree(xb.T).query(xa.T)
    if d.size and d.max() > 1e-12 * scale:
        raise NumericalError(f"{what}: interface nodes differ by up to {d.max():.3g} m "
                             f"(allowed {1e-12 * scale:.3g} m)")
    return k


def glue_meshes(h: BodyMesh, r: BodyMesh) -> BodyMesh:
    """The whole-body mesh ``H + R`` (the ``Gamma`` nodes of ``R`` merged into those of ``H``)."""
    gh = np.unique(h.edges["gamma"])
    gr = np.unique(r.edges["gamma"])
    if gh.size != gr.size:
        raise NumericalError(f"interface node counts differ (H {gh.size}, R {gr.size})")
    k = _match(r.p[:, gr], h.p[:, gh], h.gear.tip_radius, "glue")
    nh = h.n_nodes
    new = np.full(r.n_nodes, -1, dtype=np.int64)
    new[gr] = gh[k]
    rest = np.setdiff1d(np.arange(r.n_nodes), gr)
    new[rest] = nh + np.arange(rest.size)
    p = np.hstack([h.p, r.p[:, rest]])
    t = np.hstack([h.t, new[r.t]])
    edges = {k_: v for k_, v in h.edges.items() if k_ != "gamma"}
    for k_, v in r.edges.items():
        if k_ not in ("gamma", "bore"):
            edges[k_] = new[v]
    offsets = tuple(sorted(set(h.offsets) | set(r.offsets)))
    return BodyMesh(p=p, t=t, edges=edges, offsets=offsets, gear=h.gear, crack=r.crack,
                    crack_mouth=r.crack_mouth, crack_tip=r.crack_tip, settings=h.settings,
                    info={"glued": True}, cut_radius=r.cut_radius)


def _gamma_dofs(body: ElasticBody) -> tuple[np.ndarray, np.ndarray]:
    """DOFs on ``Gamma`` (P2 vertex and midside, both components) and their locations [m]."""
    seg = body.mesh.edges["gamma"]
    fac = body.facet_index(seg)
    d = np.unique(np.concatenate([body.dof_basis.nodal_dofs[:, np.unique(seg)].ravel(),
                                  body.dof_basis.facet_dofs[:, fac].ravel()]))
    return d, body.dof_basis.doflocs[:, d]


def _component(body: ElasticBody, dofs: np.ndarray) -> np.ndarray:
    comp = np.full(body.n_dofs, -1)
    comp[body.dof_basis.nodal_dofs[0]] = 0
    comp[body.dof_basis.nodal_dofs[1]] = 1
    comp[body.dof_basis.facet_dofs[0]] = 0
    comp[body.dof_basis.facet_dofs[1]] = 1
    return comp[dofs]


class HealthySuperelement:
    r"""The healthy part ``H`` of a body condensed once onto ``Gamma``, with its flank loads.

    ``H`` (every DOF but those on ``Gamma``, the bore fixed) is condensed exactly onto the
    ``Gamma`` DOFs ``g``; its interior ``i`` includes the loaded flanks of its refined teeth, whose
    Hertzian patch loads ``F`` and normal-displacement readouts ``D`` are condensed with it:

    .. math:: S = K_{gg} - K_{gi} K_{ii}^{-1} K_{ig}, \quad
              G = F_g - K_{gi} K_{ii}^{-1} F_i,

    .. math:: D u = D_i K_{ii}^{-1} F_i\,\alpha + (D_g - D_i K_{ii}^{-1} K_{ig})\,u_g

    (``alpha`` the load amplitudes). This ties the superelement to the load points ``u`` and the
    patch half-width of its teeth. A fault then solves only ``R`` with ``S`` added on its
    ``Gamma`` block (:meth:`influence`).

    Parameters
    ----------
    gear : Gear
    material : ElasticMaterial
    settings : MeshSettings
        Element sizes [m] and refined teeth (tooth 0 lies in ``R``, the others in ``H``).
    u : ndarray
        Roll lengths of the load/readout points on the flanks of ``H``'s teeth [m].
    half_width : float
        Reference Hertz patch half-width ``b_ref`` [m].
    n_points : int
        Spline points per refined involute/fillet (as :func:`.mesh.build_body_mesh`).
    fraction : float
        Position of the ``Gamma`` arc between bore and root circle (:func:`interface_radius`).

    Attributes
    ----------
    S : ndarray, shape (n_g, n_g)
        Condensed stiffness of ``H`` on ``Gamma`` [N/m per m of width].
    offsets : tuple of int
        ``H``'s refined teeth.
    stats : dict
        DOFs and seconds (``t_mesh``, ``t_condense``).
    mesh, body : BodyMesh, ElasticBody or None
        ``H``'s mesh and body (``None`` after :meth:`load`).
    """

    def __init__(self, gear: Gear, material: ElasticMaterial, settings: MeshSettings,
                 u: np.ndarray, half_width: float, *, n_points: int = 150,
                 fraction: float = 0.5):
        from skfem import condense

        u = np.asarray(u, float)
        if u.ndim != 1 or u.size < 1 or not np.all(np.isfinite(u)):
            raise InputError("u", u.shape, "a 1-D array of finite roll lengths [m]")
        if not (math.isfinite(half_width) and half_width > 0):
            raise InputError("half_width", half_width, "a patch half-width > 0 [m]")
        t0 = time.perf_counter()
        self.gear, self.material, self.settings = gear, material, settings
        self.n_points, self.fraction = n_points, fraction
        self.H0 = None
        #: the cache key this superelement was stored under ("" when built directly)
        self.inputs_hash = ""
        self.u = u.copy()
        self.half_width = float(half_width)
        self.mesh = build_part_mesh(gear, settings, "H", n_points=n_points, fraction=fraction)
        t_mesh = time.perf_counter() - t0
        body = ElasticBody(self.mesh, material)
        self.body = body
        self.gamma, self.gamma_x = _gamma_dofs(body)
        self.gamma_c = _component(body, self.gamma)
        if np.intersect1d(self.gamma, body.fixed).size:
            raise NumericalError("an interface DOF lies on the fixed bore")
        interior = np.setdiff1d(body.free, self.gamma)
        K = body.K.tocsr()
        kii = condense(K, D=np.setdiff1d(np.arange(body.n_dofs), interior),
                       expand=False).tocsc()
        lu = factorise(kii)
        teeth = self.mesh.offsets
        F = np.hstack([body.patch_loads(j, self.u, self.half_width) for j in teeth])
        D = np.vstack([body.readout(j, self.u).toarray() for j in teeth])
        rhs = np.hstack([K[interior][:, self.gamma].toarray(), F[interior]])
        x = lu.solve(rhs)
        ng = self.gamma.size
        kgi = K[self.gamma][:, interior]
        S = K[self.gamma][:, self.gamma].toarray() - kgi @ x[:, :ng]
        #: condensed stiffness on Gamma [N/m per m]
        self.S = 0.5 * (S + S.T)
        #: condensed patch loads on Gamma, one column per load of H's teeth [N/m per m]
        self.G = F[self.gamma] - kgi @ x[:, ng:]
        d_i = D[:, interior]
        #: readouts of H's teeth from the Gamma displacements [-]
        self.DX = D[:, self.gamma] - d_i @ x[:, :ng]
        #: readouts of H's teeth under H's own loads with Gamma clamped [m^2/N]
        self.DY = d_i @ x[:, ng:]
        #: H's refined teeth (model tooth offsets; tooth 0 lies in R)
        self.offsets = tuple(int(j) for j in teeth)
        self.stats = {"nodes_H": self.mesh.n_nodes, "dofs_H": body.n_dofs,
                      "gamma_dofs": int(ng), "t_mesh_H": t_mesh,
                      "t_condense_H": time.perf_counter() - t0 - t_mesh, "solver_H": lu.solver}

    _ARRAYS = ("S", "G", "DX", "DY", "gamma_x", "gamma_c", "u")

    def reference(self) -> np.ndarray:
        """Influence coefficients ``H`` of the unfaulted glued body ``H + R`` [m^2/N], loaded on
        every refined tooth (:meth:`influence` without a fault); computed once, kept (and stored
        by :meth:`save`). A fault's change of ``H`` is its :meth:`influence` minus this."""
        if getattr(self, "H0", None) is None:
            self.H0 = self.influence()[0].H
        return self.H0

    def save(self, path) -> None:
        """Write the condensed arrays to ``.npz`` (no pickle; not the mesh of ``H``)."""
        stats = stats_to_array(self.stats)
        with open(path, "wb") as fh:
            np.savez(fh, **{k: getattr(self, k) for k in self._ARRAYS},
                     n_gamma=np.int64(self.gamma.size), offsets=np.asarray(self.offsets),
                     half_width=self.half_width, n_points=np.int64(self.n_points),
                     fraction=self.fraction, stats=stats, inputs_hash=np.array(self.inputs_hash),
                     **({} if getattr(self, "H0", None) is None else {"H0": self.H0}))

    @classmethod
    def load(cls, path, gear: Gear, material: ElasticMaterial,
             settings: MeshSettings) -> HealthySuperelement:
        """Read a file written by :meth:`save` for ``gear``, ``material`` and ``settings`` (the
        caller's cache key vouches that they are the ones it was built with). The mesh and body
        of ``H`` are not stored: ``mesh`` and ``body`` are ``None``."""
        self = cls.__new__(cls)
        with np.load(path, allow_pickle=False) as d:
            for k in cls._ARRAYS:
                setattr(self, k, d[k].copy())
            self.gamma = np.arange(int(d["n_gamma"]))  # only its size is used by influence()
            self.offsets = tuple(int(v) for v in d["offsets"])
            self.half_width = float(d["half_width"])
            self.n_points = int(d["n_points"])
            self.fraction = float(d["fraction"])
            self.stats = stats_from_array(d["stats"])
            self.inputs_hash = str(d["inputs_hash"])
            self.H0 = d["H0"].copy() if "H0" in d.files else None
        self.gear, self.material, self.settings = gear, material, settings
        self.mesh = self.body = None
        return self

    def influence(self, *, crack: CrackGeometry | None = None,
                  cut_radius: float | None = None, load_offsets: tuple[int, ...] | None = None,
                  u0: np.ndarray | None = None) -> tuple[BodyInfluence, BodyMesh]:
        """Influence coefficients of the body with a new fault in ``R`` (``H`` not re-solved).

        The meaning of :func:`.solve.influence_matrices` on the glued mesh (:func:`glue_meshes`),
        at the superelement's points ``u`` and patch half-width.

        Parameters
        ----------
        crack : CrackGeometry, optional
            Root crack of model tooth 0.
        cut_radius : float, optional
            Breakage: tooth 0 ends at this radius [m].
        load_offsets : tuple of int, optional
            Teeth loaded (default every refined tooth).
        u0 : ndarray, optional
            Roll lengths of the points on tooth 0 [m] (same count as ``u``; a broken tooth's
            flank); default ``u``.

        Returns
        -------
        (BodyInfluence, BodyMesh)
            The coefficients and the mesh of ``R`` used.
        """
        t0 = time.perf_counter()
        rmesh = build_part_mesh(self.gear, self.settings, "R", crack=crack,
                                cut_radius=cut_radius, n_points=self.n_points,
                                fraction=self.fraction)
        t_mesh = time.perf_counter() - t0
        rb = ElasticBody(rmesh, self.material)
        g_r, x_r = _gamma_dofs(rb)
        c_r = _component(rb, g_r)
        if g_r.size != self.gamma.size:
            raise NumericalError(f"interface DOF counts differ (H {self.gamma.size}, "
                                 f"R {g_r.size})")
        # R's Gamma DOF matching each of H's (same location and same component)
        shift = 10.0 * self.gear.tip_radius
        gam_r = g_r[_match(self.gamma_x + shift * self.gamma_c[None, :],
                           x_r + shift * c_r[None, :], self.gear.tip_radius, "substructure")]
        ng = gam_r.size
        rows = np.repeat(gam_r, ng)
        cols = np.tile(gam_r, ng)
        K = (rb.K + sp.csr_matrix((self.S.ravel(), (rows, cols)),
                                  shape=rb.K.shape)).tocsc()
        lu = factorise(K)
        t_factor = time.perf_counter() - t0 - t_mesh

        teeth_h = self.offsets
        offsets = tuple(sorted(set(teeth_h) | set(rmesh.offsets)))
        loads = offsets if load_offsets is None else tuple(load_offsets)
        for i in loads:
            if i not in offsets:
                raise InputError("load_offsets", i, f"refined teeth {offsets}")
        u = self.u
        u0 = u if u0 is None else np.asarray(u0, float)
        if u0.shape != u.shape:
            raise InputError("u0", u0.shape, f"as many roll lengths as u ({u.size})")
        n = u.size
        read_r = rb.readout(0, u0)
        H = np.empty((len(loads), len(offsets), n, n))
        jr = offsets.index(0)
        h_rows = [offsets.index(j) for j in teeth_h]
        for a, i in enumerate(loads):
            if i == 0:
                f = rb.patch_loads(0, u0, self.half_width)
            else:
                k = teeth_h.index(i)
                f = np.zeros((rb.n_dofs, n))
                f[gam_r] = self.G[:, k * n:(k + 1) * n]
            x = lu.solve(f)
            H[a, jr] = read_r @ x
            dh = self.DX @ x[gam_r]
            if i != 0:
                dh = dh + self.DY[:, k * n:(k + 1) * n]
            for m, jj in enumerate(h_rows):
                H[a, jj] = dh[m * n:(m + 1) * n]
        stats = {"nodes_R": rmesh.n_nodes, "dofs_R": rb.n_dofs, "t_mesh_R": t_mesh,
                 "t_factor_R": t_factor, "t_total_R": time.perf_counter() - t0,
                 "solver_R": lu.solver, **self.stats}
        u_teeth = None
        if u0 is not u:
            u_teeth = np.stack([u0 if j == 0 else u for j in offsets])
        inf = BodyInfluence(u=u, load_offsets=loads, read_offsets=offsets, H=H,
                            half_width=self.half_width,
                            plane_modulus=self.material.plane_modulus, stats=stats,
                            u_teeth=u_teeth)
        return inf, rmesh
