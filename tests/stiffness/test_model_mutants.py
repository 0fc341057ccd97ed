"""PEMModel (stiffness/pem/model.py) at its edges: defaults, wiring of the case, the interference
bounds at the bound, refusals in full and the provenance record.

Written against the mutants that survived the first mutation run of ``stiffness/pem/model.py``
(docs/mutation.md, run of issue 20 item 6). Oracles: scipy ``quad`` on a freshly built section
(:func:`tooth_compliance_quad`), the closed-form line-of-action geometry for the interference
bounds (``t1t2 = sqrt(d'^2 - (r_b1 + r_b2)^2)``, ``s_start = t1t2 - sqrt(r_a2^2 - r_b2^2)``),
the Hertz closed form ``4 (1 - nu^2) / (pi E L)`` (Yang & Lin 1987) and values written out by
hand.
"""

from __future__ import annotations

import math
import types

import numpy as np
import pytest

from geardyn import paper_case
from geardyn.errors import GeometryError, InputError
from geardyn.geometry import Gear, GearPair
from geardyn.stiffness.pem import PEMModel, ToothCrack, ToothSection, tooth_compliance_quad

DEG = math.pi / 180
E, NU = 69e9, 0.33


@pytest.fixture(scope="module")
def case():
    return paper_case()


@pytest.fixture(scope="module")
def pair(case):
    return case.gear_pair()


def _bound(pair: GearPair, which: str) -> float:
    """Centre distance change [m] at which contact starts exactly at the form circle of
    ``which`` (closed-form line-of-action geometry; below it the tip of the mate interferes)."""
    p, g = pair.pinion, pair.gear
    rsum = p.base_radius + g.base_radius
    if which == "pinion":
        t = ToothSection(p).u_min * p.base_radius + math.sqrt(g.tip_radius ** 2
                                                              - g.base_radius ** 2)
    else:
        t = ToothSection(g).u_min * g.base_radius + math.sqrt(p.tip_radius ** 2
                                                              - p.base_radius ** 2)
    return math.hypot(rsum, t) - pair.design_centre_distance


# ------------------------------------------------------------------ per-tooth compliance
def test_exact_tooth_compliance_defaults_to_the_healthy_tooth_and_uses_the_models_theta_f(pair):
    """``tooth_compliance_exact`` without ``cracked`` is the healthy tooth even when the model
    has a crack on that gear, and it uses the model's foundation half-angle (here 0.05 rad,
    not the outline's 0.131 rad). Oracle: adaptive quad on freshly built sections."""
    crack = ToothCrack(tooth=3, depth=4e-3)
    pm = PEMModel(pair, E, NU, crack, foundation_half_angle=0.05)
    roll = 0.45
    healthy = tooth_compliance_quad(ToothSection(pair.pinion), roll, E, NU, 0.02, theta_f=0.05)
    cracked = tooth_compliance_quad(ToothSection(pair.pinion, crack), roll, E, NU, 0.02,
                                    theta_f=0.05)
    assert cracked > healthy * 1.001           # the two differ, so the test can tell them apart
    assert pm.tooth_compliance_exact("pinion", roll)[0] == pytest.approx(healthy, rel=1e-9)
    assert pm.tooth_compliance_exact("pinion", roll, True)[0] == pytest.approx(cracked, rel=1e-9)
    fillet = tooth_compliance_quad(ToothSection(pair.gear), roll, E, NU, 0.02)
    assert abs(fillet / healthy - 1) > 1e-3     # theta_f matters at this tolerance
    assert pm.tooth_compliance_exact("gear", roll)[0] == pytest.approx(healthy, rel=1e-9)


def test_torsional_stiffness_defaults_to_the_nominal_centre_distance(pair):
    pm = PEMModel(pair, E, NU)
    th = np.linspace(0.0, 2 * math.pi / 23, 7)
    rb1 = pair.pinion.base_radius
    np.testing.assert_allclose(pm.torsional_stiffness(th), pm.mesh_stiffness(th, 0.0) * rb1 ** 2,
                               rtol=1e-15)


# ------------------------------------------------------------------ case wiring
def test_from_case_crack_only_when_asked_and_enabled(case):
    assert PEMModel.from_case(case).crack == ToothCrack.from_config(case.crack)
    assert PEMModel.from_case(case, cracked=False).crack is None
    off = case.with_overrides({"crack.enabled": False})
    assert PEMModel.from_case(off, cracked=True).crack is None
    assert PEMModel.from_case(off, cracked=False).crack is None


def test_from_case_passes_the_tooth_model(case):
    pm = PEMModel.from_case(case, cracked=False, model="classic")
    assert pm.model == "classic"
    assert pm.sections[("pinion", False)].model == "classic"
    assert pm.parameters()["tooth_model"] == "classic"


