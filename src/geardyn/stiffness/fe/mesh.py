r"""Finite-element meshes of whole gear bodies from the rack-generated tooth outline (gmsh).

Each body is the whole gear, from the bore to the tips, with every tooth drawn from
:meth:`geardyn.geometry.Gear.outline` (involute and trochoid fillet as splines through the generated
points, tip and root circle arcs). The teeth near the loaded one (``teeth_in_model`` of them) get a
graded mesh: a fine size along their loaded involute (the contact zone) growing to a tooth size
inside them and to a body size in the rest of the gear. The whole gear, not a sector, is modelled
so that the torsion of the body down to the bore, which enters the paper's combined torsional mesh
stiffness (Xue & Howard 2018, section 3), is that of the real annulus.

Body frame and conventions
--------------------------
* Gear centre at the origin; model tooth ``j`` (``j = 0`` the central tooth, negative ``j``
  clockwise) is centred on the direction at angle ``pi/2 + 2 pi j / z`` from ``+x``.
* The **loaded flank** is the counter-clockwise side of each tooth (``x < 0`` for tooth 0). In the
  frame of :mod:`geardyn.geometry` both the driving pinion (turning counter-clockwise) and the
  driven gear (turning clockwise) carry the mesh force on that side, so one body model serves both.
* A root crack (optional) starts on the loaded-side fillet of model tooth 0, at the ISO 6336-3
  critical point where the fillet tangent makes 30 deg with the tooth centreline, and runs
  ``depth`` into the tooth at ``angle`` to the centreline, towards the centreline and the gear
  centre (the tip is ``depth sin(angle)`` nearer the centreline than the mouth). It is a true
  discontinuity: the nodes on the crack line, except the tip, are duplicated so the two faces are
  free (LEFM). The mesh is refined around the crack tip.
* A tooth breakage (optional, :mod:`geardyn.faults.breakage`) removes the tip of model tooth 0
  above the radius ``r_a - Delta h``: that tooth is meshed with its involutes ending at that radius
  and a circular arc of that radius as its tip (the cut), so its loaded flank (``"flank0"``) ends
  at the cut.

References
----------
Geuzaine, C. & Remacle, J.-F. (2009). Gmsh: a 3-D finite element mesh generator with built-in pre-
and post-processing facilities. Int. J. Numer. Meth. Engng 79(11):1309-1331.
ISO 6336-3:2019, Calculation of load capacity of spur and helical gears - Part 3: tooth bending
strength (30 deg tangent critical section).
"""

from __future__ import annotations

import math
import threading
from dataclasses import dataclass, field

import numpy as np

from ...errors import InputError, NumericalError
from ...geometry import Gear

__all__ = ["MeshSettings", "CrackGeometry", "BodyMesh", "build_body_mesh", "loaded_flank",
           "critical_fillet_point", "crack_segment", "crack_polyline", "tooth_offsets", "cut_flank",
           "check_cut"]

#: Serialises every use of gmsh in this process. gmsh keeps one global model and is not
#: thread-safe: two threads meshing at once (a Dask worker with several threads, say) crash the
#: process. Held from ``gmsh.initialize`` to ``gmsh.finalize``.
_GMSH_LOCK = threading.Lock()


def _initialize_gmsh() -> None:
    """``gmsh.initialize`` for one mesh (one thread, no configuration files, Ctrl-C left to
    Python), with Python's ``SIGPIPE`` disposition put back afterwards.

    gmsh's initialisation sets ``SIGPIPE`` to its default action (measured with gmsh 4.15.2:
    ``sigaction`` reports ``SIG_IGN`` before ``gmsh.initialize`` and ``SIG_DFL`` after it, also
    after ``gmsh.finalize``; no other signal changes), while Python ignores it "so write errors
    on pipes and sockets can be reported as ordinary Python exceptions" (Python's ``signal``
    module documentation, *General rules*). After a mesh, a write to a closed pipe killed the
    whole process without a word: ``geardyn stiffness ... | head -1``, or the queue feeding a
    second process that has died (``geardyn.studies.figure_process``). Call it holding
    :data:`_GMSH_LOCK`.
    """
    import signal

    import gmsh

    gmsh.initialize(["", "-nt", "1"], readConfigFiles=False, interruptible=False)
    if hasattr(signal, "SIGPIPE") and signal.getsignal(signal.SIGPIPE) == signal.SIG_IGN:
        _ignore_sigpipe()


