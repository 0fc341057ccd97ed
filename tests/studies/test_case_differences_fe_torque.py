"""The paper comparison reads the FE map's torque as used: omitted means motor.torque."""

from __future__ import annotations

import geardyn
from geardyn.studies.paper_values import case_differences


def test_explicit_fe_torque_equal_to_the_operating_torque_is_the_paper_case():
    assert case_differences(geardyn.paper_case({"stiffness.fe.torque": 100.0})) == ([], [])
    inputs, _ = case_differences(geardyn.paper_case({"stiffness.fe.torque": 120.0}))
    assert inputs == [{"key": "stiffness.fe.torque", "paper": 100.0, "case": 120.0}]
    # a new operating torque moves the map's torque with it, and both are listed
    keys = [r["key"] for r in case_differences(geardyn.paper_case({"motor.torque": 120.0}))[0]]
    assert keys == ["motor.torque", "stiffness.fe.torque"]
