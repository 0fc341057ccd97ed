r"""Direct two-body contact solve of the gear pair at one position (validation and baseline).

This is the independent check of :mod:`.contact`. Nothing of the influence-coefficient route is
reused except the FE body model itself (mesh and elasticity):

* both bodies' meshes are rotated into their real positions at ``(theta, dd)`` from the angular
  positions of the flanks (not from the contact-point formulas of :mod:`.contact`);
* contact is node-to-segment between the discretised surfaces: every pinion flank node (P2 vertex
  or edge midpoint) within reach is a slave against the gear flank segments, and the gear tip
  corner against the pinion flank segments; the unloaded gaps are measured on the meshes;
* the contact pressure is whatever the solve gives (nodal Lagrange multipliers): no Hertzian patch
  is assumed and no analytical local term is added;
* the compatibility problem is solved with non-negative multipliers (NNLS on the Cholesky factor
  of the Delassus matrix) and the pinion rotation is found from the torque balance.

Limitation at a loaded tip corner (extended contact beyond the path): the FE teeth have sharp
tip corners and the flanks meet there at an angle, so the corner's contact zone is narrower than
the flank elements and the contact is carried by the corner node alone. Its compliance is then
that of a point load on the mesh, which grows without bound as the mesh is refined (by
``(2/pi)(1/E_1' + 1/E_2') ln(h_1/h_2)`` per refinement from ``h_1`` to ``h_2``; trap T21 of
docs/verification/stiffness.md), and it does not depend on the load. So at such positions the
solve is not a converged reference (docs/verification/stiffness.md, section 3.1). ``node_*``
of the result show which nodes carry each pair and their compliances.

Linear elasticity with linearised (small-displacement) contact, the same bore conditions as the
influence route (gear bore fixed, pinion bore rigid and turned by ``Delta theta``).

The Delassus matrix ``W = G_1 K_1^{-1} G_1^T + G_2 K_2^{-1} G_2^T`` needs one solve per contact
node with each body's factorisation; this per-position cost is the "full FE solve per position"
baseline reported by the benchmark.
"""

from __future__ import annotations

import math
import time
from dataclasses import dataclass

import numpy as np
import scipy.sparse as sp
from scipy.optimize import brentq, nnls

from ...errors import NumericalError
from .solve import ElasticBody

__all__ = ["DirectOperator", "DirectResult", "direct_contact", "direct_operator"]


@dataclass(frozen=True)
class DirectResult:
    """Result of a direct two-body contact solve (per metre of face width).

    Attributes
    ----------
    rotation : float
        Pinion hub rotation under the torque [rad].
    pair_force : dict of int -> float
        Total normal contact force per pair index ``n`` [N/m].
    n_contact_nodes : int
        Slave nodes carrying load.
    n_candidates : int
        Slave nodes considered.
    seconds : float
        Wall time of the solve (Delassus matrix and contact problem) [s].
    node_pair : ndarray of int, optional
        Pair index ``n`` of each candidate node.
    node_kind : ndarray of str, optional
        ``"p"`` pinion flank node (its tip corner included) against the gear flank, ``"g"`` gear
        tip corner against the pinion flank.
    node_gap : ndarray, optional
        Unloaded normal gap of each candidate node, measured on the meshes [m].
    node_force : ndarray, optional
        Normal contact force of each candidate node [N/m].
    node_compliance : ndarray, optional
        Diagonal of the Delassus matrix: approach of the two bodies at the node per unit force
        there [m^2/N] (a point load on the mesh).
    """

    rotation: float
    pair_force: dict
    n_contact_nodes: int
    n_candidates: int
    seconds: float
    node_pair: np.ndarray | None = None
    node_kind: np.ndarray | None = None
    node_gap: np.ndarray | None = None
    node_force: np.ndarray | None = None
    node_compliance: np.ndarray | None = None

    def load_share(self) -> dict:
        """Share of the total normal force per pair [-]."""
        tot = sum(self.pair_force.values())
        return {k: v / tot for k, v in self.pair_force.items()}


def _rot(a: float) -> np.ndarray:
    c, s = math.cos(a), math.sin(a)
    return np.array([[c, -s], [s, c]])