def _ignore_sigpipe() -> None:
    """Set ``SIGPIPE`` to ``SIG_IGN`` for the process: through :func:`signal.signal` in the
    main thread, through the C library's ``signal`` in another (where Python refuses)."""
    import signal
    import threading

    if threading.current_thread() is threading.main_thread():
        signal.signal(signal.SIGPIPE, signal.SIG_IGN)
        return
    import ctypes

    libc = ctypes.CDLL(None, use_errno=True)
    libc.signal.argtypes = [ctypes.c_int, ctypes.c_void_p]
    libc.signal.restype = ctypes.c_void_p
    libc.signal(int(signal.SIGPIPE), 1)  # 1: SIG_IGN in every C library with SIGPIPE


@dataclass(frozen=True)
class MeshSettings:
    """Element sizes of a body mesh [m] and how many teeth are refined.

    Attributes
    ----------
    flank_size : float
        Element size along the loaded involute of the refined teeth and at the crack tip [m].
    tooth_size : float
        Element size inside the refined teeth [m].
    body_size : float
        Element size in the rest of the gear (other teeth, rim, bore) [m].
    refined_teeth : int
        Number of teeth around tooth 0 with refined loaded flanks (``teeth_in_model``).
    growth : float
        Largest ratio of neighbouring element sizes in the graded zones [-].
    """

    flank_size: float
    tooth_size: float
    body_size: float
    refined_teeth: int = 5
    growth: float = 1.25

    def __post_init__(self) -> None:
        for name in ("flank_size", "tooth_size", "body_size"):
            v = getattr(self, name)
            if not (math.isfinite(v) and v > 0):
                raise InputError(f"stiffness.fe.{name}", v, "a finite element size > 0 [m]")
        if not self.flank_size <= self.tooth_size <= self.body_size:
            raise InputError("stiffness.fe.mesh_size", (self.flank_size, self.tooth_size,
                                                        self.body_size),
                             "flank_size <= tooth_size <= body_size")
        if self.refined_teeth < 1:
            raise InputError("stiffness.fe.teeth_in_model", self.refined_teeth, "an integer >= 1")
        if not 1.05 <= self.growth <= 2.0:
            raise InputError("growth", self.growth, "a size ratio in [1.05, 2]")


@dataclass(frozen=True)
class CrackGeometry:
    """A root crack on the loaded-side fillet of model tooth 0: straight, or a polyline.

    Attributes
    ----------
    depth : float
        Crack length from the mouth on the fillet to the tip [m] (a straight crack).
    angle : float
        Angle between the crack and the tooth centreline [rad], in (0, pi/2); the crack runs
        towards the centreline and towards the gear centre.
    path : tuple of (x, y)
        Optional: the crack as a polyline from the mouth through these points, the last one the
        tip, body frame [m] (a grown crack, :mod:`geardyn.faults.tooth_growth`); ``depth`` and
        ``angle`` then describe the crack it grew from and are not meshed.
    """

    depth: float
    angle: float
    path: tuple = ()

    def __post_init__(self) -> None:
        if not (math.isfinite(self.depth) and self.depth > 0):
            raise InputError("crack.depth", self.depth, "a crack length > 0 [m]")
        if not 0 < self.angle < math.pi / 2:
            raise InputError("crack.angle", self.angle, "an angle in (0, pi/2) rad")
        pts = tuple((float(x), float(y)) for x, y in self.path)
        if not all(math.isfinite(v) for q in pts for v in q):
            raise InputError("crack.path", self.path, "finite points (x, y) [m]")
        object.__setattr__(self, "path", pts)


