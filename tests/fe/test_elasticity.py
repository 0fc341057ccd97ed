"""The plane-elasticity solver against exact answers.

* A cantilever with a parabolic end shear (Timoshenko & Goodier, Theory of Elasticity, 3rd ed.,
  section 21): the 2-D elasticity solution is a cubic polynomial; prescribing it on the clamped
  edge, the tip deflection is exactly ``P L^3/(3 E I) + P L/(kappa G A)`` with ``kappa = 2/3``
  (the vertical element of the axis fixed at the wall). We also compare with the Timoshenko beam
  (``kappa = 5/6``), which differs by 0.2 % at L/h = 10. Plane stress and plane strain (the latter
  via ``E' = E/(1 - nu^2)``, ``nu' = nu/(1 - nu)``).
* An annulus twisted by a uniform shear on its outer edge with the bore fixed (Lame): the rotation
  is ``T/(4 pi G) (1/r_i^2 - 1/r_o^2)`` per unit thickness; this is the gear-body torsion that the
  FE mesh stiffness includes down to the bore. It uses the production class ``ElasticBody``
  (assembly, fixed bore, factorisation, solve).
"""

from __future__ import annotations

import math

import numpy as np
import pytest
from skfem import Basis, ElementTriP2, ElementVector, LinearForm, MeshTri, asm, condense, solve
from skfem.models.elasticity import linear_elasticity

from geardyn.stiffness.fe.mesh import BodyMesh, MeshSettings
from geardyn.stiffness.fe.solve import ElasticBody, ElasticMaterial

E, NU = 206e9, 0.3


def _cantilever_tip(plane: str, length=0.1, height=0.01, load=1000.0, nx=40, ny=6):
    """FE and exact tip deflection of the Timoshenko-Goodier cantilever (per unit thickness)."""
    mat = ElasticMaterial(E, NU, plane)
    c = height / 2
    # the exact field is written for plane stress; plane strain maps E, nu
    e, nu = (E, NU) if plane == "stress" else (E / (1 - NU ** 2), NU / (1 - NU))
    g = E / (2 * (1 + NU))
    inertia = 2 * c ** 3 / 3
    P, L = load, length
    d = -P * c ** 2 / (2 * inertia * g) - P * L ** 2 / (2 * e * inertia)
    ecoef = P * L ** 2 / (2 * e * inertia)
    h = -P * L ** 3 / (6 * e * inertia) - d * L

    def exact(x, y):
        u = (-P * x ** 2 * y / (2 * e * inertia) - nu * P * y ** 3 / (6 * e * inertia)
             + P * y ** 3 / (6 * inertia * g) + ecoef * y)
        v = nu * P * x * y ** 2 / (2 * e * inertia) + P * x ** 3 / (6 * e * inertia) + d * x + h
        return u, v

    mesh = MeshTri.init_tensor(np.linspace(0, L, nx + 1), np.linspace(-c, c, 2 * ny + 1))
    basis = Basis(mesh, ElementVector(ElementTriP2()))
    K = asm(linear_elasticity(*mat.lame), basis)
    end = mesh.facets_satisfying(lambda x: np.isclose(x[0], 0.0))
    fb = basis.boundary(end, intorder=6) if hasattr(basis, "boundary") else None

    @LinearForm
    def shear(v, w):
        return P / (2 * inertia) * (c ** 2 - w.x[1] ** 2) * v[1]

    f = asm(shear, fb)
    wall = basis.get_dofs(lambda x: np.isclose(x[0], L)).all()
    xfix = np.zeros(basis.N)
    xy = basis.doflocs[:, wall]
    ue, ve = exact(xy[0], xy[1])
    comp = np.zeros(basis.N, dtype=int)
    comp[basis.nodal_dofs[1]] = 1
    comp[basis.facet_dofs[1]] = 1
    xfix[wall] = np.where(comp[wall] == 0, ue, ve)
    sol = solve(*condense(K, f, x=xfix, D=wall))
    tip_node = np.nonzero(np.isclose(mesh.p[0], 0) & np.isclose(mesh.p[1], 0))[0][0]
    v_fe = sol[basis.nodal_dofs[1, tip_node]]
    v_exact = exact(0.0, 0.0)[1]
    bend = P * L ** 3 / (3 * e * inertia)
    area = height
    timoshenko = bend + P * L / (5 / 6 * g * area)
    return v_fe, v_exact, bend, timoshenko, P * L / (2 / 3 * g * area)


@pytest.mark.parametrize("plane", ["stress", "strain"])
def test_cantilever_tip_deflection(plane):
    v_fe, v_exact, bend, timo, shear_23 = _cantilever_tip(plane)
    # the exact 2-D value is the closed form with kappa = 2/3
    assert v_exact == pytest.approx(bend + shear_23, rel=1e-12)
    assert v_fe == pytest.approx(v_exact, rel=0.02)
    assert abs(v_fe / v_exact - 1) < 2e-3  # P2 on 40 x 12 cells: far inside the 2 % target
    assert v_fe == pytest.approx(timo, rel=0.02)  # Timoshenko beam, kappa = 5/6