@dataclass(frozen=True)
class DirectOperator:
    """The contact problem of :func:`direct_operator` at one position, ready for any torque.

    Attributes
    ----------
    gap : ndarray, shape (n,)
        Unloaded gap of each candidate node [m].
    arm : ndarray, shape (n,)
        Lever arm of each candidate's normal about the pinion centre [m]: a pinion rotation
        ``dth`` closes the gap by ``arm * dth``.
    pair_of : ndarray of int, shape (n,)
        Pair index of each candidate (as :attr:`DirectResult.node_pair`).
    node_kind : ndarray of str, shape (n,)
        ``"p"`` pinion flank node or ``"g"`` gear tip corner.
    W : ndarray, shape (n, n)
        Delassus matrix (symmetrised) [m/(N/m)].
    L : ndarray, shape (n, n)
        Its Cholesky factor (with a 1e-14 relative diagonal shift).
    reach : float
        Candidate reach the operator was built with [m].
    seconds : float
        Wall time of building it [s].
    """

    gap: np.ndarray
    arm: np.ndarray
    pair_of: np.ndarray
    node_kind: np.ndarray
    W: np.ndarray
    L: np.ndarray
    reach: float
    seconds: float

    def solve(self, torque_per_width: float) -> DirectResult:
        """The loaded contact under ``torque_per_width`` [N m/m]: non-negative multipliers
        (NNLS on the Cholesky factor) and the pinion rotation from the torque balance.
        ``seconds`` of the result is this operator's build time plus this solve's."""
        t0 = time.perf_counter()
        gap, arm, L, reach = self.gap, self.arm, self.L, self.reach
        n = gap.size

        def forces(dth: float) -> np.ndarray:
            c = gap - dth * arm
            rhs = -np.linalg.solve(L, c)
            lam, _ = nnls(L.T, rhs, maxiter=50 * n)
            return lam

        def resid(dth: float) -> float:
            return float(arm @ forces(dth)) - torque_per_width

        lo = 0.0
        hi = 1e-6
        while resid(hi) < 0:
            hi *= 2
            if hi > 1:
                raise NumericalError("direct contact: no rotation balances the torque")
        dth = brentq(resid, lo, hi, xtol=1e-16, rtol=1e-12)
        lam = forces(dth)
        if np.any(gap[lam > 0] > 0.5 * reach):
            raise NumericalError("direct contact: loaded nodes near the candidate reach; "
                                 "increase reach", state={"reach": reach, "max_loaded_gap":
                                                          float(gap[lam > 0].max())})
        pf: dict[int, float] = {}
        for q, f in zip(self.pair_of, lam, strict=True):
            if f > 0:
                pf[int(q)] = pf.get(int(q), 0.0) + float(f)
        return DirectResult(rotation=float(dth), pair_force=pf,
                            n_contact_nodes=int(np.sum(lam > 0)), n_candidates=n,
                            seconds=self.seconds + time.perf_counter() - t0,
                            node_pair=self.pair_of, node_kind=self.node_kind, node_gap=gap,
                            node_force=lam, node_compliance=np.diag(self.W).copy())


def _surface(body: ElasticBody, names: list[str]):
    """Segments (v0, v1, facet) of named boundary curves."""
    segs = [body.mesh.edges[n] for n in names if n in body.mesh.edges]
    seg = np.hstack(segs)
    return seg, body.facet_index(seg)


def _points_of(body: ElasticBody, seg: np.ndarray, fac: np.ndarray):
    """All P2 surface nodes of segments: coordinates (body frame) and their (2,) dofs."""
    nd, fd = body.dof_basis.nodal_dofs, body.dof_basis.facet_dofs
    verts = np.unique(seg)
    xs = [body.mesh.p[:, verts], 0.5 * (body.mesh.p[:, seg[0]] + body.mesh.p[:, seg[1]])]
    dofs = [nd[:, verts], fd[:, fac]]
    owner_seg = np.concatenate([np.full(verts.size, -1), np.arange(seg.shape[1])])
    return np.hstack(xs), np.hstack(dofs), owner_seg


def _project(x: np.ndarray, a: np.ndarray, b: np.ndarray):
    """Closest points of points x (2, n) on segments a->b (2, m): index, parameter, distance."""
    d = b - a
    ll = np.sum(d * d, axis=0)
    rel = x[:, :, None] - a[:, None, :]  # (2, n, m)
    t = np.sum(rel * d[:, None, :], axis=0) / ll[None, :]
    tc = np.clip(t, 0, 1)
    q = a[:, None, :] + tc[None] * d[:, None, :]
    dist = np.hypot(*(x[:, :, None] - q))
    k = np.argmin(dist, axis=1)
    idx = np.arange(x.shape[1])
    return k, t[idx, k], dist[idx, k]