@dataclass(frozen=True)
class BodyMesh:
    """A linear triangle mesh of one gear body (P2 fields are built on it by scikit-fem).

    Attributes
    ----------
    p : ndarray, shape (2, n_nodes)
        Node coordinates in the body frame [m].
    t : ndarray, shape (3, n_triangles)
        Triangle node indices (counter-clockwise).
    edges : dict of str -> ndarray, shape (2, n)
        Boundary segments (node pairs) by name: ``"bore"``; ``"flank{j}"`` (loaded involute of
        model tooth ``j``, ordered root to tip), ``"tip{j}"`` and ``"fillet{j}"`` (loaded-side
        fillet) for the refined teeth; ``"crack+"`` and ``"crack-"`` (the two crack faces).
    offsets : tuple of int
        Model teeth with refined loaded flanks.
    gear : Gear
        The gear meshed.
    crack : CrackGeometry or None
    crack_mouth, crack_tip : ndarray or None
        Crack end points in the body frame [m].
    settings : MeshSettings
    info : dict
    cut_radius : float or None
        Radius of the cut of a broken model tooth 0 [m] (``None``: no breakage).
    """

    p: np.ndarray
    t: np.ndarray
    edges: dict[str, np.ndarray]
    offsets: tuple[int, ...]
    gear: Gear
    crack: CrackGeometry | None
    crack_mouth: np.ndarray | None
    crack_tip: np.ndarray | None
    settings: MeshSettings
    info: dict = field(default_factory=dict)
    cut_radius: float | None = None

    @property
    def n_nodes(self) -> int:
        """Number of mesh vertices."""
        return self.p.shape[1]

    @property
    def n_triangles(self) -> int:
        """Number of triangles."""
        return self.t.shape[1]


