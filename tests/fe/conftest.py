"""Shared coarse FE models for the tests (the converged default mesh is studied by the benchmark).

The coarse mesh changes the pitch-point stiffness by about 0.2 % against the default mesh
(benchmarks/bench_fe.py prints the study), far below the tolerances tested here.
"""

from __future__ import annotations

import dataclasses

import pytest

import geardyn
from geardyn.stiffness.fe import FESettings, FEStiffness

STEEL = {"material.youngs_modulus": 206e9, "material.poisson_ratio": 0.3}
#: coarse numerical settings: element sizes [m], refined teeth, load points per flank
COARSE = {"flank_size": 0.1e-3, "tooth_size": 1.0e-3, "body_size": 3e-3, "refined_teeth": 3,
          "n_points": 24}


def coarse_settings(case, **kw) -> FESettings:
    """The case's FE settings with the coarse test mesh (``kw`` overrides)."""
    return dataclasses.replace(FESettings.from_case(case), **{**COARSE, **kw})


@pytest.fixture(scope="session")
def paper_case():
    return geardyn.paper_case()


@pytest.fixture(scope="session")
def steel_case(paper_case):
    return paper_case.with_overrides(STEEL)


@pytest.fixture(scope="session")
def steel_model(_private_cache, steel_case):
    """Healthy steel pair, plane strain, coarse mesh."""
    return FEStiffness(steel_case, cracked=False, settings=coarse_settings(steel_case))


@pytest.fixture(scope="session")
def paper_models(_private_cache, paper_case):
    """The paper's aluminium pair (E = 69 GPa), healthy and with the 5 mm crack, coarse mesh."""
    s = coarse_settings(paper_case)
    return (FEStiffness(paper_case, cracked=False, settings=s),
            FEStiffness(paper_case, cracked=True, settings=s))
