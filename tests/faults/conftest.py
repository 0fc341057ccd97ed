"""Shared pieces of the fault tests: the paper's pair without its crack, PEM models."""

from __future__ import annotations

import numpy as np
import pytest

from geardyn.config import paper_case
from geardyn.faults import faults_from_case
from geardyn.stiffness.pem import PEMModel
from geardyn.stiffness.pem.fault_model import fault_model_from_case


@pytest.fixture(scope="session")
def base():
    """The paper's case with its [crack] switched off and the PEM method."""
    return paper_case(["crack.enabled=false", "stiffness.method='pem'"])


@pytest.fixture(scope="session")
def healthy(base):
    return PEMModel.from_case(base, cracked=False)


@pytest.fixture(scope="session")
def theta(base):
    """Two pinion revolutions' worth of angles over teeth 9..13 (dense)."""
    tm = 2 * np.pi / base.pinion.teeth
    return np.linspace(8 * tm, 15 * tm, 1401)


def faulty(case, *entries):
    """The fault model of ``case`` with the ``faults`` entries given."""
    c = case.with_overrides({"faults": list(entries)})
    return fault_model_from_case(c, faults_from_case(c))
