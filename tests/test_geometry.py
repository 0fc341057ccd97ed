"""Geometry of the involute pair against closed-form values and the paper's numbers.

Oracles: docs/verification/geometry.md and docs/verification/dynamics.md "Static point" (recomputed
from the paper's Table 1 with the corrected base radius, erratum 1).
"""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from geardyn import Gear, GearPair, InputError, paper_case
from geardyn.errors import GeometryError
from geardyn.geometry import (
    centre_distance_from_displacements,
    inv,
    inv_inverse,
    static_operating_point,
)

DEG = math.pi / 180


@pytest.fixture(scope="module")
def pair() -> GearPair:
    return paper_case().gear_pair()


def test_paper_radii_and_pitch(pair):
    p = pair.pinion
    assert p.pitch_radius == pytest.approx(69e-3, abs=1e-12)
    assert p.base_radius == pytest.approx(64.8388e-3, abs=1e-7)
    assert p.tip_radius == pytest.approx(75e-3, abs=1e-12)
    assert p.root_radius == pytest.approx(61.5e-3, abs=1e-12)
    assert pair.base_pitch == pytest.approx(17.7128e-3, abs=1e-7)
    # erratum 1: Table 1's "129.7 mm" is r_b1 + r_b2
    assert pair.base_radius_sum == pytest.approx(129.7e-3, abs=0.05e-3)
    assert pair.design_centre_distance == pytest.approx(138e-3, rel=1e-14)


def test_paper_fillet_values(pair):
    """Trochoid fillet: rho = 2.2797 mm, form radius 65.121 mm, theta_f = 3.0128/z (stiffness.md)."""
    g = pair.pinion
    assert g.tool_tip_radius == pytest.approx(2.2797e-3, abs=1e-7)
    assert g.form_radius == pytest.approx(65.121e-3, abs=1e-6)
    assert g.root_half_angle == pytest.approx(0.13099, abs=1e-5)
    assert g.root_half_angle * g.teeth == pytest.approx(3.0128, abs=1e-4)


@pytest.mark.parametrize(
    ("dd_mm", "alpha_deg", "eps", "eps8"),
    [(0.0, 20.0, 1.5916, 1.5916), (0.5, 20.5608, 1.5102, 1.5156),
     (1.0, 21.1034, 1.4308, 1.4412), (1.07, 21.178, 1.4198, 1.4308)],
)
def test_operating_pressure_angle_and_contact_ratio(pair, dd_mm, alpha_deg, eps, eps8):
    op = pair.operating(dd_mm * 1e-3)
    assert math.degrees(op.pressure_angle) == pytest.approx(alpha_deg, abs=6e-4)
    assert op.contact_ratio == pytest.approx(eps, abs=6e-5)
    assert op.contact_ratio_eq8 == pytest.approx(eps8, abs=6e-5)
    assert op.contact_ratio_by("paper_eq8") == op.contact_ratio_eq8


def test_contact_interval_and_backlash(pair):
    op0 = pair.operating(0.0)
    assert op0.s_start == pytest.approx(9.504e-3, abs=1e-6)
    assert op0.s_end == pytest.approx(37.695e-3, abs=1e-6)
    assert op0.t1t2 == pytest.approx(47.199e-3, abs=1e-6)
    assert op0.normal_backlash == pytest.approx(0.0, abs=1e-15)
    op1 = pair.operating(1.0e-3)
    assert op1.normal_backlash == pytest.approx(702e-6, abs=1e-6)
    # small-change approximations: j_n ~ 2 dd sin(alpha), circumferential ~ 2 dd tan(alpha)
    assert op1.normal_backlash == pytest.approx(2e-3 * math.sin(20 * DEG), rel=0.03)
    assert op1.circumferential_backlash == pytest.approx(2e-3 * math.tan(20 * DEG), rel=0.04)
    assert op1.closing_rotation == pytest.approx(op1.normal_backlash / pair.pinion.base_radius)


