"""``geardyn run --quick``: shorter simulations and coarser stiffness maps (issue 16.6)."""

from __future__ import annotations

import geardyn
from geardyn.studies.paper import QUICK_CENTRE_DISTANCES, QUICK_REFINEMENT, _map_case, _simulation_case


def test_quick_coarsens_the_maps_and_shortens_the_records_only_with_quick():
    case = geardyn.paper_case()
    assert _map_case(case, False) is case and _simulation_case(case, False) is case
    q = _map_case(case, True)
    assert q.stiffness.fe.refinement == QUICK_REFINEMENT < case.stiffness.fe.refinement
    assert q.stiffness.centre_distances == QUICK_CENTRE_DISTANCES < case.stiffness.centre_distances
    # everything else is the case's
    back = q.with_overrides({"stiffness.fe.refinement": case.stiffness.fe.refinement,
                             "stiffness.centre_distances": case.stiffness.centre_distances})
    for section in ("pair", "pinion", "gear", "material", "stiffness", "simulation", "crack"):
        assert getattr(back, section).model_dump() == getattr(case, section).model_dump()
    s = _simulation_case(case, True)
    assert s.simulation.record_time < case.simulation.record_time
    # already coarse: unchanged
    coarse = case.with_overrides({"stiffness.method": "pem", "stiffness.centre_distances": 5})
    assert _map_case(coarse, True) is coarse
