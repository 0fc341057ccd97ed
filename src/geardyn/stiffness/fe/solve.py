r"""Plane elasticity of one gear body (scikit-fem, P2) and its flank influence coefficients.

Model
-----
Linear elasticity per unit face width on the body mesh of :mod:`.mesh`, quadratic triangles
(``ElementVector(ElementTriP2())``), the bore fixed (the hub is rigid; the pinion's hub rotation is
added as a rigid-body term by :mod:`.contact`). Plane strain (default) uses the Lame constants
``lambda = E nu / ((1 + nu)(1 - 2 nu))``, ``mu = E / (2 (1 + nu))``; plane stress replaces lambda by
``2 lambda mu / (lambda + 2 mu)``. The stiffness matrix is factorised once (CHOLMOD's Cholesky
where installed, SuperLU otherwise: :mod:`.factor`) and solved for many right-hand sides.

Loads: a Hertzian pressure patch
--------------------------------
A point load on a plane body gives a logarithmically infinite displacement under it, so the
compliance of a point-loaded mesh never converges (trap T21 of docs/verification/stiffness.md). Each load is
instead a Hertzian (elliptical) pressure distribution over the flank,

.. math:: p(\sigma) = \frac{2}{\pi b}\sqrt{1 - (\sigma - \sigma_c)^2/b^2},
   \qquad \int p\,d\sigma = 1\ \mathrm{N/m},

in the arc length ``sigma`` of the involute (``sigma = u^2 / (2 r_b)`` for roll length ``u``),
acting along the involute normal at the patch centre, i.e. along the line of action of that
contact. The half-width is a fixed *reference* ``b_ref`` (a numerical parameter, several elements
wide); the displacement is read at the patch centre along the same normal. The difference between
this reference patch and the actual Hertzian contact width at the actual load is added analytically
by :mod:`.contact` (Johnson 1985, eq. 5.36: per body the centre approach changes by
``-(2 / (pi E')) ln(b / b_ref)`` per unit load and width, ``E' = E / (1 - nu^2)`` in plane strain,
``E`` in plane stress); :func:`influence_matrices` stores everything needed.

Influence coefficients
----------------------
For ``n_p`` patch centres along the loaded involute of each model tooth (roll lengths ``u``, from
the form circle to the tip, denser towards the tip), ``H[i, j, b, a]`` is the displacement at point
``b`` of tooth ``j`` along its inward normal per unit load (1 N per m of face width) at point ``a``
of tooth ``i`` [m^2/N]. For a healthy body only tooth 0 is loaded (``i = 0``), the whole gear being
cyclically symmetric; a cracked body is loaded on every refined tooth.

References
----------
Gustafsson, T. & McBain, G. D. (2020). scikit-fem: a Python package for finite element assembly.
J. Open Source Softw. 5(52):2369.
Johnson, K. L. (1985). Contact Mechanics. Cambridge University Press, sections 5.6 and 5.7.
Andersson, A. & Vedmar, L. (2003). A dynamic model to determine vibrations in involute helical
gears. J. Sound Vib. 260(2):195-212 (FE influence functions with an analytical local contact part).
"""

from __future__ import annotations

import math
import time
from dataclasses import dataclass, field

import numpy as np
import scipy.sparse as sp

from ...errors import InputError, NumericalError
from .factor import Factorisation, default_solver, factorise, lower_triangle
from .mesh import BodyMesh

__all__ = ["ElasticMaterial", "ElasticBody", "flank_points", "influence_matrices",
           "load_roll_lengths", "BodyInfluence"]