def _teeth_of_segments(body: ElasticBody, names_by_tooth: dict[int, list[str]]):
    out = []
    for j, names in names_by_tooth.items():
        for n in names:
            if n in body.mesh.edges:
                out.append(np.full(body.mesh.edges[n].shape[1], j))
    return np.concatenate(out)


def direct_contact(pinion: ElasticBody, gear: ElasticBody, pair, theta: float, dd: float,
                   torque_per_width: float, *, reach: float = 25e-6) -> DirectResult:
    """Solve the loaded contact of the two FE bodies at ``(theta, dd)``.

    ``direct_operator(pinion, gear, pair, theta, dd, reach=reach).solve(torque_per_width)``:
    at several torques, build the operator once (:func:`direct_operator`).

    Parameters
    ----------
    pinion, gear, pair, theta, dd, reach
        As in :func:`direct_operator`.
    torque_per_width : float
        Pinion torque per metre of face width [N m/m].

    Returns
    -------
    DirectResult
    """
    return direct_operator(pinion, gear, pair, theta, dd, reach=reach).solve(torque_per_width)


def direct_operator(pinion: ElasticBody, gear: ElasticBody, pair, theta: float, dd: float,
                    *, reach: float = 25e-6) -> DirectOperator:
    """The contact problem of the two FE bodies at ``(theta, dd)``, for any torque: candidates,
    unloaded gaps, lever arms and the Delassus matrix with its Cholesky factor. Everything here
    is the unloaded geometry and the bodies' compliance; the torque enters only in
    :meth:`DirectOperator.solve` (linearised contact), so one operator serves every torque.

    Parameters
    ----------
    pinion, gear : ElasticBody
        Bodies in their body frames (:mod:`.mesh` conventions); body tooth 0 of the pinion is
        pinion tooth 0 and body tooth 0 of the gear is gear tooth 0 (pair 0). Their refined teeth
        must include every tooth in contact.
    pair : geardyn.geometry.GearPair
    theta : float
        Pinion angle [rad] (backlash closed).
    dd : float
        Centre distance change [m].
    reach : float
        Slave nodes with an unloaded gap below ``reach`` are candidates [m].

    Returns
    -------
    DirectOperator
    """
    t0 = time.perf_counter()
    p1, p2 = pair.pinion, pair.gear
    rb1, rb2 = p1.base_radius, p2.base_radius
    op = pair.operating(dd, check=False)
    s0 = pair.pitch_point_s + rb1 * theta
    rho1 = s0 / rb1 - math.pi / 2 - p1.base_half_angle
    rho2 = math.pi / 2 + (op.t1t2 - s0) / rb2 - p2.base_half_angle
    r1, r2 = _rot(rho1), _rot(rho2)
    o2 = np.array([rb1 + rb2, op.t1t2])

    offs1 = pinion.mesh.offsets
    offs2 = gear.mesh.offsets
    # ---- pinion slaves (flank nodes incl. the tip corner) against gear flank segments
    seg1, fac1 = _surface(pinion, [f"flank{j}" for j in offs1])
    tooth_seg1 = _teeth_of_segments(pinion, {j: [f"flank{j}"] for j in offs1})
    x1b, d1, own1 = _points_of(pinion, seg1, fac1)
    x1 = r1 @ x1b
    seg2, fac2 = _surface(gear, [f"flank{j}" for j in offs2])
    tooth_seg2 = _teeth_of_segments(gear, {j: [f"flank{j}"] for j in offs2})
    a2 = o2[:, None] + r2 @ gear.mesh.p[:, seg2[0]]
    b2 = o2[:, None] + r2 @ gear.mesh.p[:, seg2[1]]
    k2, t2, _ = _project(x1, a2, b2)
    dseg = b2[:, k2] - a2[:, k2]
    # flank segments run root -> tip, the tooth material on their right: (d_y, -d_x) points
    # into the gear tooth, i.e. from the pinion towards the gear
    nrm = np.vstack([dseg[1], -dseg[0]]) / np.hypot(*dseg)
    foot = a2[:, k2] + t2 * dseg
    g0 = np.sum((foot - x1) * nrm, axis=0)
    ok = (t2 >= 0) & (t2 <= 1) & (g0 < reach) & (g0 > -reach)
    rows1 = []
    for i in np.nonzero(ok)[0]:
        rows1.append(("p", i, k2[i], t2[i], nrm[:, i], g0[i], x1[:, i]))

    # ---- gear tip corners (slaves) against pinion flank segments
    corner = []
    for j in offs2:
        s = gear.mesh.edges[f"flank{j}"]
        corner.append(s[1, -1])  # tip end of the last (outermost) segment
    corner = np.asarray(corner)
    xc = o2[:, None] + r2 @ gear.mesh.p[:, corner]
    a1 = r1 @ pinion.mesh.p[:, seg1[0]]
    b1 = r1 @ pinion.mesh.p[:, seg1[1]]
    kc, tc, _ = _project(xc, a1, b1)
    dsc = b1[:, kc] - a1[:, kc]
    nc = -np.vstack([dsc[1], -dsc[0]]) / np.hypot(*dsc)  # out of the pinion: to the gear
    footc = a1[:, kc] + tc * dsc
    gc = np.sum((xc - footc) * nc, axis=0)
    rows2 = []
    for i in range(corner.size):
        if 0 < tc[i] < 1 and -reach < gc[i] < reach:
            rows2.append(("g", i, kc[i], tc[i], nc[:, i], gc[i], footc[:, i]))

    n = len(rows1) + len(rows2)
    if n == 0:
        raise NumericalError("no contact candidates in the direct solve", state={"theta": theta})
    # constraint rows assembled as COO triplets (row, dof, value), converted once to CSR
    G1: tuple[list, list, list] = ([], [], [])
    G2: tuple[list, list, list] = ([], [], [])

    def put(g, r, col, val):
        g[0].append(r)
        g[1].append(col)
        g[2].append(val)
    gap = np.zeros(n)
    arm = np.zeros(n)
    pair_of = np.zeros(n, dtype=np.int64)
    nd1, fd1 = pinion.dof_basis.nodal_dofs, pinion.dof_basis.facet_dofs
    nd2, fd2 = gear.dof_basis.nodal_dofs, gear.dof_basis.facet_dofs

    def edge_weights(t):
        return np.array([(1 - t) * (1 - 2 * t), t * (2 * t - 1), 4 * t * (1 - t)])

    row = 0
    for _, i, k, t, nv, g, xp in rows1:
        nb1 = r1.T @ nv  # normal in the pinion body frame
        for c in range(2):
            put(G1, row, d1[c, i], nb1[c])
        nb2 = r2.T @ nv
        w = edge_weights(t)
        dd2 = [nd2[:, seg2[0, k]], nd2[:, seg2[1, k]], fd2[:, fac2[k]]]
        for a in range(3):
            for c in range(2):
                put(G2, row, dd2[a][c], w[a] * nb2[c])
        gap[row] = g
        arm[row] = xp[0] * nv[1] - xp[1] * nv[0]
        # pair: the gear tooth of the segment (gear tooth q = model offset q)
        pair_of[row] = int(tooth_seg2[k])
        row += 1
    for _, i, k, t, nv, g, xp in rows2:
        nb1 = r1.T @ nv
        w = edge_weights(t)
        dd1 = [nd1[:, seg1[0, k]], nd1[:, seg1[1, k]], fd1[:, fac1[k]]]
        for a in range(3):
            for c in range(2):
                put(G1, row, dd1[a][c], w[a] * nb1[c])
        nb2 = r2.T @ nv
        for c in range(2):
            put(G2, row, nd2[c, corner[i]], nb2[c])
        gap[row] = g
        arm[row] = xp[0] * nv[1] - xp[1] * nv[0]
        pair_of[row] = -int(tooth_seg1[k])  # pinion tooth p = model offset -p
        row += 1
    G1 = sp.coo_matrix((G1[2], (G1[0], G1[1])), shape=(n, pinion.n_dofs)).tocsr()
    G2 = sp.coo_matrix((G2[2], (G2[0], G2[1])), shape=(n, gear.n_dofs)).tocsr()
    W = G1 @ pinion.solve(G1.T.toarray()) + G2 @ gear.solve(G2.T.toarray())
    W = 0.5 * (W + W.T)
    L = np.linalg.cholesky(W + 1e-14 * np.trace(W) / n * np.eye(n))
    return DirectOperator(gap=gap, arm=arm, pair_of=pair_of,
                          node_kind=np.array([r[0] for r in rows1 + rows2]), W=W, L=L,
                          reach=float(reach), seconds=time.perf_counter() - t0)

