"""Geometry of an unequal, profile-shifted pair (17/40), where pinion and gear cannot be confused.

The paper's pair is 23/23 with no shift, so every pinion/gear mix-up (a base radius, a tip radius
or a roll angle taken from the wrong gear) is invisible on it. Here z1 = 17, z2 = 40, m = 4 mm,
alpha = 20 deg, x1 = +0.4, x2 = +0.1, and each value is computed in the test by the textbook
formula (ISO 21771; Litvin & Fuentes 2004, ch. 10) from the radii written out by hand, not through
geardyn. The literal numbers were worked out with mpmath at 30 digits from the same formulas
(docs/verification/geometry.md).
"""

from __future__ import annotations

import math

import numpy as np
import pytest

from geardyn import Gear, GearPair
from geardyn.geometry import (
    centre_distance_from_displacements,
    inv,
    inv_inverse,
    static_operating_point,
)

DEG = math.pi / 180
M, ALPHA, Z1, Z2, X1, X2 = 4e-3, 20 * DEG, 17, 40, 0.4, 0.1


@pytest.fixture(scope="module")
def pair() -> GearPair:
    mk = dict(module=M, pressure_angle=ALPHA, face_width=0.02, bore_radius=0.01)
    return GearPair(Gear(teeth=Z1, profile_shift=X1, **mk),
                    Gear(teeth=Z2, profile_shift=X2, **{**mk, "bore_radius": 0.03}))


# ----------------------------------------------------------------- the radii, by hand
R1, R2 = Z1 * M / 2, Z2 * M / 2                       # 34 mm, 80 mm
RB1, RB2 = R1 * math.cos(ALPHA), R2 * math.cos(ALPHA)  # 31.9495 mm, 75.1754 mm
RA1, RA2 = R1 + (1 + X1) * M, R2 + (1 + X2) * M        # 39.6 mm, 84.4 mm
RF1, RF2 = R1 - (1.25 - X1) * M, R2 - (1.25 - X2) * M  # 30.6 mm, 75.4 mm
PB = math.pi * M * math.cos(ALPHA)


def _alpha_w() -> float:
    """inv(alpha_w) = inv(alpha) + 2 tan(alpha) (x1 + x2)/(z1 + z2), solved by bisection."""
    target = math.tan(ALPHA) - ALPHA + 2 * math.tan(ALPHA) * (X1 + X2) / (Z1 + Z2)
    lo, hi = ALPHA, 1.2
    for _ in range(200):
        mid = (lo + hi) / 2
        lo, hi = (mid, hi) if math.tan(mid) - mid < target else (lo, mid)
    return (lo + hi) / 2


AW = _alpha_w()
A_W = (RB1 + RB2) / math.cos(AW)  # zero-backlash centre distance


def _textbook_contact_ratio(d: float) -> float:
    """epsilon = [sqrt(ra1^2 - rb1^2) + sqrt(ra2^2 - rb2^2) - d sin(alpha')] / (pi m cos alpha)."""
    ao = math.acos((RB1 + RB2) / d)
    return (math.sqrt(RA1 ** 2 - RB1 ** 2) + math.sqrt(RA2 ** 2 - RB2 ** 2)
            - d * math.sin(ao)) / (math.pi * M * math.cos(ALPHA))


def _tip_angle_contact_ratio(d: float) -> float:
    """The equivalent form sum_i z_i (tan alpha_ai - tan alpha')/(2 pi) (as in GEARpie)."""
    ao = math.acos((RB1 + RB2) / d)
    return sum(z * (math.tan(math.acos(rb / ra)) - math.tan(ao))
               for z, rb, ra in ((Z1, RB1, RA1), (Z2, RB2, RA2))) / (2 * math.pi)


def test_radii_by_hand(pair):
    p, g = pair.pinion, pair.gear
    assert (p.base_radius, g.base_radius) == pytest.approx((RB1, RB2), rel=1e-14)
    assert (p.tip_radius, g.tip_radius) == pytest.approx((RA1, RA2), rel=1e-14)
    assert (p.root_radius, g.root_radius) == pytest.approx((RF1, RF2), rel=1e-14)
    assert RB1 == pytest.approx(31.949549e-3, abs=1e-9)
    assert RB2 == pytest.approx(75.175410e-3, abs=1e-9)
    assert pair.ratio == pytest.approx(40 / 17, rel=1e-15)
    assert pair.mesh_angle == pytest.approx(2 * math.pi / 17, rel=1e-15)
    assert pair.base_pitch == pytest.approx(PB, rel=1e-14)
    assert pair.checks() == []


def test_working_pressure_angle_and_centre_distance(pair):
    assert math.degrees(AW) == pytest.approx(22.4246986, abs=1e-6)  # mpmath, 30 digits
    assert pair.working_pressure_angle == pytest.approx(AW, abs=1e-12)
    assert pair.design_centre_distance == pytest.approx(A_W, rel=1e-12)
    assert A_W == pytest.approx(115.8882323e-3, abs=1e-9)
    # the pitch point divides the LOA in the ratio of the base radii
    assert pair.pitch_point_s == pytest.approx(RB1 * math.tan(AW), rel=1e-12)
    assert pair.design_t1t2 - pair.pitch_point_s == pytest.approx(RB2 * math.tan(AW), rel=1e-12)