@dataclass(frozen=True)
class ElasticMaterial:
    """Isotropic elastic constants and the plane assumption.

    Attributes
    ----------
    youngs_modulus : float
        ``E`` [Pa].
    poisson_ratio : float
        ``nu`` [-].
    plane : {"strain", "stress"}
    """

    youngs_modulus: float
    poisson_ratio: float
    plane: str = "strain"

    def __post_init__(self) -> None:
        if not (math.isfinite(self.youngs_modulus) and self.youngs_modulus > 0):
            raise InputError("material.youngs_modulus", self.youngs_modulus, "a modulus > 0 [Pa]")
        if not 0 < self.poisson_ratio < 0.5:
            raise InputError("material.poisson_ratio", self.poisson_ratio, "a value in (0, 0.5)")
        if self.plane not in ("strain", "stress"):
            raise InputError("stiffness.fe.plane", self.plane, "'strain' or 'stress'")

    @property
    def lame(self) -> tuple[float, float]:
        """Lame constants ``(lambda, mu)`` of the 2-D model [Pa] (plane stress: reduced lambda)."""
        e, nu = self.youngs_modulus, self.poisson_ratio
        lam = e * nu / ((1 + nu) * (1 - 2 * nu))
        mu = e / (2 * (1 + nu))
        if self.plane == "stress":
            lam = 2 * lam * mu / (lam + 2 * mu)
        return lam, mu

    @property
    def plane_modulus(self) -> float:
        """``E' = E/(1 - nu^2)`` (plane strain) or ``E`` (plane stress) [Pa]."""
        e, nu = self.youngs_modulus, self.poisson_ratio
        return e / (1 - nu * nu) if self.plane == "strain" else e


