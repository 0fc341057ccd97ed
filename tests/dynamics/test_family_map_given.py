"""A load-family case (``stiffness.fe.torques``) given another map: refused, before any FE work.
It ran on the family's cracked FE maps while the record named the given healthy PEM map (a
user audit, 2026-11-27)."""

from __future__ import annotations

import pytest

import geardyn
from geardyn.errors import InputError
from geardyn.stiffness import build_map


def test_another_map_for_a_family_case_is_refused():
    case = geardyn.paper_case({"stiffness.method": "fe", "simulation.record_time": "0.1 s",
                               "stiffness.centre_distances": 4,
                               "stiffness.nodes_per_segment": 8})
    family = case.with_overrides({"stiffness.fe.torques": [80.0, 100.0, 120.0]})
    pem = build_map(case, method="pem", cracked=False)
    with pytest.raises(InputError) as err:
        geardyn.simulate(family, pem)
    assert err.value.field == "stiffness_map"
    assert err.value.value == "a pem map of other inputs than the case's"
    assert "stiffness.fe.torques" in err.value.allowed
    # without the family the same map is simulated as given (it names itself in the record)
    ds = geardyn.simulate(case.with_overrides({"simulation.model": "I"}), pem, cracked=False)
    assert ds.attrs["stiffness_method"] == "pem"
