"""Independent oracles for the PEM terms that used to be checked only against themselves.

* The Sainsot, Velex & Duverger (2004) foundation term re-evaluated in the test from the formula
  and coefficient table as transcribed by ROSS (``ross/gear_element.py``, ``_inv_kf``) and PHM-BGU
  (``calcInvFilletFoundationStiff.m``), typed here independently of geardyn's table; tolerance
  1e-12 relative (a flipped sign of the Q* term moves it by several per cent).
* The root half-angle of each literature definition from its closed form
  (docs/verification/stiffness.md, section "root half-angle").
* An unequal, shifted pair (17/40): every pair stiffness is rebuilt from the two teeth's own
  sections and roll angles, so a pinion/gear mix-up shows.
"""

from __future__ import annotations

import math
import warnings

import numpy as np
import pytest

from geardyn import Gear, GearPair, paper_case
from geardyn.errors import InputError
from geardyn.stiffness.pem import (
    PEMModel,
    SainsotRangeWarning,
    ToothSection,
    foundation_compliance,
    hertz_compliance,
    sainsot_validity,
    tooth_compliance_quad,
)
from geardyn.stiffness.pem.foundation import root_half_angle

DEG = math.pi / 180
E, NU, B = 206e9, 0.3, 0.02
QUAD = {"epsabs": 0.0, "epsrel": 1e-10}  # adaptive quad: relative accuracy, far below 1e-6

# Sainsot et al. (2004) coefficients A, B, C, D, E, F of L*, M*, P*, Q* as printed in ROSS's
# _inv_kf (poly_coeffs) and PHM-BGU's coefficient matrix.
_TABLE = {
    "L": (-5.574e-5, -1.9986e-3, -2.3015e-4, 4.7702e-3, 0.0271, 6.8045),
    "M": (60.111e-5, 28.100e-3, -83.431e-4, -9.9256e-3, 0.1624, 0.9086),
    "P": (-50.952e-5, 185.50e-3, 0.0538e-4, 53.300e-3, 0.2895, 0.9236),
    "Q": (-6.2042e-5, 9.0889e-3, -4.0964e-4, 7.8297e-3, -0.1472, 0.6904),
}


def _sainsot_by_hand(rb, rf, r_int, theta_f, alpha_2, roll, e, width):
    """delta_f / F = cos^2(a1)/(E L) {L* (u/S)^2 + M* u/S + P* (1 + Q* tan^2 a1)}, with
    a1 = roll - alpha_2, u = r_b / cos(a1) - r_f (load line meets the centreline, PHM-BGU's
    u = X - r_f - Y tan(a1) for the load point (X, Y)) and S = 2 r_f theta_f."""
    h = rf / r_int
    x = {k: a / theta_f ** 2 + b * h ** 2 + c * h / theta_f + d / theta_f + ee * h + f
         for k, (a, b, c, d, ee, f) in _TABLE.items()}
    a1 = roll - alpha_2
    # the load point on the involute at roll u: height X and half-thickness Y (Tian 2004)
    t = alpha_2 - roll
    big_x = rb * (math.cos(t) - roll * math.sin(t))
    big_y = rb * (roll * math.cos(t) + math.sin(t))
    u = big_x - rf - big_y * math.tan(a1)
    s = 2 * rf * theta_f
    return math.cos(a1) ** 2 / (e * width) * (
        x["L"] * (u / s) ** 2 + x["M"] * (u / s) + x["P"] * (1 + x["Q"] * math.tan(a1) ** 2))


@pytest.fixture(scope="module")
def paper_pinion() -> Gear:
    return paper_case().gear_pair().pinion


@pytest.fixture(scope="module")
def unequal() -> GearPair:
    mk = dict(module=4e-3, pressure_angle=20 * DEG, face_width=B)
    return GearPair(Gear(teeth=17, profile_shift=0.4, bore_radius=0.012, **mk),
                    Gear(teeth=40, profile_shift=0.1, bore_radius=0.03, **mk))