def test_cantilever_converges():
    """Halving the element size reduces the error (it is already tiny: quadratic elements on a
    cubic field)."""
    e1 = abs(_cantilever_tip("stress", nx=10, ny=2)[0] / _cantilever_tip("stress")[1] - 1)
    e2 = abs(_cantilever_tip("stress", nx=20, ny=4)[0] / _cantilever_tip("stress")[1] - 1)
    assert e2 < e1 or e2 < 1e-6


def _annulus(ri, ro, nr, nt):
    r = ri * (ro / ri) ** np.linspace(0, 1, nr + 1)
    th = np.linspace(0, 2 * math.pi, nt, endpoint=False)
    R, T = np.meshgrid(r, th, indexing="ij")
    p = np.vstack([(R * np.cos(T)).ravel(), (R * np.sin(T)).ravel()])
    idx = np.arange(p.shape[1]).reshape(nr + 1, nt)
    tris = []
    for i in range(nr):
        for j in range(nt):
            a, b = idx[i, j], idx[i, (j + 1) % nt]
            c, d = idx[i + 1, j], idx[i + 1, (j + 1) % nt]
            tris += [(a, b, d), (a, d, c)]
    t = np.array(tris).T
    bore = np.vstack([idx[0], np.roll(idx[0], -1)])
    outer = np.vstack([idx[-1], np.roll(idx[-1], -1)])
    return p, t, bore, outer


@pytest.mark.parametrize("plane", ["strain", "stress"])
def test_annulus_torsion(plane):
    ri, ro, torque = 0.02, 0.0615, 100.0  # the paper case's bore and root radii
    p, t, bore, outer = _annulus(ri, ro, 24, 240)
    settings = MeshSettings(flank_size=1e-3, tooth_size=1e-3, body_size=1e-3)
    bm = BodyMesh(p=p, t=t, edges={"bore": bore}, offsets=(), gear=None, crack=None,
                  crack_mouth=None, crack_tip=None, settings=settings)
    body = ElasticBody(bm, ElasticMaterial(E, NU, plane))
    tau = torque / (2 * math.pi * ro ** 2)

    @LinearForm
    def shear(v, w):
        rr = np.sqrt(w.x[0] ** 2 + w.x[1] ** 2)
        return tau * (-w.x[1] * v[0] + w.x[0] * v[1]) / rr

    fb = body.basis.boundary(body.facet_index(outer), intorder=4)
    u = body.solve(asm(shear, fb))
    nodes = np.unique(outer)
    ux = u[body.basis.nodal_dofs[0, nodes]]
    uy = u[body.basis.nodal_dofs[1, nodes]]
    x, y = p[:, nodes]
    rot = np.mean((-y * ux + x * uy) / (x * x + y * y))
    g = E / (2 * (1 + NU))
    exact = torque / (4 * math.pi * g) * (1 / ri ** 2 - 1 / ro ** 2)
    assert rot == pytest.approx(exact, rel=5e-3)


def test_fixed_dof_bookkeeping_by_scikit_fem_equals_the_hand_made_one():
    """``ElasticBody`` takes the bore DOFs from ``basis.get_dofs(facets=...)`` and the free-free
    stiffness from ``skfem.condense`` (issue 17.7). Both equal the former hand bookkeeping
    (vertex DOFs of the bore nodes + midside DOFs of the bore facets; ``K[free][:, free]``)
    exactly, so the solution is bit for bit the same (tolerance 0) with the same solver."""
    from geardyn.stiffness.fe.factor import factorise

    p, t, bore, outer = _annulus(0.02, 0.0615, 6, 60)
    settings = MeshSettings(flank_size=1e-3, tooth_size=1e-3, body_size=1e-3)
    bm = BodyMesh(p=p, t=t, edges={"bore": bore}, offsets=(), gear=None, crack=None,
                  crack_mouth=None, crack_tip=None, settings=settings)
    body = ElasticBody(bm, ElasticMaterial(E, NU, "strain"))
    hand = np.unique(np.concatenate([body.basis.nodal_dofs[:, np.unique(bore)].ravel(),
                                     body.basis.facet_dofs[:, body.facet_index(bore)].ravel()]))
    np.testing.assert_array_equal(body.fixed, hand)
    # 2 components x (60 bore vertices + 60 bore midsides)
    assert body.fixed.size == 2 * 2 * 60
    mask = np.ones(body.n_dofs, bool)
    mask[hand] = False
    free = np.nonzero(mask)[0]
    np.testing.assert_array_equal(body.free, free)
    kff_hand = body.K[free][:, free].tocsc()
    kff = condense(body.K, D=body.fixed, expand=False).tocsc()
    assert (kff != kff_hand).nnz == 0
    rng = np.random.default_rng(2)
    rhs = rng.standard_normal(body.n_dofs)
    got = body.solve(rhs)
    expected = np.zeros(body.n_dofs)
    expected[free] = factorise(kff_hand, body.solver).solve(rhs[free])
    np.testing.assert_array_equal(got, expected)