def test_contact_fractions(pair):
    op = pair.operating(1.0e-3)
    assert op.single_contact_fraction == pytest.approx(2 - op.contact_ratio)
    assert op.double_contact_fraction == pytest.approx(op.contact_ratio - 1)


def test_eq4_zero_displacement_gives_design(pair):
    assert centre_distance_from_displacements(pair, 0.0, 0.0) == pytest.approx(
        pair.design_centre_distance, rel=1e-15)
    arr = centre_distance_from_displacements(pair, np.zeros(3), np.zeros(3))
    np.testing.assert_allclose(arr, pair.design_centre_distance, rtol=1e-15)


def test_static_operating_point(pair):
    """N = T/r_b = 1542.3 N; y_g - y_p = 3.0846 mm; dd = 1.0852 mm (dynamics.md)."""
    op = static_operating_point(pair, 100.0, 1e6, 1e6)
    assert 100.0 / pair.pinion.base_radius == pytest.approx(1542.3, abs=0.05)
    assert op.centre_distance_change == pytest.approx(1.0852e-3, abs=1e-7)
    assert math.degrees(op.pressure_angle) == pytest.approx(21.194, abs=1e-3)


@settings(max_examples=60, deadline=None)
@given(a=st.floats(0.0, 3.5e-3), b=st.floats(0.0, 3.5e-3))
def test_monotonic_in_centre_distance(pair, a, b):
    lo, hi = sorted((a, b))
    if hi - lo < 1e-9:
        return
    op_lo, op_hi = pair.operating(lo), pair.operating(hi)
    assert op_hi.contact_ratio < op_lo.contact_ratio
    assert op_hi.contact_ratio_eq8 < op_lo.contact_ratio_eq8
    assert op_hi.pressure_angle > op_lo.pressure_angle
    assert op_hi.normal_backlash > op_lo.normal_backlash


def test_contact_ratio_below_one_is_refused(pair):
    limit = pair.max_centre_distance_change()
    assert pair.operating(limit - 1e-9).contact_ratio == pytest.approx(1.0, abs=1e-6)
    with pytest.raises(GeometryError, match="centre_distance_change"):
        pair.operating(limit + 1e-6)
    assert pair.checks(limit + 1e-6)  # reported by checks() too
    with pytest.raises(GeometryError):
        pair.operating(-0.2)  # below r_b1 + r_b2


def test_contact_points_follow_the_loa(pair):
    rb1, pb = pair.pinion.base_radius, pair.base_pitch
    cp = pair.contact_points(0.0)
    # pinion tooth 0 at the design pitch point at theta = 0
    k = int(np.flatnonzero(cp.pinion_tooth == 0)[0])
    assert cp.s[k] == pytest.approx(rb1 * math.tan(20 * DEG), abs=1e-15)
    assert cp.pinion_roll[k] == pytest.approx(math.tan(20 * DEG))
    # gear roll at the pitch point is the same (equal gears)
    assert cp.gear_roll[k] == pytest.approx(math.tan(20 * DEG), abs=1e-12)
    # radius on the pinion at the pitch point is the pitch radius
    assert cp.pinion_radius[k] == pytest.approx(pair.pinion.pitch_radius, rel=1e-12)
    # consecutive pairs one base pitch apart; number in contact matches the contact ratio
    assert np.allclose(np.diff(cp.s), pb)
    thetas = np.linspace(0, 2 * math.pi / 23, 2001, endpoint=False)
    for dd in (0.0, 0.5e-3, 1.0e-3):
        n = np.array([pair.contact_points(t, dd).in_contact.sum() for t in thetas])
        assert np.mean(n) == pytest.approx(pair.operating(dd).contact_ratio, abs=2e-3)