@pytest.mark.parametrize("which", ["paper", "pinion17", "gear40"])
def test_foundation_term_against_the_published_formula(which, paper_pinion, unequal):
    g = {"paper": paper_pinion, "pinion17": unequal.pinion, "gear40": unequal.gear}[which]
    rb, a2 = g.base_radius, g.base_half_angle
    u_lo = g.form_roll_length / rb
    u_hi = math.sqrt((g.tip_radius / rb) ** 2 - 1)
    rolls = [u_lo + f * (u_hi - u_lo) for f in (0.1, 0.5, 0.9)]
    for theta_f in (g.root_half_angle, 0.09):
        got = foundation_compliance(g, rolls, E, B, theta_f=theta_f)
        want = [_sainsot_by_hand(rb, g.root_radius, g.bore_radius, theta_f, a2, r, E, B)
                for r in rolls]
        np.testing.assert_allclose(got, want, rtol=1e-12)
    # the default theta_f is the generated outline's
    np.testing.assert_allclose(foundation_compliance(g, rolls, E, B),
                               foundation_compliance(g, rolls, E, B, theta_f=g.root_half_angle),
                               rtol=1e-15)


def test_foundation_term_literal_value_at_the_paper_pitch_point(paper_pinion):
    """At the pitch point (roll tan 20 deg) of the paper's pinion, per metre of width: 1/k_f =
    3.2e-11 m^2/N with theta_f = alpha_3 (the design table, docs/verification/stiffness.md) and
    2.49e-11 m^2/N with the default theta_f = 3.013/z (a wider root chord is stiffer)."""
    roll = math.tan(20 * DEG)
    a3 = root_half_angle(paper_pinion, "alpha3")
    for theta_f, per_width in ((a3, 3.2e-11), (paper_pinion.root_half_angle, 2.49e-11)):
        want = _sainsot_by_hand(paper_pinion.base_radius, 61.5e-3, 20e-3, theta_f,
                                paper_pinion.base_half_angle, roll, E, B)
        got = foundation_compliance(paper_pinion, [roll], E, B, theta_f=theta_f)[0]
        assert got == pytest.approx(want, rel=1e-12)
        assert got * B == pytest.approx(per_width, rel=0.01)


def test_root_half_angle_definitions_from_their_closed_forms(paper_pinion, unequal):
    """fillet: [pi/2 + 2 tan a (h_a* + c* - rho*) + 2 rho*/cos a]/z (rack tip reaching the root
    circle, x = 0); ross: the same with h_a* alone; alpha3 = arcsin(r_b sin(alpha_2)/r_f)."""
    g = paper_pinion
    a, rho = 20 * DEG, 0.25 / (1 - math.sin(20 * DEG))
    fillet = (math.pi / 2 + 2 * math.tan(a) * (1.25 - rho) + 2 * rho / math.cos(a)) / 23
    ross = (math.pi / 2 + 2 * math.tan(a) * (1.0 - rho) + 2 * rho / math.cos(a)) / 23
    a2 = math.pi / 46 + math.tan(a) - a
    alpha3 = math.asin(69e-3 * math.cos(a) * math.sin(a2) / 61.5e-3)
    assert root_half_angle(g, "fillet") == pytest.approx(fillet, rel=1e-9)
    assert root_half_angle(g, "ross") == pytest.approx(ross, rel=1e-12)
    assert root_half_angle(g, "alpha3") == pytest.approx(alpha3, rel=1e-12)
    assert (fillet * 23, ross * 23, alpha3) == pytest.approx((3.0128, 2.8308, 0.08773), abs=1e-4)
    assert root_half_angle(g, 0.1) == 0.1
    for bad in ("rectangle", -0.1, math.pi / 23):
        with pytest.raises(InputError, match="foundation_half_angle"):
            root_half_angle(g, bad)
    # a root circle above the base circle has no alpha_3
    with pytest.raises(InputError, match="alpha3"):
        root_half_angle(Gear(teeth=60, module=4e-3, pressure_angle=20 * DEG, bore_radius=0.03),
                        "alpha3")
    # each gear its own: the 40-tooth gear's theta_f is not the 17-tooth pinion's
    assert root_half_angle(unequal.gear) != pytest.approx(root_half_angle(unequal.pinion), rel=0.1)


def test_half_angle_is_a_case_option():
    case = paper_case()
    assert case.stiffness.foundation_half_angle == "fillet"
    for choice, z_theta in (("ross", 2.8308), ("alpha3", 0.08773 * 23)):
        pem = PEMModel.from_case(case.with_overrides({"stiffness.foundation_half_angle": choice}),
                                 cracked=False)
        assert pem.theta_f["pinion"] * 23 == pytest.approx(z_theta, abs=1e-3)
        assert pem.parameters()["foundation_half_angle"] == choice
    pem = PEMModel.from_case(case.with_overrides({"stiffness.foundation_half_angle": "6 deg"}),
                             cracked=False)
    assert pem.theta_f["gear"] == pytest.approx(6 * DEG, rel=1e-12)
    with pytest.raises(InputError, match="foundation_half_angle"):
        case.with_overrides({"stiffness.foundation_half_angle": "rectangle"})


