r"""Plane meshes with a sharp crack (a slit along a polyline) and a small plane-elasticity solve.

What this module gives the fracture tools of :mod:`.sif`:

* :func:`mesh_cracked_polygon` meshes a polygon (gmsh, linear triangles) with a crack polyline
  embedded as mesh edges, graded from ``tip_size`` at the crack tip(s) to ``size`` far away;
* :func:`split_crack` then duplicates the crack nodes (all but the tips) so the two faces are free,
  for any polyline: the triangles around each crack node are split into the two fans the crack
  edges separate (a topological split, no side test against one crack direction, so a kinked
  grown crack splits as cleanly as a straight one);
* :func:`edge_crack_strip` and :func:`centre_crack_plate` build the two test specimens (single
  edge crack in a strip; inclined centre crack in a plate) and :func:`solve_tractions` solves them
  under prescribed end tractions with the rigid-body motion removed by three pinned DOFs.

The element is the one of :mod:`.solve`: quadratic triangles (``ElementVector(ElementTriP2())``)
on the linear mesh, plane strain or plane stress (:class:`.solve.ElasticMaterial`). No
quarter-point elements are used; the stress intensity factors are extracted with a domain
(interaction) integral that does not need them (:mod:`.sif`).

References
----------
Geuzaine, C. & Remacle, J.-F. (2009). Gmsh: a 3-D finite element mesh generator with built-in
pre- and post-processing facilities. Int. J. Numer. Meth. Engng 79(11):1309-1331.
Gustafsson, T. & McBain, G. D. (2020). scikit-fem: a Python package for finite element assembly.
J. Open Source Softw. 5(52):2369.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from ...errors import InputError, NumericalError
from .mesh import _GMSH_LOCK, _initialize_gmsh
from .solve import ElasticMaterial

__all__ = ["CrackedMesh", "mesh_cracked_polygon", "split_crack", "edge_crack_strip",
           "centre_crack_plate", "solve_plane", "solve_tractions", "PlaneSolution"]


@dataclass(frozen=True)
class CrackedMesh:
    """A linear triangle mesh with a split (two-faced) crack.

    Attributes
    ----------
    p : ndarray, shape (2, n_nodes)
        Node coordinates [m].
    t : ndarray, shape (3, n_triangles)
        Counter-clockwise triangles.
    crack : ndarray, shape (m, 2)
        Crack polyline [m], from its first point (the mouth, on the boundary, for an edge crack)
        to its last point (a tip).
    tips : tuple of int
        Node indices of the crack tips (not duplicated).
    tip_points : ndarray, shape (k, 2)
        Tip coordinates [m] (same order as ``tips``).
    edges : dict of str -> ndarray, shape (2, n)
        Named boundary segments (node pairs), e.g. ``"top"``, ``"bottom"`` of a specimen;
        ``"crack+"`` and ``"crack-"``: the two crack faces (the ``+`` face on the left of the
        polyline's direction).
    info : dict
        Element sizes [m] and counts.
    """

    p: np.ndarray
    t: np.ndarray
    crack: np.ndarray
    tips: tuple[int, ...]
    tip_points: np.ndarray
    edges: dict[str, np.ndarray]
    info: dict = field(default_factory=dict)

    @property
    def n_nodes(self) -> int:
        """Number of mesh vertices."""
        return self.p.shape[1]

    def tip_direction(self, k: int = -1) -> np.ndarray:
        """Unit vector of crack advance at the last tip (``k = -1``) or the first (``k = 0``),
        along the polyline's end segment [-]."""
        c = self.crack
        d = c[-1] - c[-2] if k == -1 else c[0] - c[1]
        return d / np.hypot(*d)


def _check_polyline(crack: np.ndarray) -> np.ndarray:
    crack = np.asarray(crack, float)
    if crack.ndim != 2 or crack.shape[1] != 2 or crack.shape[0] < 2:
        raise InputError("crack", crack.shape, "a polyline of at least two (x, y) points")
    seg = np.hypot(*np.diff(crack, axis=0).T)
    if not np.all(np.isfinite(crack)) or np.any(seg <= 0):
        raise InputError("crack", "polyline", "finite points with no zero-length segment")
    return crack


def mesh_cracked_polygon(outline: np.ndarray, crack: np.ndarray, *, tip_size: float,
                         size: float, growth: float = 1.2, edge_crack: bool = True,
                         names: dict[str, int | list[int]] | None = None,
                         crack_size: float | None = None,
                         refine: list[tuple[np.ndarray, float]] | None = None) -> CrackedMesh:
    """Mesh a polygon with an embedded crack polyline, then split the crack (gmsh, 2-D).

    Parameters
    ----------
    outline : ndarray, shape (n, 2)
        Polygon vertices, counter-clockwise [m]. For an edge crack the crack mouth
        ``crack[0]`` must be one of them.
    crack : ndarray, shape (m, 2)
        Crack polyline [m]: from the mouth to the tip (edge crack) or from one tip to the other
        (interior crack, ``edge_crack=False``).
    tip_size : float
        Element size at the tip(s) [m].
    size : float
        Element size far from the crack [m].
    growth : float
        Largest size ratio of neighbouring elements in the graded zone [-].
    edge_crack : bool
        ``True``: ``crack[0]`` is on the boundary (one tip, ``crack[-1]``); ``False``: both
        ends are tips.
    names : dict of str -> int or list of int, optional
        Boundary segment names: ``name -> i`` (or a list of such ``i``) for the polygon side(s)
        from vertex ``i`` to ``i + 1``; returned in :attr:`CrackedMesh.edges`.
    crack_size : float, optional
        Element size along the crack faces away from the tip [m] (default ``4 tip_size``,
        at most ``size``).
    refine : list of (point, size), optional
        Extra graded refinement: element ``size`` [m] within ``2 size`` of ``point`` [m].

    Returns
    -------
    CrackedMesh
    """
    import gmsh

    outline = np.asarray(outline, float)
    crack = _check_polyline(crack)
    for name, v in (("tip_size", tip_size), ("size", size)):
        if not (math.isfinite(v) and v > 0):
            raise InputError(name, v, "an element size > 0 [m]")
    if tip_size > size:
        raise InputError("tip_size", tip_size, f"at most size ({size:g} m)")
    if not 1.05 <= growth <= 2.0:
        raise InputError("growth", growth, "a size ratio in [1.05, 2]")
    hc = min(size, 4 * tip_size) if crack_size is None else crack_size
    n = outline.shape[0]
    mouth_vertex = None
    if edge_crack:
        d = np.hypot(*(outline - crack[0]).T)
        mouth_vertex = int(np.argmin(d))
        if d[mouth_vertex] > 1e-9 * max(1.0, float(np.abs(outline).max())):
            raise InputError("crack", crack[0].tolist(), "an edge crack whose mouth is a "
                             "vertex of the outline")
    tip_pts = [crack[-1]] if edge_crack else [crack[0], crack[-1]]
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
            gmsh.model.add("cracked")
            geo = gmsh.model.geo
            pts = [geo.addPoint(float(x), float(y), 0.0, size) for x, y in outline]
            lines = [geo.addLine(pts[i], pts[(i + 1) % n]) for i in range(n)]
            loop = geo.addCurveLoop(lines)
            surf = geo.addPlaneSurface([loop])
            cpts = []
            for k, q in enumerate(crack):
                if k == 0 and edge_crack:
                    cpts.append(pts[mouth_vertex])
                else:
                    cpts.append(geo.addPoint(float(q[0]), float(q[1]), 0.0, size))
            clines = [geo.addLine(cpts[k], cpts[k + 1]) for k in range(len(cpts) - 1)]
            geo.synchronize()
            gmsh.model.mesh.embed(1, clines, 2, surf)
            fld = gmsh.model.mesh.field
            f1 = fld.add("Distance")
            tip_tags = [cpts[-1]] if edge_crack else [cpts[0], cpts[-1]]
            fld.setNumbers(f1, "PointsList", tip_tags)
            t1 = fld.add("Threshold")
            fld.setNumber(t1, "InField", f1)
            fld.setNumber(t1, "SizeMin", tip_size)
            fld.setNumber(t1, "SizeMax", size)
            fld.setNumber(t1, "DistMin", 2 * tip_size)
            fld.setNumber(t1, "DistMax", 2 * tip_size + (size - tip_size) / (growth - 1))
            f2 = fld.add("Distance")
            fld.setNumbers(f2, "CurvesList", clines)
            fld.setNumber(f2, "Sampling", 400)
            t2 = fld.add("Threshold")
            fld.setNumber(t2, "InField", f2)
            fld.setNumber(t2, "SizeMin", hc)
            fld.setNumber(t2, "SizeMax", size)
            fld.setNumber(t2, "DistMin", 0.0)
            fld.setNumber(t2, "DistMax", (size - hc) / (growth - 1) + hc)
            extra = []
            for q, hq in refine or ():
                if not (math.isfinite(hq) and 0 < hq <= size):
                    raise InputError("refine", hq, f"an element size in (0, {size:g}] m")
                pq = geo.addPoint(float(q[0]), float(q[1]), 0.0, size)
                geo.synchronize()
                fq = fld.add("Distance")
                fld.setNumbers(fq, "PointsList", [pq])
                tq = fld.add("Threshold")
                fld.setNumber(tq, "InField", fq)
                fld.setNumber(tq, "SizeMin", hq)
                fld.setNumber(tq, "SizeMax", size)
                fld.setNumber(tq, "DistMin", 2 * hq)
                fld.setNumber(tq, "DistMax", 2 * hq + (size - hq) / (growth - 1))
                extra.append(tq)
            fmin = fld.add("Min")
            fld.setNumbers(fmin, "FieldsList", [t1, t2, *extra])
            fld.setAsBackgroundMesh(fmin)
            gmsh.model.mesh.generate(2)

            tags, coords, _ = gmsh.model.mesh.getNodes()
            index = np.full(int(tags.max()) + 1, -1, dtype=np.int64)
            index[tags.astype(np.int64)] = np.arange(tags.size)
            p = coords.reshape(-1, 3)[:, :2].T.copy()
            tri = None
            for et, en in zip(*gmsh.model.mesh.getElements(2, surf)[::2], strict=True):
                if et == 2:
                    tri = index[en.astype(np.int64)].reshape(-1, 3).T.copy()
            if tri is None:
                raise NumericalError("gmsh produced no triangles")

            def segs_of(curves):
                out = []
                for c in curves:
                    et, _, en = gmsh.model.mesh.getElements(1, c)
                    for e, nn in zip(et, en, strict=True):
                        if e == 1:
                            out.append(index[nn.astype(np.int64)].reshape(-1, 2).T)
                return np.hstack(out) if out else np.zeros((2, 0), np.int64)

            crack_edges = segs_of(clines)
            edges = {name: segs_of([lines[k] for k in np.atleast_1d(i).tolist()])
                     for name, i in (names or {}).items()}
            tip_nodes = []
            for q in tip_pts:
                k = int(np.argmin(np.hypot(*(p - q[:, None]))))
                tip_nodes.append(k)
        finally:
            gmsh.finalize()

    used = np.zeros(p.shape[1], bool)
    used[tri.ravel()] = True
    new = np.cumsum(used) - 1
    p = p[:, used]
    tri = new[tri]
    crack_edges = new[crack_edges]
    edges = {k: new[v] for k, v in edges.items()}
    tip_nodes = [int(new[k]) for k in tip_nodes]
    d1 = p[:, tri[1]] - p[:, tri[0]]
    d2 = p[:, tri[2]] - p[:, tri[0]]
    cw = d1[0] * d2[1] - d1[1] * d2[0] < 0
    tri[1:, cw] = tri[2:0:-1, cw]
    p, tri, plus, minus = split_crack(p, tri, crack_edges, tip_nodes, crack)
    edges["crack+"] = plus
    edges["crack-"] = minus
    info = {"tip_size": float(tip_size), "size": float(size), "growth": float(growth),
            "nodes": int(p.shape[1]), "triangles": int(tri.shape[1])}
    return CrackedMesh(p=p, t=tri, crack=crack, tips=tuple(tip_nodes),
                       tip_points=np.array(tip_pts), edges=edges, info=info)


def _left_of(polyline: np.ndarray, pts: np.ndarray) -> np.ndarray:
    """Signed distance-like side of points ``pts`` (n, 2) to the polyline: > 0 on its left
    (the left normal of the nearest segment)."""
    a = polyline[:-1]
    b = polyline[1:]
    d = b - a
    L2 = np.sum(d * d, axis=1)
    rel = pts[:, None, :] - a[None, :, :]
    s = np.clip(np.sum(rel * d[None], axis=2) / L2[None], 0.0, 1.0)
    foot = a[None] + s[..., None] * d[None]
    dist = np.hypot(*(pts[:, None, :] - foot).transpose(2, 0, 1))
    k = np.argmin(dist, axis=1)
    dk = d[k]
    rk = pts - a[k]
    return dk[:, 0] * rk[:, 1] - dk[:, 1] * rk[:, 0]


def _find(parent: dict[int, int], x: int) -> int:
    """Root of ``x`` in a union-find forest (with path halving)."""
    while parent[x] != x:
        parent[x] = parent[parent[x]]
        x = parent[x]
    return x


def split_crack(p: np.ndarray, t: np.ndarray, crack_edges: np.ndarray, tips,
                crack: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """Duplicate the nodes of a crack (all but its tips) so its two faces are free.

    For each crack node the triangles around it fall in two groups that the crack edges through
    the node separate (found by walking across the node's non-crack edges). The group on the
    left of the crack polyline keeps the node, the other gets a copy. This is topological and
    holds for a kinked polyline.

    Parameters
    ----------
    p, t : mesh (2, n) [m] and (3, n_t)
    crack_edges : ndarray, shape (2, m)
        Mesh edges (node pairs) lying on the crack.
    tips : sequence of int
        Tip nodes (kept shared).
    crack : ndarray, shape (k, 2)
        The crack polyline [m] (only to name the faces: ``+`` on its left).

    Returns
    -------
    p, t : the split mesh
    plus, minus : ndarray, shape (2, m)
        The crack edges on the ``+`` (left) face and the matching edges of the ``-`` face.
    """
    tips = set(int(k) for k in tips)
    cset = {(min(a, b), max(a, b)) for a, b in crack_edges.T.tolist()}
    nodes = [v for v in np.unique(crack_edges).tolist() if v not in tips]
    n0 = p.shape[1]
    # triangles by node
    order = np.argsort(t.ravel(), kind="stable")  # flat positions row * n_t + triangle
    tri_of = order
    flat_nodes = t.ravel()[order]
    starts = np.searchsorted(flat_nodes, np.arange(n0))
    ends = np.searchsorted(flat_nodes, np.arange(n0), side="right")
    n_t = t.shape[1]
    cent = p[:, t].mean(axis=1).T  # (n_t, 2)
    side = _left_of(crack, cent)
    t = t.copy()
    copies = {}
    new_pts = []
    for v in nodes:
        tris = np.unique(tri_of[starts[v]:ends[v]] % n_t)
        # adjacency across non-crack edges through v
        others = {}
        for ti in tris.tolist():
            ws = [w for w in t[:, ti].tolist() if w != v]
            for w in ws:
                if (min(v, w), max(v, w)) in cset:
                    continue
                others.setdefault(w, []).append(ti)
        parent = {ti: ti for ti in tris.tolist()}
        for group in others.values():
            for a, b in zip(group[:-1], group[1:], strict=True):
                parent[_find(parent, a)] = _find(parent, b)
        comps: dict[int, list[int]] = {}
        for ti in tris.tolist():
            comps.setdefault(_find(parent, ti), []).append(ti)
        if len(comps) != 2:
            raise NumericalError(f"crack node {v} at {p[:, v].tolist()} does not split the mesh "
                                 f"into two faces ({len(comps)} groups of triangles)")
        groups = list(comps.values())
        s = [float(np.mean(side[g])) for g in groups]
        minus_group = groups[0] if s[0] < s[1] else groups[1]
        k = n0 + len(new_pts)
        copies[v] = k
        new_pts.append(p[:, v])
        for ti in minus_group:
            t[t[:, ti] == v, ti] = k
    p = np.hstack([p, np.array(new_pts).T]) if new_pts else p
    plus = crack_edges.copy()
    minus = np.vectorize(lambda a: copies.get(int(a), int(a)))(crack_edges)
    return p, t, plus, minus


def edge_crack_strip(width: float, a: float, *, half_height: float | None = None,
                     tip_size: float, size: float | None = None,
                     growth: float = 1.2) -> CrackedMesh:
    """Single-edge-cracked strip: ``0 <= x <= width``, ``|y| <= half_height``, a crack from
    ``(0, 0)`` to ``(a, 0)`` [m]. Edges ``"top"`` (``y = h``) and ``"bottom"`` (``y = -h``).

    Parameters
    ----------
    width : float
        Strip width ``b`` [m].
    a : float
        Crack length [m], ``0 < a < width``.
    half_height : float, optional
        Half the strip length ``h`` [m] (default ``2 width``: the ends far enough for the
        handbook's remote tension, see the test).
    tip_size, size : float
        Element sizes at the tip and far away [m] (``size`` default ``width / 8``).
    """
    if not 0 < a < width:
        raise InputError("a", a, f"a crack length in (0, {width:g}) m")
    h = 2 * width if half_height is None else half_height
    size = width / 8 if size is None else size
    outline = np.array([[0.0, -h], [width, -h], [width, h], [0.0, h], [0.0, 0.0]])
    return mesh_cracked_polygon(outline, np.array([[0.0, 0.0], [a, 0.0]]), tip_size=tip_size,
                                size=size, growth=growth, names={"bottom": 0, "top": 2})


def centre_crack_plate(half_width: float, a: float, beta: float, *, tip_size: float,
                       size: float | None = None, growth: float = 1.2) -> CrackedMesh:
    """Square plate ``|x|, |y| <= half_width`` with a centre crack of half-length ``a`` at angle
    ``beta`` [rad] to the ``x`` axis: under tension along ``y`` (edges ``"top"`` and
    ``"bottom"``), ``beta = 0`` is pure mode I. The crack runs from ``-a (cos beta, sin beta)``
    to ``+a (cos beta, sin beta)``; the second end is ``tips[1]`` (``tip=-1`` in
    :func:`~.sif.stress_intensity`).
    """
    if not 0 < a < 0.5 * half_width:
        raise InputError("a", a, f"a half-length in (0, {0.5 * half_width:g}) m")
    w = half_width
    size = w / 6 if size is None else size
    d = np.array([math.cos(beta), math.sin(beta)])
    outline = np.array([[-w, -w], [w, -w], [w, w], [-w, w]])
    return mesh_cracked_polygon(outline, np.array([-a * d, a * d]), tip_size=tip_size,
                                size=size, growth=growth, edge_crack=False,
                                names={"bottom": 0, "top": 2})


@dataclass(frozen=True)
class PlaneSolution:
    """A solved plane-elasticity problem (P2 displacements on a :class:`CrackedMesh`).

    Attributes
    ----------
    mesh : CrackedMesh
    material : ElasticMaterial
    basis : skfem.Basis
        ``ElementVector(ElementTriP2())`` basis of the mesh.
    u : ndarray, shape (n_dofs,)
        Displacement DOFs [m].
    """

    mesh: CrackedMesh
    material: ElasticMaterial
    basis: object
    u: np.ndarray

    def nodal_displacements(self) -> np.ndarray:
        """Displacements at the mesh vertices, shape (2, n_nodes) [m]."""
        return self.u[self.basis.nodal_dofs]


def _facets_of(m, seg: np.ndarray, name: str) -> np.ndarray:
    n = m.p.shape[1]
    fkeys = np.minimum(m.facets[0], m.facets[1]).astype(np.int64) * n + np.maximum(*m.facets)
    order = np.argsort(fkeys)
    keys = np.minimum(seg[0], seg[1]).astype(np.int64) * n + np.maximum(seg[0], seg[1])
    pos = np.searchsorted(fkeys[order], keys)
    fac = order[np.clip(pos, 0, order.size - 1)]
    if np.any(fkeys[fac] != keys):
        raise NumericalError(f"edge {name!r} not found among the mesh facets")
    return fac


def solve_plane(mesh: CrackedMesh, material: ElasticMaterial, *,
                tractions: dict[str, tuple[float, float]] | None = None,
                masks: dict[str, np.ndarray] | None = None, fixed: tuple[str, ...] = (),
                pin: bool = False) -> PlaneSolution:
    """Solve plane elasticity (P2) on a :class:`CrackedMesh`.

    Parameters
    ----------
    mesh : CrackedMesh
    material : ElasticMaterial
    tractions : dict of str -> (tx, ty), optional
        Uniform traction [Pa] on the named edges.
    masks : dict of str -> ndarray of bool, optional
        Load only the segments of a named edge where the mask (one entry per segment of
        ``mesh.edges[name]``) is true.
    fixed : tuple of str
        Named edges clamped (both components, every DOF on them).
    pin : bool
        Remove the rigid-body motion by pinning the node nearest the lower-left corner (both
        components) and the node nearest the lower-right corner (``y``) instead; the loads must
        then balance (the pins carry no reaction).

    Returns
    -------
    PlaneSolution
    """
    from scipy.sparse.linalg import spsolve
    from skfem import Basis, ElementTriP2, ElementVector, FacetBasis, LinearForm, MeshTri, asm, condense
    from skfem.models.elasticity import linear_elasticity

    m = MeshTri(np.ascontiguousarray(mesh.p, float), np.ascontiguousarray(mesh.t))
    e = ElementVector(ElementTriP2())
    basis = Basis(m, e, intorder=4)
    lam, mu = material.lame
    K = asm(linear_elasticity(lam, mu), basis).tocsr()
    f = np.zeros(basis.N)
    for name, spec in (tractions or {}).items():
        if name not in mesh.edges:
            raise InputError("tractions", name, f"a named edge: {sorted(mesh.edges)}")
        seg = mesh.edges[name]
        if name in (masks or {}):
            seg = seg[:, np.asarray(masks[name], bool)]
        tx, ty = spec
        fb = FacetBasis(m, e, facets=_facets_of(m, seg, name), intorder=4)

        @LinearForm
        def load(v, w, tx=tx, ty=ty):
            return tx * v[0] + ty * v[1]

        f += asm(load, fb)
    dofs = []
    for name in fixed:
        if name not in mesh.edges:
            raise InputError("fixed", name, f"a named edge: {sorted(mesh.edges)}")
        dofs.append(basis.get_dofs(facets=_facets_of(m, mesh.edges[name], name)).all())
    if pin:
        lo = np.array([mesh.p[0].min(), mesh.p[1].min()])
        hi = np.array([mesh.p[0].max(), mesh.p[1].min()])
        k0 = int(np.argmin(np.hypot(*(mesh.p - lo[:, None]))))
        k1 = int(np.argmin(np.hypot(*(mesh.p - hi[:, None]))))
        nd = basis.nodal_dofs
        dofs.append(np.array([nd[0, k0], nd[1, k0], nd[1, k1]]))
    if not dofs:
        raise InputError("fixed", fixed, "at least one clamped edge, or pin=True")
    D = np.unique(np.concatenate(dofs))
    u = np.zeros(basis.N)
    A, b, _, I = condense(K, f, D=D)
    u[I] = spsolve(A.tocsc(), b)
    return PlaneSolution(mesh=mesh, material=material, basis=basis, u=u)


def solve_tractions(mesh: CrackedMesh, material: ElasticMaterial,
                    tractions: dict[str, tuple[float, float]]) -> PlaneSolution:
    """Solve plane elasticity under self-equilibrated uniform tractions on named edges
    (:func:`solve_plane` with ``pin=True``).

    Parameters
    ----------
    mesh : CrackedMesh
    material : ElasticMaterial
    tractions : dict of str -> (tx, ty)
        Uniform traction vector [Pa] on each named edge. The loads must balance; the rigid-body
        motion is removed by three pinned DOFs that then carry no reaction.

    Returns
    -------
    PlaneSolution
    """
    return solve_plane(mesh, material, tractions=tractions, pin=True)
