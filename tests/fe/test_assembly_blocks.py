"""The body's stiffness assembled in blocks of triangles equals the one-pass assembly, and the
one-element basis the body keeps numbers and places the DOFs as the whole body's basis
(issue 16: the blocks and the light basis cut the FE stage's peak memory)."""

from __future__ import annotations

import numpy as np
import pytest

from geardyn.stiffness.fe.mesh import build_body_mesh
from geardyn.stiffness.fe.solve import ElasticBody, ElasticMaterial, assemble_stiffness
from tests.fe.test_mesh import COARSE_MESH, CRACK


@pytest.fixture(scope="module")
def body(paper_case):
    return ElasticBody(build_body_mesh(paper_case.gear_pair().pinion, COARSE_MESH, CRACK),
                       ElasticMaterial(206e9, 0.3))


def test_blocks_equal_the_one_pass_assembly(body):
    from skfem import asm
    from skfem.models.elasticity import linear_elasticity

    lam, mu = body.material.lame
    whole = asm(linear_elasticity(lam, mu), body.basis).tocsr()   # scikit-fem, one pass
    n_tri = body.skmesh.t.shape[1]
    scale = abs(whole).max()
    for block in (1000, 4096, n_tri - 1, n_tri, 10 * n_tri):
        K = assemble_stiffness(body.skmesh, body.material, block=block)
        assert K.shape == whole.shape
        assert abs(K - whole).max() <= 1e-14 * scale, block
    # the body's own matrix is one of them, and it is not the zero matrix
    assert abs(body.K - whole).max() <= 1e-14 * scale and scale > 1e9
    with pytest.raises(ValueError, match="block=0"):
        assemble_stiffness(body.skmesh, body.material, block=0)


def test_the_light_basis_numbers_the_dofs_as_the_whole_basis(body):
    light, whole = body.dof_basis, body.basis
    assert light.N == whole.N == body.n_dofs
    np.testing.assert_array_equal(light.nodal_dofs, whole.nodal_dofs)
    np.testing.assert_array_equal(light.facet_dofs, whole.facet_dofs)
    np.testing.assert_array_equal(light.doflocs, whole.doflocs)
    bore = body.facet_index(body.mesh.edges["bore"])
    np.testing.assert_array_equal(np.unique(whole.get_dofs(facets=bore).all()), body.fixed)


def test_a_factor_that_releases_the_matrix_solves_the_same(paper_case):
    """``factor(release_matrix=True)`` (what :func:`body_influence` uses) drops ``K`` before
    SuperLU runs and gives the same displacements, bit for bit, as a body that keeps it."""
    from geardyn.stiffness.fe.solve import influence_matrices, load_roll_lengths

    def fresh():
        return ElasticBody(build_body_mesh(paper_case.gear_pair().pinion, COARSE_MESH, CRACK),
                           ElasticMaterial(206e9, 0.3))

    keep, lean = fresh(), fresh()
    lean.factor(release_matrix=True)
    assert lean.K is None and keep.K is not None
    g = paper_case.gear_pair().pinion
    u = load_roll_lengths(g, 8)
    a = influence_matrices(keep, u, 0.5e-3, load_offsets=(0,))
    b = influence_matrices(lean, u, 0.5e-3, load_offsets=(0,))
    np.testing.assert_array_equal(a.H, b.H)
    assert np.all(np.isfinite(a.H)) and np.abs(a.H).max() > 0
    assert keep.K is not None  # the default keeps it (the substructure and direct solves use it)