def test_from_case_without_a_half_angle_setting_uses_the_fillet(case):
    """A case whose stiffness section predates the ``foundation_half_angle`` key (a stand-in
    object without it) gets the outline's half-angle, the documented default."""
    stiff = types.SimpleNamespace(body_torsion=False)
    old = types.SimpleNamespace(crack=None, material=case.material, pair=case.pair,
                                stiffness=stiff, gear_pair=case.gear_pair)
    pm = PEMModel.from_case(old)
    g = case.gear_pair().pinion
    assert pm.foundation_half_angle == "fillet"
    assert pm.theta_f == {"pinion": g.root_half_angle, "gear": g.root_half_angle}


def test_validity_notes_use_the_models_half_angle(pair):
    """The outline's theta_f (0.131 rad) is outside the unsourced [0.01, 0.12] box and is noted;
    a model built with 0.05 rad must not report it."""
    assert pair.pinion.root_half_angle > 0.12
    fillet = PEMModel(pair, E, NU).validity_warnings(notes=True)
    assert [m.split(":")[0] for m in fillet] == ["pinion", "gear"]
    assert all("theta_f = 0.131 rad outside [0.01, 0.12]" in m for m in fillet)
    assert PEMModel(pair, E, NU, foundation_half_angle=0.05).validity_warnings(notes=True) == []


# ------------------------------------------------------------------ interference bounds
def test_check_range_accepts_contact_exactly_at_the_form_circle(pair):
    """At the closed-form bound the start of contact is at the form circle (to rounding): it is
    accepted; 1 nm closer, the gear tip meets the pinion below its form circle."""
    pm = PEMModel(pair, E, NU)
    d_p, d_g = _bound(pair, "pinion"), _bound(pair, "gear")
    assert d_p == pytest.approx(d_g, abs=1e-15)   # equal pair: both bounds coincide
    op = pair.operating(d_p)
    assert op.s_start / pair.pinion.base_radius == pytest.approx(
        pm.sections[("pinion", False)].u_min, abs=1e-14)
    pm.check_range([d_p, d_p + 1e-9, 0.0, 2e-3])         # no error
    with pytest.raises(GeometryError) as exc:
        pm.check_range([0.0, d_p - 1e-9])
    assert (exc.value.field, exc.value.value, exc.value.allowed) == (
        "centre_distance_change", d_p - 1e-9,
        "a centre distance at which the gear tip meets the pinion above its form circle "
        "(interference)")
    assert type(exc.value.value) is float


def test_check_range_gear_side_interference_on_an_unequal_pair():
    """20/30 teeth, gear shifted +0.3: the pinion tip reaches the gear's fillet first when the
    centre distance shrinks (closed-form bounds -1.455 mm pinion, -1.205 mm gear), which
    ``GearPair.checks`` confirms independently."""
    p = Gear(20, 6e-3, 20 * DEG)
    g = Gear(30, 6e-3, 20 * DEG, profile_shift=0.3, bore_radius=0.04)
    pair = GearPair(p, g)
    pm = PEMModel(pair, E, NU)
    d_p, d_g = _bound(pair, "pinion"), _bound(pair, "gear")
    assert d_p < d_g - 2e-4
    pm.check_range([d_g, d_g + 1e-9])                    # at the gear's bound: accepted
    d = 0.5 * (d_p + d_g)
    assert pair.checks(d) == ["interference: the pinion tip meets the gear below its form circle"]
    with pytest.raises(GeometryError) as exc:
        pm.check_range(np.array([d]))
    assert (exc.value.field, exc.value.value, exc.value.allowed) == (
        "centre_distance_change", d,
        "a centre distance at which the pinion tip meets the gear above its form circle "
        "(interference)")
    assert type(exc.value.value) is float


