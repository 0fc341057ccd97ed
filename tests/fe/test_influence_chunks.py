"""Influence coefficients solved a few load columns at a time (memory, issue 16) equal the
all-columns-at-once solve bit for bit (every column is its own patch load and its own solve)."""

from __future__ import annotations

import numpy as np

from geardyn.stiffness.fe import solve as S
from geardyn.stiffness.fe.mesh import build_body_mesh
from geardyn.stiffness.fe.model import ElasticMaterial, load_roll_lengths

from .conftest import coarse_settings


def test_chunks_equal_one_chunk(paper_case, monkeypatch):
    s = coarse_settings(paper_case, n_points=20)
    gear = paper_case.gear_pair().pinion
    body = S.ElasticBody(build_body_mesh(gear, s.mesh_settings(), None),
                         ElasticMaterial(float(paper_case.material.youngs_modulus),
                                         float(paper_case.material.poisson_ratio), s.plane))
    u = load_roll_lengths(gear, s.n_points)
    chunked = S.influence_matrices(body, u, s.half_width, load_offsets=(0, 1)).H
    monkeypatch.setattr(S, "LOAD_CHUNK", 10 ** 6)  # every column in one solve call
    whole = S.influence_matrices(body, u, s.half_width, load_offsets=(0, 1)).H
    assert S.LOAD_CHUNK != 8 and chunked.shape == whole.shape
    assert np.array_equal(chunked, whole)