def flank_points(gear, offset: int, u: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Points of the loaded involute of model tooth ``offset`` at roll lengths ``u`` and the inward
    normals there (the line-of-action direction into the tooth), body frame.

    Parameters
    ----------
    gear : geardyn.geometry.Gear
    offset : int
        Model tooth (``0`` centred on ``+y``; positive counter-clockwise).
    u : ndarray
        Roll lengths ``sqrt(r^2 - r_b^2)`` [m].

    Returns
    -------
    x : ndarray, shape (2, n) [m]
    n_in : ndarray, shape (2, n) [-], unit vectors from the point towards its base-circle
        tangency point.
    """
    u = np.atleast_1d(np.asarray(u, float))
    rb = gear.base_radius
    ut = u / rb
    psi = gear.base_half_angle - (ut - np.arctan(ut))  # from +y towards -x
    r = rb * np.sqrt(1 + ut * ut)
    ang = math.pi / 2 + psi + 2 * math.pi * offset / gear.teeth  # polar angle from +x
    x = np.vstack([r * np.cos(ang), r * np.sin(ang)])
    beta = ang - np.arctan(ut)
    tang = np.vstack([rb * np.cos(beta), rb * np.sin(beta)])
    n_in = tang - x
    n_in /= np.hypot(*n_in)
    return x, n_in


def load_roll_lengths(gear, n: int, tip_radius: float | None = None) -> np.ndarray:
    """Roll lengths of the load points on a flank [m]: from just above the form circle to the tip,
    clustered towards the tip (where the compliance changes fastest),
    ``u = u_lo + (u_tip - u_lo)(1 - (1 - xi)^1.5)`` for ``xi`` uniform in [0, 1].

    ``tip_radius`` [m]: where the flank ends (a broken tooth's cut); default the tip circle."""
    if n < 8:
        raise InputError("n_points", n, "at least 8 load points per flank")
    rb = gear.base_radius
    ra = gear.tip_radius if tip_radius is None else float(tip_radius)
    u_tip = math.sqrt(ra ** 2 - rb ** 2)
    u_form = math.sqrt(max(gear.form_radius ** 2 - rb ** 2, 0.0))
    u_lo = u_form + 0.02 * (u_tip - u_form)
    xi = np.linspace(0.0, 1.0, n)
    return u_lo + (u_tip - u_lo) * (1 - (1 - xi) ** 1.5)


#: Load columns solved and read out together by :func:`influence_matrices`.
LOAD_CHUNK = 8


#: Triangles per block of :func:`assemble_stiffness` (bounds its temporary memory).
ASSEMBLY_BLOCK = 8192


def assemble_stiffness(skmesh, material: ElasticMaterial,
                       block: int = ASSEMBLY_BLOCK) -> sp.csr_matrix:
    """Stiffness matrix of plane linear elasticity on P2 triangles [N/m per m of width].

    ``K = sum_e int_e eps(v) : C eps(u) dA`` (scikit-fem's ``linear_elasticity`` form with
    the material's Lame constants, quadrature order 2, exact for P2 on straight triangles),
    assembled ``block`` triangles at a time: the quadrature data and the element matrices of
    one block at a time instead of the whole body (peak memory of the paper's pinion body:
    165 MB less, measured 2026-11-26). The blocks' sum equals the one-pass assembly to
    2e-16 relative (summation order only).

    Parameters
    ----------
    skmesh : skfem.MeshTri
    material : ElasticMaterial
    block : int
        Triangles per block.

    Returns
    -------
    scipy.sparse.csr_matrix, shape (n_dofs, n_dofs)
    """
    from skfem import Basis, ElementTriP2, ElementVector, asm
    from skfem.models.elasticity import linear_elasticity

    if block < 1:
        raise ValueError(f"block={block!r}: give at least 1 triangle per block")
    lam, mu = material.lame
    form = linear_elasticity(lam, mu)
    element = ElementVector(ElementTriP2())
    n = skmesh.t.shape[1]
    K = None
    for start in range(0, n, block):
        part = Basis(skmesh, element, intorder=2, elements=np.arange(start, min(start + block, n)))
        k = asm(form, part).tocsr()
        K = k if K is None else K + k
        del part, k
    return K


class ElasticBody:
    """A gear body ready to solve: P2 basis, stiffness matrix, bore fixed, one factorisation.

    Parameters
    ----------
    mesh : BodyMesh
    material : ElasticMaterial
    """

    def __init__(self, mesh: BodyMesh, material: ElasticMaterial):
        from skfem import Basis, ElementTriP2, ElementVector, MeshTri

        self.mesh = mesh
        self.material = material
        t0 = time.perf_counter()
        self.skmesh = MeshTri(np.ascontiguousarray(mesh.p, float), np.ascontiguousarray(mesh.t))
        self.K = assemble_stiffness(self.skmesh, material)
        # the body needs the global DOF numbering and locations only (nodal, facet, doflocs,
        # N): a basis on one element has them all, without the quadrature data of every
        # element (about 120 MB for the paper's 150,880-DOF pinion); ``basis``, the whole
        # body's, is built if asked for
        self.dof_basis = Basis(self.skmesh, ElementVector(ElementTriP2()), intorder=2,
                               elements=np.arange(1))
        self._basis = None
        self.t_assemble = time.perf_counter() - t0
        f = self.skmesh.facets
        n = self.skmesh.p.shape[1]
        keys = np.minimum(f[0], f[1]).astype(np.int64) * n + np.maximum(f[0], f[1])
        self._facet_order = np.argsort(keys)
        self._facet_keys = keys[self._facet_order]
        bf = self.facet_index(mesh.edges["bore"])
        # every DOF on the bore facets (vertex and midside, both components), by scikit-fem
        self.fixed = np.unique(self.dof_basis.get_dofs(facets=bf).all())
        self.free = np.setdiff1d(np.arange(self.dof_basis.N), self.fixed)
        self._lu = None
        self.t_factor = 0.0

    @property
    def basis(self):
        """The scikit-fem basis of the whole body (P2 vector field, quadrature order 2; built
        on first use: the body's own solves need only :attr:`dof_basis`)."""
        if self._basis is None:
            from skfem import Basis, ElementTriP2, ElementVector

            self._basis = Basis(self.skmesh, ElementVector(ElementTriP2()), intorder=2)
        return self._basis

    @property
    def n_dofs(self) -> int:
        """Number of degrees of freedom (P2, two components)."""
        return int(self.dof_basis.N)

    def facet_index(self, seg: np.ndarray) -> np.ndarray:
        """scikit-fem facet indices of node pairs ``seg`` (2, n)."""
        n = self.skmesh.p.shape[1]
        keys = np.minimum(seg[0], seg[1]).astype(np.int64) * n + np.maximum(seg[0], seg[1])
        pos = np.searchsorted(self._facet_keys, keys)
        pos = np.clip(pos, 0, self._facet_keys.size - 1)
        if np.any(self._facet_keys[pos] != keys):
            raise NumericalError("boundary segment not found among the mesh facets")
        return self._facet_order[pos]

    def factor(self, *, release_matrix: bool = False, solver: str | None = None
               ) -> Factorisation:
        """The factorisation of the free-free stiffness (computed once; :func:`.factor.factorise`,
        CHOLMOD where installed, SuperLU otherwise, or ``solver``).

        ``release_matrix=True`` drops the assembled stiffness ``K`` once its free-free part is
        taken, before the solver allocates its factors: a caller that only solves with the body
        afterwards (:func:`geardyn.stiffness.fe.model.body_influence`) lowers its peak memory
        by the matrix (measured on the paper's cracked pinion, 150,880 DOFs: both FE maps in
        one process 682 -> 627 MB with SuperLU). The factorisation is the same; ``K`` is
        ``None`` after.
        """
        from skfem import condense

        if self._lu is None:
            t0 = time.perf_counter()
            solver = default_solver() if solver is None else solver
            kff = condense(self.K, D=self.fixed, expand=False)
            if release_matrix:
                self.K = None
            # CHOLMOD reads the lower triangle only: the whole free-free matrix is dropped
            # before it factorises (the paper's cracked pinion: 16-34 MB less at the peak)
            kff = lower_triangle(kff) if solver == "cholmod" else kff.tocsc()
            self._lu = factorise(kff, solver)
            del kff
            self.t_factor = time.perf_counter() - t0
        return self._lu

    @property
    def solver(self) -> str | None:
        """The solver that factorised the body (``"cholmod"`` or ``"superlu"``; None before)."""
        return None if self._lu is None else self._lu.solver

    def solve(self, rhs: np.ndarray) -> np.ndarray:
        """Displacements [m] for loads ``rhs`` (n_dofs, n) or (n_dofs,) [N/m per unit width],
        bore fixed (zero on the fixed DOFs)."""
        lu = self.factor()
        rhs = np.asarray(rhs, float)
        one = rhs.ndim == 1
        b = rhs[:, None] if one else rhs
        out = np.zeros((self.n_dofs, b.shape[1]))
        out[self.free] = lu.solve(b[self.free])
        return out[:, 0] if one else out

    # ---------------------------------------------------------------- flank loads and readouts
    def _flank(self, offset: int):
        seg = self.mesh.edges[f"flank{offset}"]
        fac = self.facet_index(seg)
        x0 = self.mesh.p[:, seg[0]]
        x1 = self.mesh.p[:, seg[1]]
        return seg, fac, x0, x1

    def _edge_dofs(self, seg: np.ndarray, fac: np.ndarray) -> np.ndarray:
        """(3, 2, n) dofs: [vertex 0, vertex 1, midpoint] x [x, y] of each segment."""
        nd, fd = self.dof_basis.nodal_dofs, self.dof_basis.facet_dofs
        return np.stack([nd[:, seg[0]], nd[:, seg[1]], fd[:, fac]])

    def patch_loads(self, offset: int, u: np.ndarray, half_width: float,
                    n_gauss: int = 8) -> np.ndarray:
        """Load vectors of unit Hertzian pressure patches on the loaded flank of tooth ``offset``.

        Parameters
        ----------
        offset : int
            Model tooth.
        u : ndarray
            Roll lengths of the patch centres [m].
        half_width : float
            Patch half-width ``b_ref`` along the flank arc [m].

        Returns
        -------
        ndarray, shape (n_dofs, len(u))
            Each column has a resultant of 1 N per m of width along the inward normal at the
            centre (patches cut by the tip corner are renormalised).
        """
        gear = self.mesh.gear
        rb = gear.base_radius
        seg, fac, x0, x1 = self._flank(offset)
        dofs = self._edge_dofs(seg, fac)
        xg, wg = np.polynomial.legendre.leggauss(n_gauss)
        tg = 0.5 * (xg + 1)
        wg = 0.5 * wg
        length = np.hypot(*(x1 - x0))  # (nf,)
        pts = x0[:, :, None] + (x1 - x0)[:, :, None] * tg[None, None, :]  # (2, nf, ng)
        sig = (np.sum(pts ** 2, axis=0) - rb ** 2) / (2 * rb)  # (nf, ng)
        shape = np.stack([(1 - tg) * (1 - 2 * tg), tg * (2 * tg - 1), 4 * tg * (1 - tg)])  # (3,ng)
        u = np.atleast_1d(np.asarray(u, float))
        _, n_in = flank_points(gear, offset, u)
        out = np.zeros((self.n_dofs, u.size))
        sig_c = u ** 2 / (2 * rb)
        for k in range(u.size):
            q = (sig - sig_c[k]) / half_width
            p = np.where(np.abs(q) < 1, np.sqrt(np.clip(1 - q * q, 0, None)), 0.0)
            p *= 2 / (math.pi * half_width)
            w = p * wg[None, :] * length[:, None]  # (nf, ng)
            nodal = np.einsum("fg,ag->af", w, shape)  # (3, nf): integral of p N_a
            total = nodal.sum()
            if total <= 0:
                raise NumericalError(f"load patch at u = {u[k]:.6g} m misses the flank")
            for comp in range(2):
                np.add.at(out[:, k], dofs[:, comp, :].ravel(),
                          (nodal * n_in[comp, k] / total).ravel())
        return out

    def readout(self, offset: int, u: np.ndarray) -> sp.csr_matrix:
        """Matrix giving the displacement along the inward normal at flank points [m per m].

        Parameters
        ----------
        offset : int
            Model tooth.
        u : ndarray
            Roll lengths of the points [m].

        Returns
        -------
        scipy.sparse.csr_matrix, shape (len(u), n_dofs)
        """
        gear = self.mesh.gear
        seg, fac, x0, x1 = self._flank(offset)
        dofs = self._edge_dofs(seg, fac)
        x, n_in = flank_points(gear, offset, u)
        r0 = np.hypot(*x0)
        r = np.hypot(*x)
        i = np.clip(np.searchsorted(r0, r) - 1, 0, seg.shape[1] - 1)
        d = x1[:, i] - x0[:, i]
        t = np.sum((x - x0[:, i]) * d, axis=0) / np.sum(d * d, axis=0)
        if np.any(t < -1e-6) or np.any(t > 1 + 1e-6):
            raise NumericalError("flank readout point outside the flank mesh")
        t = np.clip(t, 0.0, 1.0)
        shape = np.stack([(1 - t) * (1 - 2 * t), t * (2 * t - 1), 4 * t * (1 - t)])  # (3, n)
        rows, cols, vals = [], [], []
        for comp in range(2):
            for a in range(3):
                rows.append(np.arange(u.size))
                cols.append(dofs[a, comp, i])
                vals.append(shape[a] * n_in[comp])
        return sp.csr_matrix((np.concatenate(vals), (np.concatenate(rows),
                                                     np.concatenate(cols))),
                             shape=(u.size, self.n_dofs))


@dataclass(frozen=True)
class BodyInfluence:
    """Flank influence coefficients of one gear body (what the contact solver needs).

    Attributes
    ----------
    u : ndarray, shape (n_p,)
        Roll lengths of the load/readout points on each loaded flank [m].
    load_offsets, read_offsets : tuple of int
        Model teeth loaded and read.
    H : ndarray, shape (n_load, n_read, n_p, n_p)
        ``H[i, j, b, a]``: inward normal displacement at point ``b`` of tooth ``read_offsets[j]``
        per unit load at point ``a`` of tooth ``load_offsets[i]`` [m^2/N] (per metre of width).
    half_width : float
        Reference Hertz patch half-width ``b_ref`` [m].
    plane_modulus : float
        ``E'`` of the body [Pa] (for the analytical local correction).
    stats : dict
        Mesh and timing figures (nodes, dofs, seconds).
    inputs_hash : str
        Cache key of the inputs these coefficients were computed for ("" when not cached); a
        cache entry whose stored hash differs from its key is rebuilt.
    u_teeth : ndarray, shape (n_read, n_p), optional
        Roll lengths of the points of each read tooth [m] when they differ from ``u`` (a broken
        tooth's flank ends at its cut); ``None``: ``u`` on every tooth.
    """

    u: np.ndarray
    load_offsets: tuple[int, ...]
    read_offsets: tuple[int, ...]
    H: np.ndarray
    half_width: float
    plane_modulus: float
    stats: dict = field(default_factory=dict)
    inputs_hash: str = ""
    u_teeth: np.ndarray | None = None

    def grid(self, offset: int) -> np.ndarray:
        """Roll lengths of the points on model tooth ``offset`` [m]."""
        if self.u_teeth is None:
            return self.u
        return self.u_teeth[self.read_offsets.index(offset)]

    def save(self, path) -> None:
        """Write to ``.npz`` (no pickle)."""
        stats = stats_to_array(self.stats)
        extra = {} if self.u_teeth is None else {"u_teeth": self.u_teeth}
        with open(path, "wb") as fh:
            np.savez(fh, u=self.u, load_offsets=np.asarray(self.load_offsets),
                     read_offsets=np.asarray(self.read_offsets), H=self.H,
                     half_width=self.half_width, plane_modulus=self.plane_modulus, stats=stats,
                     inputs_hash=np.array(self.inputs_hash), **extra)

    @classmethod
    def load(cls, path) -> BodyInfluence:
        """Read a file written by :meth:`save`."""
        with np.load(path, allow_pickle=False) as d:
            stats = stats_from_array(d["stats"])
            return cls(u=d["u"].copy(), load_offsets=tuple(int(v) for v in d["load_offsets"]),
                       read_offsets=tuple(int(v) for v in d["read_offsets"]), H=d["H"].copy(),
                       half_width=float(d["half_width"]), plane_modulus=float(d["plane_modulus"]),
                       stats=stats,
                       inputs_hash=str(d["inputs_hash"]) if "inputs_hash" in d.files else "",
                       u_teeth=d["u_teeth"].copy() if "u_teeth" in d.files else None)


def stats_to_array(stats: dict) -> np.ndarray:
    """A ``stats`` dict (numbers and strings) as an (n, 2) string array for ``.npz`` files
    without pickle: numbers by ``repr``, strings as they are (:func:`stats_from_array`)."""
    return np.array([[k, v if isinstance(v, str) else repr(v)] for k, v in stats.items()],
                    dtype=str)


def stats_from_array(arr) -> dict:
    """The ``stats`` dict :func:`stats_to_array` stored: numbers back as floats."""
    return {str(k): float(v) if _isfloat(v) else str(v) for k, v in arr}


def _isfloat(v) -> bool:
    try:
        float(v)
    except ValueError:
        return False
    return True


def influence_matrices(body: ElasticBody, u: np.ndarray, half_width: float, *,
                       load_offsets: tuple[int, ...] = (0,),
                       progress=None, u_by_offset: dict | None = None) -> BodyInfluence:
    """Influence coefficients of a body's loaded flanks (one factorisation, many solves).

    Parameters
    ----------
    body : ElasticBody
    u : ndarray
        Roll lengths of the load/readout points [m].
    half_width : float
        Reference Hertz patch half-width [m].
    load_offsets : tuple of int
        Teeth to load (``(0,)`` for a healthy, cyclically symmetric body).
    progress : callable, optional
        ``progress(done, total)`` per loaded tooth.
    u_by_offset : dict of int -> ndarray, optional
        Other roll lengths (same count) on some teeth [m], e.g. a broken tooth's flank.

    Returns
    -------
    BodyInfluence
    """
    read = body.mesh.offsets
    for i in load_offsets:
        if i not in read:
            raise InputError("load_offsets", i, f"refined teeth {read}")
    body.factor()  # (the caller may have factorised it already)
    t0 = time.perf_counter()
    grids = {j: np.asarray((u_by_offset or {}).get(j, u), float) for j in read}
    readouts = sp.vstack([body.readout(j, grids[j]) for j in read]).tocsr()
    H = np.empty((len(load_offsets), len(read), u.size, u.size))
    for a, i in enumerate(load_offsets):
        # a few load columns at a time: the dense loads and displacements (n_dofs x columns,
        # 57 MB each for 48 columns of the paper's body) stay small; every column is its own
        # patch and solve, so the coefficients are the same bit for bit
        for c0 in range(0, u.size, LOAD_CHUNK):
            cols = slice(c0, min(c0 + LOAD_CHUNK, u.size))
            X = body.solve(body.patch_loads(i, grids[i][cols], half_width))
            H[a, :, :, cols] = (readouts @ X).reshape(len(read), u.size, -1)
        if progress is not None:
            progress(a + 1, len(load_offsets))
    stats = {"nodes": body.mesh.n_nodes, "triangles": body.mesh.n_triangles,
             "dofs": body.n_dofs, "t_assemble": body.t_assemble, "t_factor": body.t_factor,
             "t_solve": time.perf_counter() - t0, "solver": body.solver}
    u_teeth = np.stack([grids[j] for j in read]) if u_by_offset else None
    return BodyInfluence(u=np.asarray(u, float), load_offsets=tuple(load_offsets),
                         read_offsets=tuple(read), H=H, half_width=float(half_width),
                         plane_modulus=body.material.plane_modulus, stats=stats, u_teeth=u_teeth)
