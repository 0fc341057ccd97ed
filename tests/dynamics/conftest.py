"""Session fixtures of the paper tests: the paper's case over one revolution, its PEM map and the
runs of models I and II (shared by test_paper_consistency.py and test_paper.py)."""

from __future__ import annotations

import math

import pytest

import geardyn
from geardyn.dynamics import simulate
from geardyn.stiffness import centre_distance_grid

T_REV = 2 * math.pi / 114.14          # one pinion revolution at the paper's speed [s]


@pytest.fixture(scope="session")
def paper_run_case():
    return geardyn.paper_case({"simulation.settle_time": 0.2, "simulation.record_time": T_REV})


@pytest.fixture(scope="session")
def paper_pem(paper_run_case):
    from geardyn.stiffness.pem import pem_map

    return pem_map(paper_run_case, centre_distance_grid(paper_run_case), cracked=True)


@pytest.fixture(scope="session")
def paper_runs(paper_run_case, paper_pem):
    return {w: simulate(paper_run_case, paper_pem, model=w) for w in ("I", "II")}