def test_tooth_outline_is_c1_at_the_form_circle(pair):
    """The trochoid fillet meets the involute with no gap and a common tangent; the kink angle
    measured on chords falls linearly with the sampling step (it is the chord error only)."""
    g = pair.pinion
    kinks = []
    for n in (400, 1600):
        o = g.outline(n_involute=n, n_fillet=n)
        assert np.linalg.norm(o.involute[0] - o.fillet[0]) < 1e-12
        assert np.hypot(*o.involute[0]) == pytest.approx(g.form_radius, abs=1e-12)
        assert np.hypot(*o.fillet[-1]) == pytest.approx(g.root_radius, abs=1e-12)
        assert np.hypot(*o.involute[-1]) == pytest.approx(g.tip_radius, abs=1e-12)
        ti = o.involute[1] - o.involute[0]
        tf = o.fillet[0] - o.fillet[1]
        cosang = ti @ tf / np.linalg.norm(ti) / np.linalg.norm(tf)
        kinks.append(math.acos(min(1.0, cosang)))
    assert kinks[1] < 0.3 * kinks[0]
    assert kinks[1] < math.radians(0.05)


def test_outline_radii_monotonic_and_closed_tooth_symmetric(pair):
    o = pair.pinion.outline()
    r = np.hypot(*o.right_flank().T)
    assert np.all(np.diff(r) > 0)
    tooth = o.closed_tooth()
    np.testing.assert_allclose(tooth[:, 0], -tooth[::-1, 0], atol=1e-15)


def test_involute_inverse_round_trip():
    for a in np.linspace(0.01, 1.2, 50):
        assert inv_inverse(float(inv(a))) == pytest.approx(a, abs=1e-13)


def test_undercut_and_pointed_teeth_are_reported():
    g = Gear(teeth=12, module=0.006, pressure_angle=20 * DEG, face_width=0.02, bore_radius=0.01)
    assert g.undercut
    pointed = Gear(teeth=10, module=0.006, pressure_angle=20 * DEG, profile_shift=1.2,
                   face_width=0.02, bore_radius=0.01)
    assert pointed.pointed
    pair = GearPair(g, Gear(teeth=40, module=0.006, pressure_angle=20 * DEG, face_width=0.02,
                            bore_radius=0.02))
    assert any("undercut" in c for c in pair.checks())
    assert any("interference" in c for c in pair.checks())


@pytest.mark.parametrize(("kwargs", "field"), [
    ({"teeth": 3}, "teeth"), ({"teeth": 22.5}, "teeth"), ({"module": -1.0}, "module"),
    ({"pressure_angle": 50 * DEG}, "pressure_angle"), ({"bore_radius": 0.1}, "bore_radius"),
])
def test_bad_gear_input_names_the_field(kwargs, field):
    base = dict(teeth=23, module=0.006, pressure_angle=20 * DEG, face_width=0.02,
                bore_radius=0.02)
    with pytest.raises(InputError) as exc:
        Gear(**{**base, **kwargs})
    assert exc.value.field == field
    assert "allowed" in str(exc.value)


def test_profile_shift_design_centre_distance():
    """x1 + x2 > 0: inv(alpha_w) = inv(alpha) + 2 tan(alpha)(x1 + x2)/(z1 + z2) and zero
    backlash at the design centre distance (ISO 21771)."""
    mk = dict(module=0.004, pressure_angle=20 * DEG, face_width=0.02, bore_radius=0.01)
    pair = GearPair(Gear(teeth=17, profile_shift=0.4, **mk), Gear(teeth=40, profile_shift=0.1,
                                                                 **mk))
    aw = pair.working_pressure_angle
    assert float(inv(aw)) == pytest.approx(float(inv(20 * DEG)) + 2 * math.tan(20 * DEG) * 0.5
                                           / 57, rel=1e-12)
    assert pair.operating(0.0).normal_backlash == pytest.approx(0.0, abs=1e-12)
    assert pair.design_centre_distance > 0.004 * 57 / 2