def tooth_offsets(n: int) -> tuple[int, ...]:
    """Model tooth offsets refined for ``teeth_in_model = n``: ``-(n-1)//2 ... n//2``."""
    return tuple(range(-((n - 1) // 2), n // 2 + 1))


def _rot(a: float) -> np.ndarray:
    c, s = math.cos(a), math.sin(a)
    return np.array([[c, -s], [s, c]])


def loaded_flank(gear: Gear, n: int = 60) -> tuple[np.ndarray, np.ndarray]:
    """Loaded-side (counter-clockwise side) outline of tooth 0 in the body frame [m].

    Returns
    -------
    involute : ndarray, shape (n, 2)
        From the form circle to the tip.
    fillet : ndarray, shape (k, 2)
        From the form circle down to the root circle.
    """
    o = gear.outline(n_involute=n, n_fillet=n)
    mirror = np.array([-1.0, 1.0])
    return o.involute * mirror, o.fillet * mirror


def critical_fillet_point(gear: Gear, tangent_angle: float = math.radians(30)) -> np.ndarray:
    """Point of the loaded-side fillet of tooth 0 whose tangent makes ``tangent_angle`` with the
    tooth centreline (ISO 6336-3 critical section for 30 deg) [m], body frame.

    Found on a dense sampling of the trochoid and refined by linear interpolation of the tangent
    angle between neighbouring samples.
    """
    fil = gear.outline(n_involute=4, n_fillet=2001).fillet  # right side, form -> root
    d = np.diff(fil, axis=0)
    ang = np.arctan2(np.abs(d[:, 0]), np.abs(d[:, 1]))  # angle of the tangent to the y axis
    mid = 0.5 * (fil[1:] + fil[:-1])
    k = np.nonzero((ang[:-1] - tangent_angle) * (ang[1:] - tangent_angle) <= 0)[0]
    if k.size == 0:
        raise InputError("crack", "fillet", "a fillet whose tangent reaches 30 deg to the "
                                            "centreline (the trochoid is too short)")
    i = int(k[0])
    w = (tangent_angle - ang[i]) / (ang[i + 1] - ang[i])
    pt = mid[i] + w * (mid[i + 1] - mid[i])
    return pt * np.array([-1.0, 1.0])


def _closed_polygon(gear: Gear, n: int = 40) -> np.ndarray:
    """A polygon of the whole gear outline (for inside tests) [m]."""
    inv, fil = loaded_flank(gear, n)
    right = np.vstack([fil[::-1] * [-1, 1], inv[1:] * [-1, 1]])  # right flank root -> tip
    left = right[::-1] * [-1, 1]  # left (loaded) flank tip -> root
    pts = []
    z = gear.teeth
    for k in range(z):
        r = _rot(2 * math.pi * k / z)
        pts.append((r @ np.vstack([right, left]).T).T)
    return np.vstack(pts)


def _inside(poly: np.ndarray, pts: np.ndarray) -> np.ndarray:
    """Whether each point of ``pts`` (k, 2) lies inside the closed polygon ``poly`` (n, 2)
    [m], by the even-odd (crossing-number) rule: a ray from the point crosses the outline an
    odd number of times (as stated in PlanetMath, "determining when a point is inside a
    polygon"). The ray goes towards +x; each edge is half-open in y, so a ray through a vertex
    counts it once.

    NumPy only, one point at a time over every edge. It replaced matplotlib's
    ``Path.contains_points``, whose import (13 MB, 2026-11-27) came into the FE bodies'
    process with the crack checks; ``tests/fe/test_mesh.py`` compares the two away from the
    outline, where both rules agree.
    """
    x0, y0 = poly[:, 0], poly[:, 1]
    x1, y1 = np.roll(x0, -1), np.roll(y0, -1)
    out = np.empty(len(pts), dtype=bool)
    for k, (x, y) in enumerate(np.asarray(pts, float)):
        spans = (y0 > y) != (y1 > y)  # edges whose y-range holds y (half-open)
        xa, ya, xb, yb = x0[spans], y0[spans], x1[spans], y1[spans]
        xc = xa + (y - ya) * (xb - xa) / (yb - ya)  # where each crosses the horizontal line
        out[k] = np.count_nonzero(x < xc) % 2 == 1
    return out


def crack_polyline(gear: Gear, crack: CrackGeometry) -> np.ndarray:
    """The crack from the mouth to the tip, shape (k, 2), body frame [m] (checked)."""
    mouth, tip = crack_segment(gear, crack)
    if not crack.path:
        return np.array([mouth, tip])
    return np.vstack([mouth, np.asarray(crack.path, float)])


def _check_path(gear: Gear, crack: CrackGeometry, mouth: np.ndarray) -> np.ndarray:
    """Tip of a polyline crack after checking that it stays inside the body [m]."""
    pts = np.vstack([mouth, np.asarray(crack.path, float)])
    seg = np.diff(pts, axis=0)
    if np.any(np.hypot(*seg.T) <= 1e-9):
        raise InputError("crack.path", "repeated point", "distinct consecutive points")
    poly = _closed_polygon(gear)
    s = np.linspace(0.02, 1.0, 20)[:, None, None]
    samples = (pts[:-1][None] + s * seg[None]).reshape(-1, 2)
    tip = pts[-1]
    if not np.all(_inside(poly, samples)) or np.hypot(*tip) < gear.bore_radius + gear.module:
        raise InputError("crack.path", f"tip at ({tip[0]:.4g}, {tip[1]:.4g}) m",
                         "a crack path that stays inside the tooth and the rim (it leaves the "
                         "body or comes within one module of the bore)")
    return tip


def crack_segment(gear: Gear, crack: CrackGeometry) -> tuple[np.ndarray, np.ndarray]:
    """Mouth and tip of the crack on model tooth 0, body frame [m]; checks the tip is inside."""
    mouth = critical_fillet_point(gear)
    if crack.path:
        return mouth, _check_path(gear, crack, mouth)
    direction = np.array([math.sin(crack.angle), -math.cos(crack.angle)])  # to +x: centreline
    tip = mouth + crack.depth * direction
    if abs(tip[0]) >= abs(mouth[0]):
        # the same domain as the PEM's crack model: the tip stays within the tooth's root
        # section (it must not reach past the opposite fillet's abscissa)
        raise InputError("crack.depth", crack.depth,
                         f"a root crack whose tip stays inside the tooth section (tip at "
                         f"{abs(tip[0]):.4g} m from the centreline, mouth at "
                         f"{abs(mouth[0]):.4g} m)")
    poly = _closed_polygon(gear)
    s = np.linspace(0.02, 1.0, 60)[:, None]
    inside = _inside(poly, mouth + s * crack.depth * direction)
    if not np.all(inside) or np.hypot(*tip) < gear.bore_radius + gear.module:
        raise InputError("crack.depth", crack.depth,
                         "a crack that stays inside the tooth and the rim (it leaves the body or "
                         "comes within one module of the bore)")
    # the crack must not reach the other side of the tooth: distance from the right fillet
    if tip[0] > 0 and np.any(np.hypot(*(poly - tip).T) < 0.05 * gear.module):
        raise InputError("crack.depth", crack.depth, "a crack that does not cut the tooth off")
    return mouth, tip


def cut_flank(gear: Gear, cut_radius: float, n: int) -> np.ndarray:
    """Loaded involute of tooth 0 from the form circle to the cut radius, ``n`` points [m].

    The points of :func:`loaded_flank` below the cut, ending on the exact involute point at the
    cut radius (:func:`geardyn.stiffness.fe.solve.flank_points`)."""
    from .solve import flank_points

    inv, _ = loaded_flank(gear, n)
    rb = gear.base_radius
    u_c = math.sqrt(cut_radius ** 2 - rb ** 2)
    end = flank_points(gear, 0, np.array([u_c]))[0][:, 0]
    r = np.hypot(*inv.T)
    keep = inv[r < cut_radius - 1e-3 * (cut_radius - r[0])]
    return np.vstack([keep, end])


def check_cut(gear: Gear, cut_radius: float, field: str = "breakage.height") -> None:
    """Raise :class:`InputError` unless a cut at ``cut_radius`` leaves a loaded flank of at
    least a tenth of the involute above the form circle (the FE loads it there)."""
    rf, ra = gear.form_radius, gear.tip_radius
    lo = rf + 0.1 * (ra - rf)
    if not (lo <= cut_radius <= ra):
        raise InputError(field, ra - cut_radius,
                         f"for the FE method a height lost in [0, {ra - lo:.4g}] m, which "
                         f"leaves at least a tenth of the involute above the form circle "
                         f"(radius {rf:.6g} m) as a flank to load")


#: The last body meshes built in this process (``build_body_mesh``'s arguments -> mesh): the
#: figure of the mesh (``geardyn stiffness``, the report) reuses the mesh its body was just
#: solved on instead of meshing it again (about 0.8 s for the paper's body).
_MESH_MEMO: dict = {}
_MESH_MEMO_SIZE = 2
_MESH_MEMO_LOCK = threading.Lock()


def build_body_mesh(gear: Gear, settings: MeshSettings, crack: CrackGeometry | None = None,
                    *, n_points: int = 150, cut_radius: float | None = None) -> BodyMesh:
    """Mesh a whole gear body with gmsh (run in-process, single thread, no GUI); the last
    :data:`_MESH_MEMO_SIZE` meshes are kept and returned again for the same arguments (their
    arrays read-only).

    Parameters
    ----------
    gear : Gear
        Geometry (teeth, radii, rack-generated outline, bore).
    settings : MeshSettings
        Element sizes [m] and refined teeth.
    crack : CrackGeometry, optional
        Root crack on model tooth 0.
    n_points : int
        Points per involute and per fillet of the refined teeth (splines through them).
    cut_radius : float, optional
        Tooth breakage: model tooth 0 ends at this radius [m] (:func:`check_cut`).

    Returns
    -------
    BodyMesh
    """
    key = (gear, settings, crack, int(n_points), None if cut_radius is None else
           float(cut_radius))
    with _MESH_MEMO_LOCK:
        hit = _MESH_MEMO.get(key)
    if hit is not None:
        return hit
    mesh = _build_body_mesh(gear, settings, crack, n_points=n_points, cut_radius=cut_radius)
    for a in (mesh.p, mesh.t, *mesh.edges.values()):
        a.setflags(write=False)
    with _MESH_MEMO_LOCK:
        _MESH_MEMO[key] = mesh
        while len(_MESH_MEMO) > _MESH_MEMO_SIZE:
            _MESH_MEMO.pop(next(iter(_MESH_MEMO)))
    return mesh


def _build_body_mesh(gear: Gear, settings: MeshSettings, crack: CrackGeometry | None,
                     *, n_points: int, cut_radius: float | None) -> BodyMesh:
    """:func:`build_body_mesh` without the memo."""
    import gmsh

    z = gear.teeth
    offsets = tooth_offsets(settings.refined_teeth)
    if len(offsets) > z:
        raise InputError("stiffness.fe.teeth_in_model", settings.refined_teeth,
                         f"at most the number of teeth ({z})")
    inv_r, fil_r = loaded_flank(gear, n_points)
    inv_c, fil_c = loaded_flank(gear, 16)
    mouth = tip = None
    if crack is not None:
        mouth, tip = crack_segment(gear, crack)
    inv_cut = None
    if cut_radius is not None:
        check_cut(gear, cut_radius)
        inv_cut = cut_flank(gear, cut_radius, n_points)

    # gmsh is a process-wide singleton and not thread-safe: one mesh at a time per process
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
            gmsh.model.add("gear_body")
            geo = gmsh.model.geo
            lc = settings.body_size

            def point(xy) -> int:
                return geo.addPoint(float(xy[0]), float(xy[1]), 0.0, lc)

            centre = geo.addPoint(0.0, 0.0, 0.0, lc)
            curves: list[int] = []
            named: dict[str, list[int]] = {}
            crack_mouth_tag = None
            first_point = None
            prev_end = None  # last point of the previous tooth (its loaded fillet on the root circle)
            for k in range(z):
                j = k if k <= z // 2 else k - z
                refined = j in offsets
                inv, fil = (inv_r, fil_r) if refined else (inv_c, fil_c)
                if inv_cut is not None and j == 0:
                    inv = inv_cut  # the broken tooth: both involutes end at the cut radius
                rot = _rot(2 * math.pi * j / z)
                # unloaded (clockwise, x > 0) side: mirror of the loaded one
                r_fil = (rot @ (fil * [-1, 1]).T).T  # form -> root
                r_inv = (rot @ (inv * [-1, 1]).T).T  # form -> tip
                l_fil = (rot @ fil.T).T
                l_inv = (rot @ inv.T).T
                # points: right root -> right form -> right tip -> left tip -> left form -> left root
                p_rroot = point(r_fil[-1])
                p_rform = point(r_fil[0])
                p_rtip = point(r_inv[-1])
                p_ltip = point(l_inv[-1])
                p_lform = point(l_fil[0])
                p_lroot = point(l_fil[-1])
                if first_point is None:
                    first_point = p_rroot
                if prev_end is not None:
                    curves.append(geo.addCircleArc(prev_end, centre, p_rroot))
                mid = [point(q) for q in r_fil[-2:0:-1]]
                curves.append(geo.addSpline([p_rroot, *mid, p_rform]))
                mid = [point(q) for q in r_inv[1:-1]]
                curves.append(geo.addSpline([p_rform, *mid, p_rtip]))
                tipc = geo.addCircleArc(p_rtip, centre, p_ltip)
                curves.append(tipc)
                mid = [point(q) for q in l_inv[-2:0:-1]]
                flank = geo.addSpline([p_ltip, *mid, p_lform])
                curves.append(flank)
                if refined:
                    named[f"flank{j}"] = [flank]
                    named[f"tip{j}"] = [tipc]
                if crack is not None and j == 0:
                    # split the loaded fillet at the crack mouth
                    pts = l_fil
                    d_m = np.hypot(*(pts - mouth).T)
                    i_m = int(np.argmin(d_m))
                    upper = [q for q in pts[1:i_m + 1] if np.hypot(*(q - mouth)) > 1e-3 * lc]
                    lower = [q for q in pts[i_m:-1] if np.hypot(*(q - mouth)) > 1e-3 * lc]
                    # keep each part on its side of the mouth (fillet ordered form -> root, radius
                    # decreasing)
                    rm = np.hypot(*mouth)
                    upper = [q for q in upper if np.hypot(*q) > rm]
                    lower = [q for q in lower if np.hypot(*q) < rm]
                    crack_mouth_tag = point(mouth)
                    c1 = geo.addSpline([p_lform, *[point(q) for q in upper], crack_mouth_tag])
                    c2 = geo.addSpline([crack_mouth_tag, *[point(q) for q in lower], p_lroot])
                    curves += [c1, c2]
                    named["fillet0"] = [c1, c2]
                else:
                    mid = [point(q) for q in l_fil[1:-1]]
                    c = geo.addSpline([p_lform, *mid, p_lroot])
                    curves.append(c)
                    if refined:
                        named[f"fillet{j}"] = [c]
                prev_end = p_lroot
            curves.append(geo.addCircleArc(prev_end, centre, first_point))
            outer = geo.addCurveLoop(curves)
            b = gear.bore_radius
            pb = [point((b * math.cos(a), b * math.sin(a))) for a in (0, 2 * math.pi / 3,
                                                                       4 * math.pi / 3)]
            bore = [geo.addCircleArc(pb[i], centre, pb[(i + 1) % 3]) for i in range(3)]
            named["bore"] = bore
            inner = geo.addCurveLoop(bore)
            surf = geo.addPlaneSurface([outer, inner])
            crack_lines = []
            if crack is not None:  # mouth -> tip, or through the path's points
                crack_lines, p_tip = embed_crack(geo, gear, crack, crack_mouth_tag, lc)
            geo.synchronize()
            if crack_lines:
                gmsh.model.mesh.embed(1, crack_lines, 2, surf)
                named["crack"] = crack_lines

            # ---- size fields
            fld = gmsh.model.mesh.field
            g = settings.growth
            fields = []
            flank_curves = [named[f"flank{j}"][0] for j in offsets]
            hf, ht, hb = settings.flank_size, settings.tooth_size, settings.body_size
            flen = (gear.outline(4, 4).involute[-1] - gear.outline(4, 4).involute[0])
            sampling = int(min(20000, max(100, 4 * np.hypot(*flen) * 3 / hf)))
            f1 = fld.add("Distance")
            fld.setNumbers(f1, "CurvesList", flank_curves)
            fld.setNumber(f1, "Sampling", sampling)
            t1 = fld.add("Threshold")
            fld.setNumber(t1, "InField", f1)
            fld.setNumber(t1, "SizeMin", hf)
            fld.setNumber(t1, "SizeMax", hb)
            fld.setNumber(t1, "DistMin", 2 * hf)
            fld.setNumber(t1, "DistMax", 2 * hf + (hb - hf) / (g - 1))
            fields.append(t1)
            tooth_curves = []
            for j in offsets:
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
            fields.append(t2)
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
                raise NumericalError("gmsh produced no triangles for the gear body")
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

    # drop unused nodes (the circle centre), renumber
    used = np.zeros(p.shape[1], bool)
    used[tri.ravel()] = True
    new = np.cumsum(used) - 1
    p = p[:, used]
    tri = new[tri]
    edges = {k: new[v] for k, v in edges.items()}
    # counter-clockwise triangles
    d1 = p[:, tri[1]] - p[:, tri[0]]
    d2 = p[:, tri[2]] - p[:, tri[0]]
    cw = d1[0] * d2[1] - d1[1] * d2[0] < 0
    tri[1:, cw] = tri[2:0:-1, cw]
    # order the flank segments root -> tip
    for j in offsets:
        edges[f"flank{j}"] = _orient_by_radius(p, edges[f"flank{j}"])
    info = {"n_nodes_before_crack": int(p.shape[1])}
    if crack is not None:
        p, tri, plus, minus = split_body_crack(p, tri, edges.pop("crack"), gear, crack)
        edges["crack+"] = plus
        edges["crack-"] = minus
    return BodyMesh(p=p, t=tri, edges=edges, offsets=offsets, gear=gear, crack=crack,
                    crack_mouth=mouth, crack_tip=tip, settings=settings, info=info,
                    cut_radius=None if cut_radius is None else float(cut_radius))


def _orient_by_radius(p: np.ndarray, seg: np.ndarray) -> np.ndarray:
    """Sort boundary segments of a flank by radius (root to tip), each segment root -> tip."""
    r = np.hypot(*p)
    flip = r[seg[0]] > r[seg[1]]
    seg = seg.copy()
    seg[:, flip] = seg[::-1, flip]
    order = np.argsort(r[seg[0]])
    return seg[:, order]


def embed_crack(geo, gear: Gear, crack: CrackGeometry, mouth_tag: int, lc: float
                ) -> tuple[list[int], int]:
    """gmsh (``gmsh.model.geo``): the crack's lines from the mouth point ``mouth_tag``, one
    line for a straight crack or one per segment of its path; returns ``(lines, tip tag)``."""
    tags = [mouth_tag] + [geo.addPoint(float(x), float(y), 0.0, lc)
                          for x, y in crack_polyline(gear, crack)[1:]]
    return [geo.addLine(a, b) for a, b in zip(tags[:-1], tags[1:], strict=True)], tags[-1]


def split_body_crack(p: np.ndarray, t: np.ndarray, seg: np.ndarray, gear: Gear,
                     crack: CrackGeometry) -> tuple[np.ndarray, np.ndarray, np.ndarray,
                                                     np.ndarray]:
    """Free the crack faces of a meshed body: the straight-line split for a straight crack
    (:func:`_split_crack`), the topological polyline split for a path
    (:func:`.crack_mesh.split_crack`). Returns ``p, t, plus, minus``."""
    mouth, tip = crack_segment(gear, crack)
    if not crack.path:
        return _split_crack(p, t, seg, mouth, tip)
    from .crack_mesh import split_crack

    nodes = np.unique(seg)
    d_tip = np.hypot(*(p[:, nodes] - tip[:, None]))
    if d_tip.min() > 1e-9:
        raise NumericalError("crack tip node not found in the mesh")
    return split_crack(p, t, seg, [int(nodes[np.argmin(d_tip)])], crack_polyline(gear, crack))


def _split_crack(p: np.ndarray, t: np.ndarray, seg: np.ndarray, mouth: np.ndarray,
                 tip: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """Duplicate the crack nodes (all but the tip) so the two crack faces are free.

    The triangles on the ``+`` side of the crack (left of the mouth -> tip direction) keep the
    original nodes; those on the ``-`` side get the copies.

    Returns
    -------
    p, t : the new mesh; plus, minus : (2, n) node pairs of the two crack faces.
    """
    d = (tip - mouth) / np.hypot(*(tip - mouth))
    nrm = np.array([-d[1], d[0]])
    nodes = np.unique(seg)
    # the tip node stays shared
    dist_tip = np.hypot(*(p[:, nodes] - tip[:, None]))
    tip_node = nodes[np.argmin(dist_tip)]
    if dist_tip.min() > 1e-9:
        raise NumericalError("crack tip node not found in the mesh")
    dup = nodes[nodes != tip_node]
    n0 = p.shape[1]
    copy_of = np.full(n0, -1, dtype=np.int64)
    copy_of[dup] = n0 + np.arange(dup.size)
    p = np.hstack([p, p[:, dup]])
    cent = p[:, t].mean(axis=1)
    side = (cent - mouth[:, None]).T @ nrm  # > 0: plus side
    touches = np.isin(t, dup)
    minus_tri = np.nonzero(touches.any(axis=0) & (side < 0))[0]
    # only triangles whose centroid lies along the crack (not beyond the tip or before the mouth)
    along = (cent[:, minus_tri] - mouth[:, None]).T @ d
    length = np.hypot(*(tip - mouth))
    minus_tri = minus_tri[(along > -0.5 * length) & (along < length * 1.5)]
    t = t.copy()
    for tri_i in minus_tri:
        for a in range(3):
            v = t[a, tri_i]
            if copy_of[v] >= 0:
                t[a, tri_i] = copy_of[v]
    plus = seg.copy()
    minus = np.where(copy_of[seg] >= 0, copy_of[seg], seg)
    return p, t, plus, minus
