"""Shared, session-wide fixtures of the measurement tests: a short run of the paper study's
measurement stage on coarse PEM maps (built once in the tests' private cache)."""

from __future__ import annotations

import warnings

import pytest

#: Coarse PEM maps and a short settling time: the paper case otherwise (1 s record).
FAST_STUDY = {"stiffness.method": "pem", "stiffness.centre_distances": 6,
              "stiffness.nodes_per_segment": 8, "simulation.settle_time": 0.1,
              "simulation.record_time": 1.0}


@pytest.fixture(scope="session")
def measured_study(_private_cache):
    """``(case, result)`` after the measurement stage of :mod:`geardyn.studies.paper` on the
    paper case (model II, PEM, 1 s records): maps, the stage's two ideal records (healthy and
    cracked) as the simulation stage would leave them, and ``summary["measurement"]``."""
    from geardyn.config import paper_case
    from geardyn.stiffness import build_map
    from geardyn.studies.paper import (
        UNDEFINED_BASELINE_REASON,
        cached_simulation,
        healthy_baseline_is_periodic,
    )
    from geardyn.studies.paper_measurement import measurement_stage
    from geardyn.studies.paper_result import StudyResult

    case = paper_case().with_overrides(FAST_STUDY)
    result = StudyResult(out=None)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        result.maps = {s: build_map(case, cracked=s == "cracked") for s in ("healthy", "cracked")}
        result.sims = {("II", s): cached_simulation(case, result.maps[s], "II")
                       for s in ("healthy", "cracked")}
    if healthy_baseline_is_periodic(result.maps["healthy"]):
        result.summary["condition_metrics_undefined"] = {"NA4star": UNDEFINED_BASELINE_REASON}
    measurement_stage(case, case, result, simulate=cached_simulation)
    return case, result