def test_smaller_half_angle_softens_the_mesh_as_documented():
    """K(fillet) > K(ross) > K(alpha3): -2.1 % and -16 % in the mean over a mesh period on the
    paper's pair (docs/verification/stiffness.md); the foundation is the only term that changes."""
    case = paper_case()
    th = np.linspace(0, 2 * math.pi / 23, 48, endpoint=False)
    k = {c: PEMModel.from_case(case.with_overrides({"stiffness.foundation_half_angle": c}),
                               cracked=False).mesh_stiffness(th).mean()
         for c in ("fillet", "ross", "alpha3")}
    assert k["ross"] / k["fillet"] == pytest.approx(0.979, abs=0.003)
    assert k["alpha3"] / k["fillet"] == pytest.approx(0.843, abs=0.005)


def test_paper_case_builds_without_a_range_warning():
    """The shipped case is inside the fitted coefficient envelope (ROSS's live check) and h_f
    range, so no SainsotRangeWarning; the unsourced theta_f box is reported as a note."""
    case = paper_case()
    pem = PEMModel.from_case(case, cracked=False)
    assert pem.validity_warnings() == []
    assert any("theta_f" in m for m in pem.validity_warnings(notes=True))
    g = case.gear_pair().pinion
    with warnings.catch_warnings():
        warnings.simplefilter("error", SainsotRangeWarning)
        foundation_compliance(g, [0.4], E, B, warn=True)
    # a small bore (h_f = 61.5/8 = 7.7 > 7) still warns, naming h_f
    small_bore = Gear(23, 6e-3, 20 * DEG, bore_radius=8e-3)
    assert any("h_f" in m for m in sainsot_validity(small_bore))
    with pytest.warns(SainsotRangeWarning, match="h_f"):
        foundation_compliance(small_bore, [0.4], E, B, warn=True)
    # a very thin root (theta_f = 0.01 rad) leaves the coefficient envelope: L* = 6.718 < 6.82
    assert any(m.startswith("L* = 6.718") for m in sainsot_validity(g, 0.01))


def test_unequal_pair_stiffness_from_each_teeths_own_section(unequal):
    """Each pair's stiffness is 1/(1/k_h + c_pinion(phi_1) + c_gear(phi_2)) with the pinion
    tooth at its roll s/r_b1 and the gear tooth at (T1T2 - s)/r_b2 (adaptive quad, from
    scratch); the load shares sum to one and the number of pairs matches the geometry."""
    pem = PEMModel(unequal, E, NU, face_width=B)
    sec_p, sec_g = ToothSection(unequal.pinion), ToothSection(unequal.gear)
    kh = math.pi * E * B / (4 * (1 - NU ** 2))
    assert 1 / hertz_compliance(E, NU, B) == pytest.approx(kh, rel=1e-14)
    for dd in (0.0, 0.3e-3):
        for theta in (0.0, 0.11, 0.27):
            out = pem.evaluate([theta], dd)
            cp = unequal.contact_points(theta, dd)
            on = cp.in_contact
            assert out["pairs_in_contact"][0] == on.sum()
            k = [1 / (1 / kh + tooth_compliance_quad(sec_p, r1, E, NU, B, **QUAD)
                      + tooth_compliance_quad(sec_g, r2, E, NU, B, **QUAD))
                 for r1, r2 in zip(cp.pinion_roll[on], cp.gear_roll[on], strict=True)]
            assert out["k_mb"][0] == pytest.approx(sum(k), rel=1e-6)
            got_rolls = np.sort(out["pinion_roll"][0][np.isfinite(out["pinion_roll"][0])])
            np.testing.assert_allclose(got_rolls, np.sort(cp.pinion_roll[on]), rtol=1e-12)
            assert out["load_share"][0].sum() == pytest.approx(1.0, abs=1e-12)
    # the two teeth differ: swapping the sections would change the pair stiffness
    r = unequal.contact_points(0.0).pinion_roll[0]
    assert tooth_compliance_quad(sec_g, r, E, NU, B, **QUAD) != pytest.approx(
        tooth_compliance_quad(sec_p, r, E, NU, B, **QUAD), rel=0.02)
