"""The dynamics of an unequal, profile-shifted pair (17/40), where pinion and gear radii differ.

Hand oracles (docs/verification/geometry.md, "Static point"): mesh force N = T / r_b1 with the
pinion's base radius, gear speed w r_b1 / r_b2 = w z1 / z2, gear-side torque N r_b2, and eq. 4
for the centre distance with unequal bearings.
"""

from __future__ import annotations

import math

import numpy as np
import pytest

from geardyn.dynamics import DynamicModel, simulate, static_equilibrium, summary

from ._support import geometric_map, short_case

DEG = math.pi / 180
M = 6e-3
RB1, RB2 = 17 * M / 2 * math.cos(20 * DEG), 40 * M / 2 * math.cos(20 * DEG)


@pytest.fixture(scope="module")
def case():
    return short_case(**{"pinion.teeth": 17, "gear.teeth": 40, "pinion.profile_shift": 0.3,
                         "gear.profile_shift": -0.3, "gear.bore_radius": "40 mm",
                         "pinion.bearing_stiffness": "2e6 N/m",
                         "simulation.record_time": 0.03})


@pytest.fixture(scope="module")
def smap(case):
    return geometric_map(case.gear_pair(), k_pair=1.2e8)


def test_static_point_uses_each_gears_own_radius(case, smap):
    dyn = DynamicModel.from_case(case, smap)
    assert dyn.r_b1 == pytest.approx(RB1, rel=1e-14)
    assert dyn.r_b2 == pytest.approx(RB2, rel=1e-14)
    st = static_equilibrium(dyn, smap, which="II")
    n = 100.0 / RB1
    assert st.mesh_force == pytest.approx(n, rel=1e-12)
    assert st.gear_speed == pytest.approx(st.speed * 17 / 40, rel=1e-12)
    kp, kg = dyn.K0[1, 1], dyn.K0[3, 3]
    assert kp == pytest.approx(2e6) and kg == pytest.approx(1e6)
    assert (st.y_p, st.y_g) == pytest.approx((-n / kp, n / kg), rel=1e-12)
    # x1 + x2 = 0: alpha_w = alpha, so T1T2 = (r_b1 + r_b2) tan 20 deg at the design distance
    t1t2 = (RB1 + RB2) * math.tan(20 * DEG) + n / kg + n / kp
    d = math.hypot(RB1 + RB2, t1t2)
    assert st.centre_distance_change == pytest.approx(d - (RB1 + RB2) / math.cos(20 * DEG),
                                                      rel=1e-10)
    assert st.transmission_error == pytest.approx(
        st.z[2] - RB2 / RB1 * st.z[4], abs=1e-15)


def test_simulated_means_follow_the_static_balance(case, smap):
    """Over the record the mean mesh force is T / r_b1 and the gear turns z1/z2 as fast."""
    ds = simulate(case, smap, model="II")
    s = summary(ds)
    assert s["mean_mesh_force_N"] == pytest.approx(100.0 / RB1, rel=2e-3)
    wg = float(np.mean(ds.omega_g.values))
    assert wg == pytest.approx(s["mean_pinion_speed_rad_s"] * 17 / 40, rel=2e-3)
