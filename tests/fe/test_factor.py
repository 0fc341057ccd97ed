"""The body factorisations (geardyn.stiffness.fe.factor): CHOLMOD and SuperLU give the same
influence coefficients, the fallback to SuperLU works where cholespy is missing, and bad input
is refused with the field named (issue 16.1: "a sparse Cholesky only if it measurably helps
(SuperLU stays as the fallback)"; "every solver path gives the same map to 1e-9 relative; a
fallback is exercised in a test")."""

from __future__ import annotations

import numpy as np
import pytest
import scipy.sparse as sp

from geardyn.errors import InputError, NumericalError
from geardyn.stiffness.fe import factor as F
from geardyn.stiffness.fe.mesh import CrackGeometry, build_body_mesh
from geardyn.stiffness.fe.solve import (
    ElasticBody,
    ElasticMaterial,
    influence_matrices,
    load_roll_lengths,
)

from .conftest import coarse_settings

needs_cholmod = pytest.mark.skipif("cholmod" not in F.available_solvers(),
                                   reason="cholespy is not installed here")


def _spd(n: int, seed: int = 0) -> sp.csc_matrix:
    """A sparse symmetric positive-definite matrix (a 1-D Laplacian plus a random SPD part)."""
    rng = np.random.default_rng(seed)
    lap = sp.diags([-np.ones(n - 1), 2.5 * np.ones(n), -np.ones(n - 1)], [-1, 0, 1])
    r = sp.random(n, n, density=3.0 / n, random_state=rng)
    return (lap + r @ r.T).tocsc()


def _coarse_cracked_pinion(paper_case):
    """The paper's pinion with a 2 mm crack at 45 degrees, on the coarse test mesh: the FE
    settings, the gear, its body mesh and its material."""
    s = coarse_settings(paper_case)
    gear = paper_case.gear_pair().pinion
    mesh = build_body_mesh(gear, s.mesh_settings(), CrackGeometry(depth=2e-3,
                                                                  angle=np.deg2rad(45)))
    mat = ElasticMaterial(float(paper_case.material.youngs_modulus),
                          float(paper_case.material.poisson_ratio))
    return s, gear, mesh, mat


@pytest.mark.parametrize("solver", F.available_solvers())
@pytest.mark.parametrize("k", [None, 1, 3, 9, 70])
def test_solve_equals_a_dense_solve(solver, k):
    """Each solver against numpy's dense LAPACK solve (an independent method), for one load and
    for blocks of loads (SuperLU solves four columns at a time, CHOLMOD 32: 9 and 70 span
    several blocks and end in a partial one)."""
    A = _spd(60)
    rng = np.random.default_rng(1)
    b = rng.standard_normal(60) if k is None else rng.standard_normal((60, k))
    x = F.factorise(A, solver).solve(b)
    assert x.shape == b.shape
    np.testing.assert_allclose(x, np.linalg.solve(A.toarray(), b), rtol=1e-10, atol=1e-12)


@pytest.mark.parametrize("fmt", ["csr", "csc", "coo"])
@pytest.mark.parametrize("symmetric", [True, False])
def test_lower_triangle_equals_scipy_tril(fmt, symmetric):
    """:func:`lower_triangle` against ``scipy.sparse.tril`` (SciPy's own, through COO: an
    independent implementation), entry for entry, for each input format and for a matrix that
    is not symmetric (the filter must read rows and columns the right way round), with empty
    rows and columns; its own lower triangle comes back unchanged."""
    rng = np.random.default_rng(3)
    A = sp.random(40, 40, density=0.15, random_state=rng, format="csr")
    A = A + A.T if symmetric else A
    A = A.tolil()
    A[7, :] = 0.0
    A[:, 7] = 0.0
    A = A.asformat(fmt)
    L = F.lower_triangle(A)
    assert L.format == "csc" and L.shape == A.shape
    ref = sp.tril(A, format="csc")
    np.testing.assert_array_equal(L.toarray(), ref.toarray())
    assert L.nnz == ref.nnz
    # 4-byte indices kept (the point is memory): no int64 copy of the index arrays
    assert L.indices.dtype == np.int32 and L.indptr.dtype == np.int32
    assert F.lower_triangle(L) is L


def test_lower_triangle_refuses_what_is_not_a_square_sparse_matrix():
    with pytest.raises(TypeError, match="scipy.sparse matrix is needed, not ndarray"):
        F.lower_triangle(np.eye(3))
    with pytest.raises(ValueError, match="square"):
        F.lower_triangle(sp.csr_matrix((3, 4)))


@needs_cholmod
def test_cholmod_given_the_lower_triangle_solves_as_given_the_whole_matrix(paper_case):
    """CHOLMOD reads the lower triangle of what it is given, so handing it only that
    (geardyn's path since 2026-11-28, for memory) changes nothing: the coarse cracked pinion
    body's displacements bit for bit equal to cholespy given the whole free-free matrix, as
    before. The body's matrix is symmetric to round-off only, so this also checks that the
    triangle taken is the lower one."""
    import cholespy
    from skfem import condense

    s, gear, mesh, mat = _coarse_cracked_pinion(paper_case)
    body = ElasticBody(mesh, mat)
    kff = sp.csc_matrix(condense(body.K, D=body.fixed, expand=False))
    n = kff.shape[0]
    whole = cholespy.CholeskySolverD(n, kff.indptr.copy(), kff.indices.copy(), kff.data.copy(),
                                     cholespy.MatrixType.CSC)
    b = np.random.default_rng(4).standard_normal((n, 3))
    x_whole = np.empty_like(b)
    whole.solve(b.copy(), x_whole)
    body.factor(solver="cholmod")
    rhs = np.zeros((body.n_dofs, 3))
    rhs[body.free] = b
    np.testing.assert_array_equal(body.solve(rhs)[body.free], x_whole)


