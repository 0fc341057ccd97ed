"""Bearings so soft that the static mesh force pushes the teeth out of contact are refused by
name (a user audit, 2026-11-27: ``pinion.bearing_stiffness = "1e3 N/m"`` was refused as a
stiffness map not covering a 1458 mm centre distance change, or as an internal
``centre_distance_change`` without a unit).

Oracle: the limit is where the contact ratio of eq. 4's operating geometry is 1
(:meth:`GearPair.operating` computes it independently of
:meth:`GearPair.max_centre_distance_change`); the bearing stiffness that reaches it is found
by root finding on :func:`static_operating_point`'s centre distance with the check bypassed.
"""

from __future__ import annotations

import math

import pytest
from scipy.optimize import brentq

from geardyn.config import paper_case
from geardyn.errors import GeometryError
from geardyn.geometry import centre_distance_from_displacements, static_operating_point

from .._cli_fork import run_geardyn


def _dd(pair, torque, kyp, kyg):
    n = torque / pair.pinion.base_radius
    return float(centre_distance_from_displacements(pair, -n / kyp, n / kyg)) \
        - pair.design_centre_distance


def test_the_limit_is_where_the_contact_ratio_is_one():
    case = paper_case()
    pair = case.gear_pair()
    torque, kyg = case.motor.torque, case.gear.bearing_stiffness
    # the pinion bearing stiffness that puts the contact ratio at exactly 1
    k_star = brentq(lambda k: pair.operating(_dd(pair, torque, k, kyg), check=False)
                    .contact_ratio - 1.0, 1e4, 1e9, rtol=1e-12)
    op = static_operating_point(pair, torque, k_star * (1 + 1e-6), kyg)
    assert 1.0 <= op.contact_ratio < 1.0 + 1e-5
    with pytest.raises(GeometryError) as info:
        static_operating_point(pair, torque, k_star * (1 - 1e-6), kyg)
    assert info.value.field == "pinion_bearing_stiffness"
    assert math.isclose(info.value.value, k_star * (1 - 1e-6))
    # the softer bearing is named
    with pytest.raises(GeometryError) as info:
        static_operating_point(pair, torque, 1e9, 2e3)
    assert info.value.field == "gear_bearing_stiffness" and "mm apart" in info.value.allowed


@pytest.mark.parametrize("command", [["config", "validate", "soft.toml"],
                                     ["simulate", "--stiffness", "pem", "-c", "soft.toml", "-o",
                                      "s.nc"],
                                     ["run", "--quick", "--stiffness", "pem", "-c", "soft.toml",
                                      "--out", "r"]])
def test_the_commands_name_the_case_field(tmp_path, command):
    (tmp_path / "soft.toml").write_text('extends = "xue_howard"\n[pinion]\n'
                                        'bearing_stiffness = "1e3 N/m"\n')
    r = run_geardyn(command, cwd=tmp_path, env=None, timeout=300)
    assert r.returncode == 2, r.stdout + r.stderr
    assert "Traceback" not in r.stderr
    line = r.stderr.strip()
    assert line.startswith("error: pinion.bearing_stiffness: got "), line
    assert "keep the teeth in contact" in line and "3.9260 mm" in line, line
    assert not (tmp_path / "s.nc").exists()