# ------------------------------------------------------------------ provenance
def test_parameters_record_in_full(pair):
    crack = ToothCrack(gear="pinion", tooth=7, depth=3e-3, angle=30 * DEG, limit_line="parallel")
    pm = PEMModel(pair, E, NU, crack, face_width=0.025, foundation_half_angle="ross")
    rho = pair.pinion.tool_tip_radius / 6e-3       # ROSS closed form with the tool tip radius
    ross = (math.pi / 2 + 2 * math.tan(20 * DEG) * (1 - rho) + 2 * rho / math.cos(20 * DEG)) / 23
    par = pm.parameters()
    cg = pm.sections[("pinion", True)].crack_geometry
    # mouth: 30 deg tangent point; tip: depth sin/cos(angle) inwards and down (the convention)
    assert cg.tip[0] == pytest.approx(cg.mouth[0] - 3e-3 * 0.5, abs=1e-15)
    assert cg.tip[1] == pytest.approx(cg.mouth[1] - 3e-3 * math.sqrt(3) / 2, abs=1e-15)
    expected = {
        "youngs_modulus_Pa": 69e9,
        "poisson_ratio": 0.33,
        "face_width_m": 0.025,
        "tooth_model": "exact",
        "foundation_half_angle": "ross",
        "pinion_theta_f_rad": pytest.approx(ross, rel=1e-12),
        "gear_theta_f_rad": pytest.approx(ross, rel=1e-12),
        "pinion_bore_radius_m": 0.02,
        "gear_bore_radius_m": 0.02,
        "hertz_compliance_m_per_N": pytest.approx(4 * (1 - 0.33 ** 2) / (math.pi * 69e9 * 0.025),
                                                  rel=1e-14),
        "crack": {
            "gear": "pinion", "tooth": 7, "depth_m": 3e-3, "angle_rad": 30 * DEG,
            "angle_convention": "angle between the crack and the tooth centreline; tip "
                                "depth*sin(angle) nearer the centreline and depth*cos(angle) "
                                "nearer the root than the mouth",
            "mouth": "fillet point with a 30 deg tangent (ISO 6336-3), loaded side",
            "limit_line": "parallel",
            "mouth_xy_m": list(cg.mouth), "tip_xy_m": list(cg.tip),
        },
    }
    assert par == expected
    assert type(par["crack"]["tooth"]) is int
    assert "crack" not in PEMModel(pair, E, NU).parameters()


# ------------------------------------------------------------------ the mesh at its edges
def test_contact_ratio_three_or_more_is_refused_in_full():
    """80 teeth, 14.5 deg, addendum 1.6 m: contact ratio 3.41 (three slots cannot hold four
    pairs), computed here from the tip and base radii."""
    g = Gear(80, 2e-3, 14.5 * DEG, addendum_coefficient=1.6, dedendum_coefficient=2.0,
             bore_radius=0.03)
    pair = GearPair(g, g)
    rb, ra = g.base_radius, g.tip_radius
    a = pair.design_centre_distance
    eps = (2 * math.sqrt(ra ** 2 - rb ** 2) - a * math.sin(14.5 * DEG)) / pair.base_pitch
    assert 3 < eps < 4
    pm = PEMModel(pair, 2e11, 0.3)
    with pytest.raises(InputError) as exc:
        pm.evaluate([0.0], 0.0)
    assert (exc.value.field, exc.value.value, exc.value.allowed) == (
        "centre_distance_change", 0.0, "a centre distance with contact ratio < 3")


def test_handover_points_count_both_pairs(pair):
    """At the exact angle where a pair enters (s = s_start), and 1e-14 rad before the angle
    where it leaves (s = s_end - 6e-16 m; at s_end itself the slot scheme already counts it as
    gone), the pair counts: contact is the closed interval [s_start, s_end] up to 1e-12 m. Two
    pairs, k_mb the sum of the two pair stiffnesses; the pair indices are integers and the
    rolls out of contact are NaN."""
    pm = PEMModel(pair, E, NU)
    op = pair.operating(0.0)
    rb1, rb2, pb = pair.pinion.base_radius, pair.gear.base_radius, pair.base_pitch
    for s_edge, shift in ((op.s_start, 0.0), (op.s_end, -1e-14)):
        theta = (s_edge + 2 * pb - pair.pitch_point_s) / rb1 + shift
        r = pm.evaluate([theta])
        assert r["pairs_in_contact"][0] == 2
        assert r["pair"].dtype == np.int64
        inc = ~np.isnan(r["pinion_roll"][0])
        assert inc.sum() == 2 and r["gear_roll"].dtype == np.float64
        np.testing.assert_array_equal(np.isnan(r["gear_roll"][0]), ~inc)
        s = pair.pitch_point_s + rb1 * theta - r["pair"][0][inc] * pb
        assert np.min(np.abs(s - s_edge)) < 1e-15
        k = pm.pair_stiffness(s / rb1, (op.t1t2 - s) / rb2)
        assert r["k_mb"][0] == pytest.approx(k.sum(), rel=1e-14)


def test_compliance_table_with_three_smooth_intervals():
    """Classic 40-tooth section (involute from the base circle, above the crack mouth's
    height), crack tip on the involute: two kinks on the flank, three spline intervals. The
    table agrees with direct quadrature over the whole flank, at the kinks too."""
    g = Gear(40, 6e-3, 20 * DEG, bore_radius=0.04)
    pm = PEMModel(GearPair(g, g), 2e11, 0.3, ToothCrack(depth=0.5e-3), model="classic")
    sec = pm.sections[("pinion", True)]
    assert len(sec.roll_breaks) == 2
    u = np.concatenate([np.linspace(sec.u_min, sec.u_tip, 41), sec.roll_breaks])
    np.testing.assert_allclose(pm.tooth_compliance("pinion", u, True),
                               pm.tooth_compliance_exact("pinion", u, True), rtol=1e-8)