@needs_cholmod
def test_influence_coefficients_equal_for_both_solvers(paper_case):
    """The cracked coarse pinion body, loaded on every refined tooth: CHOLMOD and SuperLU give
    the same influence coefficients to 1e-9 relative (the issue's tolerance for solver paths),
    measured against the largest coefficient."""
    s, gear, mesh, mat = _coarse_cracked_pinion(paper_case)
    u = load_roll_lengths(gear, s.n_points)
    H = {}
    for solver in ("cholmod", "superlu"):
        body = ElasticBody(mesh, mat)
        body.factor(solver=solver)
        inf = influence_matrices(body, u, s.half_width, load_offsets=mesh.offsets)
        assert inf.stats["solver"] == solver
        H[solver] = inf.H
    scale = np.abs(H["superlu"]).max()
    assert np.abs(H["cholmod"] - H["superlu"]).max() <= 1e-9 * scale


def test_fallback_to_superlu_where_cholespy_is_missing(monkeypatch):
    """Without cholespy the default is SuperLU and the same solve works; asking for CHOLMOD
    there is refused with the variable, the value and what is allowed."""
    monkeypatch.setattr(F, "_cholespy", lambda: None)
    monkeypatch.delenv(F.SOLVER_ENV, raising=False)
    assert F.available_solvers() == ("superlu",)
    assert F.default_solver() == "superlu"
    A = _spd(30, seed=3)
    fac = F.factorise(A)
    assert fac.solver == "superlu"
    b = np.arange(30.0)
    np.testing.assert_allclose(A @ fac.solve(b), b, rtol=1e-10, atol=1e-10)
    monkeypatch.setenv(F.SOLVER_ENV, "cholmod")
    with pytest.raises(InputError, match=r"GEARDYN_FE_SOLVER.*'cholmod'.*not installed"):
        F.default_solver()


def test_the_default_prefers_cholmod_where_installed(monkeypatch):
    monkeypatch.delenv(F.SOLVER_ENV, raising=False)
    assert F.default_solver() == F.available_solvers()[0]
    monkeypatch.setenv(F.SOLVER_ENV, "superlu")
    assert F.default_solver() == "superlu"
    assert F.factorise(_spd(10)).solver == "superlu"


@pytest.mark.parametrize("value", ["umfpack", "CHOLMOD", "1"])
def test_a_bad_solver_name_is_refused(monkeypatch, value):
    monkeypatch.setenv(F.SOLVER_ENV, value)
    with pytest.raises(InputError, match=rf"GEARDYN_FE_SOLVER.*{value}.*'cholmod'.*'superlu'"):
        F.default_solver()
    with pytest.raises(InputError, match="solver"):
        F.factorise(_spd(5), value)


@pytest.mark.parametrize("solver", F.available_solvers())
def test_a_matrix_that_is_not_positive_definite_is_a_numerical_error(solver):
    """A body that is not held has a singular stiffness: a NumericalError that says so, not a
    solver's own exception (or, for CHOLMOD, a wrong answer)."""
    A = sp.diags([1.0, 0.0, 3.0]).tocsc() if solver == "superlu" else \
        sp.diags([1.0, -2.0, 3.0]).tocsc()
    with pytest.raises(NumericalError, match="held"):
        F.factorise(A, solver)


def test_a_bad_right_hand_side_is_refused():
    fac = F.factorise(_spd(8), "superlu")
    with pytest.raises(ValueError, match=r"\(8,\) or \(8, k\)"):
        fac.solve(np.ones(7))
    assert fac.solve(np.ones((8, 0))).shape == (8, 0)
    assert repr(fac) == "Factorisation(solver='superlu', n=8)"


@needs_cholmod
def test_a_factorisation_alive_at_exit_prints_nothing():
    """A script that keeps a CHOLMOD factorisation to its end exits without cholespy's binding
    printing "nanobind: leaked ..." (factor._release_all frees it at exit)."""
    import subprocess
    import sys

    # a factorisation in a reference cycle, as a body's can be, with the collector frozen at
    # exit as geardyn's own processes do (processes.skip_collection_at_exit)
    code = ("import gc, numpy as np, scipy.sparse as sp\n"
            "from geardyn.processes import skip_collection_at_exit\n"
            "from geardyn.stiffness.fe.factor import factorise\n"
            "class Body: pass\n"
            "b = Body(); b.me = b\n"
            "b.lu = factorise(sp.diags([2.0, 3.0, 4.0]).tocsc(), 'cholmod')\n"
            "print(b.lu.solve(np.ones(3)))\n"
            "del b\n"
            "skip_collection_at_exit()\n")
    res = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                         timeout=120, check=False)
    assert res.returncode == 0, res.stderr
    assert "0.5" in res.stdout
    assert "leaked" not in res.stderr, res.stderr