@pytest.mark.parametrize(("dd", "eps_hand", "s0_hand"), [
    (0.0, 1.486673088, 5.840871004e-3),
    (0.5e-3, 1.377040878, 7.135465774e-3),
])
def test_contact_interval_and_ratio_use_each_gears_own_radii(pair, dd, eps_hand, s0_hand):
    """Start of contact at the gear tip: s0 = T1T2 - sqrt(ra2^2 - rb2^2); end at the pinion tip:
    s1 = sqrt(ra1^2 - rb1^2). With the gear's base radius replaced by the pinion's the contact
    ratio would be 4.85 instead of 1.49."""
    d = A_W + dd
    ao = math.acos((RB1 + RB2) / d)
    t1t2 = (RB1 + RB2) * math.tan(ao)
    op = pair.operating(dd)
    assert op.pressure_angle == pytest.approx(ao, abs=1e-13)
    assert op.t1t2 == pytest.approx(t1t2, rel=1e-12)
    assert op.s_start == pytest.approx(t1t2 - math.sqrt(RA2 ** 2 - RB2 ** 2), abs=1e-13)
    assert op.s_end == pytest.approx(math.sqrt(RA1 ** 2 - RB1 ** 2), abs=1e-13)
    assert op.s_start == pytest.approx(s0_hand, abs=1e-11)
    assert op.s_end == pytest.approx(23.39628842e-3, abs=1e-11)
    assert op.contact_ratio == pytest.approx(_textbook_contact_ratio(d), abs=1e-12)
    assert op.contact_ratio == pytest.approx(_tip_angle_contact_ratio(d), abs=1e-12)
    assert op.contact_ratio == pytest.approx(eps_hand, abs=1e-8)
    # eq. 8 of the paper differs from the physical ratio only by cos(alpha)/cos(alpha')
    assert op.contact_ratio_eq8 == pytest.approx(
        op.contact_ratio * math.cos(ALPHA) / math.cos(ao), rel=1e-12)
    # normal backlash from the design (shifted) working angle, not from alpha
    jn = 2 * (RB1 + RB2) * ((math.tan(ao) - ao) - (math.tan(AW) - AW))
    assert op.normal_backlash == pytest.approx(jn, abs=1e-15)
    assert op.closing_rotation == pytest.approx(jn / RB1, rel=1e-12)


def test_contact_points_sit_on_each_gears_own_circles(pair):
    """At the start of contact the point is on the gear's tip circle, at the end on the pinion's;
    at the design pitch point the radii are the operating pitch radii r_bi / cos(alpha_w) and both
    roll angles equal tan(alpha_w)."""
    op = pair.operating(0.0)
    w = pair.mesh_angle
    cp = pair.contact_points(0.0)
    k = int(np.flatnonzero(cp.pair == 0)[0])
    assert cp.pinion_radius[k] == pytest.approx(RB1 / math.cos(AW), rel=1e-12)
    assert cp.gear_radius[k] == pytest.approx(RB2 / math.cos(AW), rel=1e-12)
    assert cp.pinion_roll[k] == pytest.approx(math.tan(AW), rel=1e-12)
    assert cp.gear_roll[k] == pytest.approx(math.tan(AW), rel=1e-12)
    # pinion angle that brings pair 0 to the start and to the end of contact
    t_start = (op.s_start - pair.pitch_point_s) / RB1
    t_end = (op.s_end - pair.pitch_point_s) / RB1
    c0 = pair.contact_points(t_start)
    j = int(np.flatnonzero(c0.pair == 0)[0])
    assert c0.gear_radius[j] == pytest.approx(RA2, rel=1e-12)
    assert c0.gear_roll[j] == pytest.approx(math.sqrt(RA2 ** 2 - RB2 ** 2) / RB2, rel=1e-12)
    c1 = pair.contact_points(t_end)
    j = int(np.flatnonzero(c1.pair == 0)[0])
    assert c1.pinion_radius[j] == pytest.approx(RA1, rel=1e-12)
    # teeth numbered modulo their own tooth counts
    cp = pair.contact_points(0.0)
    np.testing.assert_array_equal(cp.pinion_tooth, np.mod(cp.pair, 17))
    np.testing.assert_array_equal(cp.gear_tooth, np.mod(cp.pair, 40))
    # the mean number of pairs in contact over one mesh period is the contact ratio
    thetas = np.linspace(0.0, w, 3001, endpoint=False)
    n = np.array([pair.contact_points(t).in_contact.sum() for t in thetas])
    assert np.mean(n) == pytest.approx(_textbook_contact_ratio(A_W), abs=1e-3)


def test_largest_centre_distance_keeps_contact_ratio_one(pair):
    limit = pair.max_centre_distance_change()
    assert _textbook_contact_ratio(A_W + limit) == pytest.approx(1.0, abs=1e-12)
    assert pair.operating(limit).contact_ratio == pytest.approx(1.0, abs=1e-12)


def test_static_point_of_an_unequal_pair_with_unequal_bearings(pair):
    """N = T / r_b1 (the pinion's base radius); y_p = -N/k_p, y_g = +N/k_g; eq. 4."""
    torque, kp, kg = 40.0, 2e6, 5e6
    n = torque / RB1
    t1t2 = (RB1 + RB2) * math.tan(AW) + n / kg + n / kp
    d = math.hypot(RB1 + RB2, t1t2)
    op = static_operating_point(pair, torque, kp, kg)
    assert op.centre_distance == pytest.approx(d, rel=1e-13)
    assert op.t1t2 == pytest.approx(t1t2, rel=1e-12)
    assert centre_distance_from_displacements(pair, -n / kp, n / kg) == pytest.approx(d, rel=1e-13)


def test_involute_function_against_series():
    """inv(a) = a^3/3 + 2 a^5/15 + 17 a^7/315 + ... (tan series), and its inverse."""
    for a in (0.05, 0.1, 0.2):
        series = a ** 3 / 3 + 2 * a ** 5 / 15 + 17 * a ** 7 / 315 + 62 * a ** 9 / 2835
        assert float(inv(a)) == pytest.approx(series, rel=1e-6)
        assert inv_inverse(series) == pytest.approx(a, rel=1e-6)
    assert inv_inverse(0.0) == 0.0