# ------------------------------------------------------------------ construction
@pytest.mark.parametrize("e, nu, field, allowed", [
    (0.0, 0.3, "material.youngs_modulus", "a modulus > 0 [Pa]"),
    (-1.0, 0.3, "material.youngs_modulus", "a modulus > 0 [Pa]"),
    (math.inf, 0.3, "material.youngs_modulus", "a modulus > 0 [Pa]"),
    (math.nan, 0.3, "material.youngs_modulus", "a modulus > 0 [Pa]"),
    (E, 0.0, "material.poisson_ratio", "a value in (0, 0.5)"),
    (E, 0.5, "material.poisson_ratio", "a value in (0, 0.5)"),
    (E, 0.7, "material.poisson_ratio", "a value in (0, 0.5)"),
])
def test_material_refusals_in_full(pair, e, nu, field, allowed):
    with pytest.raises(InputError) as exc:
        PEMModel(pair, e, nu)
    assert exc.value.field == field and exc.value.allowed == allowed
    bad = e if field.endswith("modulus") else nu
    assert exc.value.value is bad or exc.value.value == bad


def test_material_accepts_values_inside_the_open_bounds(pair):
    """The bounds are E > 0 and 0 < nu < 0.5: a 0.5 Pa modulus is absurd but valid input."""
    assert PEMModel(pair, 0.5, 0.3).E == 0.5
    for nu in (1e-9, 0.4999):
        assert PEMModel(pair, E, nu).nu == nu


@pytest.fixture(scope="module")
def unequal():
    """20/30 teeth, so the pinion's and the gear's tooth ranges differ."""
    return GearPair(Gear(20, 6e-3, 20 * DEG), Gear(30, 6e-3, 20 * DEG, bore_radius=0.04))


def test_cracked_tooth_number_checked_against_its_own_gear(unequal):
    with pytest.raises(InputError) as exc:
        PEMModel(unequal, E, NU, ToothCrack(gear="pinion", tooth=20))
    assert (exc.value.field, exc.value.value, exc.value.allowed) == (
        "crack.tooth", 20, "a tooth number in [0, 19] of the pinion")
    with pytest.raises(InputError) as exc:
        PEMModel(unequal, E, NU, ToothCrack(gear="gear", tooth=30))
    assert (exc.value.field, exc.value.value, exc.value.allowed) == (
        "crack.tooth", 30, "a tooth number in [0, 29] of the gear")
    assert PEMModel(unequal, E, NU, ToothCrack(gear="gear", tooth=25)).crack.tooth == 25
    assert PEMModel(unequal, E, NU, ToothCrack(gear="pinion", tooth=19)).crack.tooth == 19


@pytest.mark.parametrize("which, teeth", [("pinion", 20), ("gear", 30)])
@pytest.mark.parametrize("model", ["exact", "classic"])
def test_every_section_is_built_on_its_gear_with_the_tooth_model(unequal, which, teeth, model):
    crack = ToothCrack(gear=which, tooth=3, depth=2e-3)
    pm = PEMModel(unequal, E, NU, crack, model=model)
    assert set(pm.sections) == {("pinion", False), ("gear", False), (which, True)}
    assert [(k, s.gear.teeth, s.model) for k, s in pm.sections.items()] == [
        (("pinion", False), 20, model), (("gear", False), 30, model), ((which, True), teeth, model)]
    assert pm.sections[(which, True)].crack is crack
    sec = ToothSection(unequal.pinion if which == "pinion" else unequal.gear, crack, model=model)
    roll = 0.5 * (sec.u_min + sec.u_tip)
    assert pm.tooth_compliance_exact(which, roll, True)[0] == pytest.approx(
        tooth_compliance_quad(sec, roll, E, NU, 0.02, theta_f=pm.theta_f[which], epsrel=1e-10),
        rel=1e-9)


def test_default_half_angle_and_body_torsion_with_a_face_width_override(pair):
    """Default foundation half-angle 'fillet' (recorded as given); the bodies' torsion in
    series uses the model's face width: r_b^2 (1/r_int^2 - 1/r_f^2) / (4 pi G b) per gear (the
    annulus integral of phi/T)."""
    assert PEMModel(pair, E, NU).parameters()["foundation_half_angle"] == "fillet"
    b = 0.03
    pm = PEMModel(pair, E, NU, face_width=b, body_torsion=True)
    G = E / (2 * (1 + NU))
    expected = sum(g.base_radius ** 2 * (1 / g.bore_radius ** 2 - 1 / g.root_radius ** 2)
                   / (4 * math.pi * G * b) for g in (pair.pinion, pair.gear))
    assert pm.body_compliance == pytest.approx(expected, rel=1e-13)
    assert PEMModel(pair, E, NU).body_compliance == 0.0
