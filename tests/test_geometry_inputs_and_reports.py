"""Geometry input limits, error messages, reports and summaries, exactly.

Written against the mutants that survived the first mutation run of ``geardyn.geometry``
(docs/mutation.md): every validation bound is tried at the bound (accepted) and just beyond
(refused), every error is compared field by field with its full text, and the JSON summary and the
``checks()`` report are compared item by item with values computed here.
"""

from __future__ import annotations

import math

import numpy as np
import pytest

from geardyn import Gear, GearPair, InputError, paper_case
from geardyn.errors import GeometryError
from geardyn.geometry import (
    centre_distance_from_displacements,
    geometry_summary,
    inv,
    inv_inverse,
)

DEG = math.pi / 180
BASE = dict(teeth=23, module=0.006, pressure_angle=20 * DEG, face_width=0.02, bore_radius=0.02)
RHO_MAX = 0.25 / (1 - math.sin(20 * DEG))  # (h_f* - h_a*) / (1 - sin alpha) = 0.3799


def _error(kwargs) -> InputError:
    with pytest.raises(InputError) as exc:
        Gear(**{**BASE, **kwargs})
    return exc.value


@pytest.mark.parametrize("kwargs", [
    {"teeth": 5, "bore_radius": 0.002}, {"pressure_angle": 35 * DEG}, {"pressure_angle": 1e-9},
    {"addendum_coefficient": 2.0, "dedendum_coefficient": 2.0},
    {"addendum_coefficient": 1e-9}, {"dedendum_coefficient": 1.0}, {"dedendum_coefficient": 3.0},
    {"profile_shift": -1.5, "teeth": 60}, {"profile_shift": 1.5, "teeth": 40},
    {"tool_tip_radius_coefficient": 0.0}, {"tool_tip_radius_coefficient": RHO_MAX},
    {"bore_radius": 61.5e-3 - 1e-9},
])
def test_limits_are_accepted_at_the_bound(kwargs):
    g = Gear(**{**BASE, **kwargs})
    for k, v in kwargs.items():
        assert getattr(g, k) == v


@pytest.mark.parametrize(("kwargs", "field", "allowed"), [
    ({"teeth": 4}, "teeth", "a whole number of teeth >= 5"),
    ({"teeth": True}, "teeth", "a whole number of teeth >= 5"),
    ({"module": 0.0}, "module", "a finite length > 0 [m]"),
    ({"face_width": math.inf}, "face_width", "a finite length > 0 [m]"),
    ({"bore_radius": -1.0}, "bore_radius", "a finite length > 0 [m]"),
    ({"pressure_angle": 0.0}, "pressure_angle",
     "a pressure angle in (0, 35 deg], given in rad (0.3491 = 20 deg)"),
    ({"pressure_angle": 35.001 * DEG}, "pressure_angle",
     "a pressure angle in (0, 35 deg], given in rad (0.3491 = 20 deg)"),
    ({"addendum_coefficient": 0.0}, "addendum_coefficient", "a value in (0, 2]"),
    ({"addendum_coefficient": 2.001, "dedendum_coefficient": 2.5}, "addendum_coefficient",
     "a value in (0, 2]"),
    ({"dedendum_coefficient": 0.999}, "dedendum_coefficient",
     "a value in [addendum_coefficient = 1.0, 3]"),
    ({"dedendum_coefficient": 3.001}, "dedendum_coefficient",
     "a value in [addendum_coefficient = 1.0, 3]"),
    ({"profile_shift": -1.501}, "profile_shift", "a value in [-1.5, 1.5]"),
    ({"profile_shift": 1.501}, "profile_shift", "a value in [-1.5, 1.5]"),
    ({"tool_tip_radius_coefficient": -0.001}, "tool_tip_radius_coefficient",
     "a value in [0, 0.3800] (larger radii cut into the active flank)"),
    ({"tool_tip_radius_coefficient": RHO_MAX + 1e-6}, "tool_tip_radius_coefficient",
     "a value in [0, 0.3800] (larger radii cut into the active flank)"),
    ({"bore_radius": 61.6e-3}, "bore_radius", "a radius below the root radius 0.0615 m"),
])
def test_refusals_name_the_field_the_value_and_what_is_allowed(kwargs, field, allowed):
    err = _error(kwargs)
    assert err.field == field
    assert err.value is list(kwargs.values())[0] or err.value == list(kwargs.values())[0]
    assert err.allowed == allowed


def test_pair_refuses_mismatched_module_and_angle():
    p = Gear(**BASE)
    with pytest.raises(InputError) as exc:
        GearPair(p, Gear(**{**BASE, "module": 0.006 * (1 + 1e-9)}))
    e = exc.value
    assert (e.field, e.value, e.allowed) == ("gear.module", 0.006 * (1 + 1e-9),
                                             "the pinion's module 0.006 m")
    GearPair(p, Gear(**{**BASE, "module": 0.006 * (1 + 1e-13)}))  # within rel_tol 1e-12
    with pytest.raises(InputError) as exc:
        GearPair(p, Gear(**{**BASE, "pressure_angle": 20.001 * DEG}))
    e = exc.value
    assert (e.field, e.value) == ("gear.pressure_angle", 20.001 * DEG)
    assert e.allowed == f"the pinion's pressure angle {20 * DEG} rad"
    assert repr(GearPair(p, Gear(**{**BASE, "teeth": 40}))) == \
        "GearPair(z=23/40, m=6 mm, alpha=20 deg)"


def test_operating_refusals_in_words():
    pair = paper_case().gear_pair()
    rsum = pair.base_radius_sum
    with pytest.raises(GeometryError) as exc:
        pair.operating(rsum - pair.design_centre_distance)  # d' = r_b1 + r_b2 exactly
    e = exc.value
    assert e.field == "centre_distance_change"
    assert e.value == rsum - pair.design_centre_distance
    assert e.allowed == (f"a change > {rsum - pair.design_centre_distance:.6g} m (the operating "
                         "centre distance must exceed r_b1 + r_b2)")
    limit = pair.max_centre_distance_change()
    with pytest.raises(GeometryError) as exc:
        pair.operating(limit + 1e-5)
    op = pair.operating(limit + 1e-5, check=False)
    assert exc.value.allowed == (
        f"a centre distance change that keeps the contact ratio >= 1 (it is "
        f"{op.contact_ratio:.4f} at {op.centre_distance * 1e3:.4f} mm; the largest allowed "
        f"change is {limit * 1e3:.4f} mm)")
    assert op.base_pitch == pair.base_pitch
    with pytest.raises(GeometryError):
        pair.operating(math.nan)
    # texts made only on an error (a function handed to the check): still made, and in full
    with pytest.raises(InputError) as exc:
        pair.operating("1 mm")
    assert (exc.value.field, exc.value.value, exc.value.allowed) == (
        "centre_distance_change", "1 mm",
        f"a number > {rsum - pair.design_centre_distance:.6g} [m] (SI: 0.001 for 1 mm)")
    with pytest.raises(InputError) as exc:
        pair.contact_points(math.inf)
    assert (exc.value.field, exc.value.allowed) == (
        "theta", "a finite pinion angle of magnitude <= 1e+12 [rad]")


def test_involute_inverse_refuses_negative_values_and_converges_from_any_start():
    with pytest.raises(InputError) as exc:
        inv_inverse(-1e-3)
    assert (exc.value.field, exc.value.value, exc.value.allowed) == (
        "involute", -1e-3, "a non-negative value")
    for a in (1e-4, 0.3, 1.0, 1.4):
        assert inv_inverse(float(inv(a))) == pytest.approx(a, rel=1e-14)


def test_contact_ratio_formula_choice():
    op = paper_case().gear_pair().operating(1e-3)
    assert op.contact_ratio_by("physical") == op.contact_ratio
    with pytest.raises(InputError) as exc:
        op.contact_ratio_by("eq8")
    assert (exc.value.field, exc.value.value, exc.value.allowed) == (
        "contact_ratio_formula", "eq8", "'physical' or 'paper_eq8'")


def test_contact_point_candidates_within_the_margin():
    """Candidates: every pair within ``margin`` base pitches of [s0, s1] (default one), and no
    other; ``contact_points`` works beyond the contact-ratio limit (no check)."""
    pair = paper_case().gear_pair()
    pb = pair.base_pitch
    for theta in (0.0, 0.1, 0.23):
        for margin in (1.0, 2.0, 0.0):
            op = pair.operating(0.0)
            s_theta = pair.pitch_point_s + pair.pinion.base_radius * theta
            n_all = np.arange(-20, 21)
            s_all = s_theta - n_all * pb
            want = n_all[(s_all >= op.s_start - margin * pb - 1e-12)
                         & (s_all <= op.s_end + margin * pb + 1e-12)]
            cp = pair.contact_points(theta, margin=margin) if margin != 1.0 else \
                pair.contact_points(theta)
            assert sorted(cp.pair) == sorted(want)
            assert np.all(np.diff(cp.s) > 0)
            np.testing.assert_allclose(cp.gear_radius, np.hypot(pair.gear.base_radius,
                                                                op.t1t2 - cp.s), rtol=1e-14)
    beyond = pair.max_centre_distance_change() + 1e-4
    assert pair.contact_points(0.0, beyond).in_contact.sum() in (0, 1)


def test_thickness_and_outline():
    g = Gear(**BASE)
    assert g.thickness_at(g.pitch_radius) == pytest.approx(math.pi * 0.006 / 2, rel=1e-14)
    assert g.thickness_at(g.base_radius) == pytest.approx(2 * g.base_radius * g.base_half_angle,
                                                          rel=1e-14)
    with pytest.raises(InputError) as exc:
        g.thickness_at(g.base_radius * 0.999)
    assert exc.value.field == "radius"
    assert exc.value.allowed == f"a radius >= the base radius {g.base_radius:.6g} m"
    o = g.outline(n_involute=30, n_fillet=20)
    assert o.involute.shape == (30, 2) and o.fillet.shape == (20, 2)
    rf = o.right_flank()
    assert rf.shape == (49, 2)
    np.testing.assert_array_equal(rf[0], o.fillet[-1])
    np.testing.assert_array_equal(rf[-1], o.involute[-1])
    tooth = o.closed_tooth()
    assert tooth.shape == (2 * 49 + 7, 2)
    tip = tooth[49:56]
    np.testing.assert_allclose(np.hypot(*tip.T), g.tip_radius, rtol=1e-14)
    assert np.all(np.abs(tip[:, 0]) < rf[-1, 0])
    np.testing.assert_allclose(tooth[:49], rf[::-1] * [-1, 1])
    # the tooth thickness at the tip circle is the arc between the two flank tips
    half = math.asin(rf[-1, 0] / g.tip_radius)
    assert 2 * g.tip_radius * half == pytest.approx(g.tip_thickness, rel=1e-12)
    # a pointed tooth's involute stops on the centreline
    pointed = Gear(teeth=10, module=0.006, pressure_angle=20 * DEG, profile_shift=1.2,
                   bore_radius=0.01)
    assert pointed.outline().involute[-1, 0] == pytest.approx(0.0, abs=1e-12)


def test_rack_tip_centre_with_profile_shift():
    """Ma et al. (2014) b_1 = pi m/4 + h_a* m tan(alpha) + rho cos(alpha) for x = 0; a shift x
    moves the rack centre depth to (h_f* - x) m - rho and the abscissa by x m tan(alpha)."""
    m, a = 0.006, 20 * DEG
    rho = RHO_MAX * m
    g0 = Gear(**BASE)
    xi0, a10 = g0._rack_tip_centre()
    assert a10 == pytest.approx(1.25 * m - rho, rel=1e-14)
    b1 = math.pi * m / 4 + m * math.tan(a) + rho * math.cos(a)
    assert xi0 == pytest.approx(b1, rel=1e-12)
    g1 = Gear(**{**BASE, "profile_shift": 0.3})
    xi1, a11 = g1._rack_tip_centre()
    assert a11 == pytest.approx((1.25 - 0.3) * m - rho, rel=1e-14)
    # the fillet ends on the (shifted) root circle, at the centre of the tooth space or before it
    end = g1.outline(n_fillet=7).fillet[-1]
    assert np.hypot(*end) == pytest.approx(g1.root_radius, rel=1e-13)
    assert g1.root_half_angle == pytest.approx(math.atan2(*end), rel=1e-14)
    assert g1.root_half_angle < math.pi / 23


def test_checks_report_in_words():
    mk = dict(module=0.006, pressure_angle=20 * DEG, face_width=0.02, bore_radius=0.01)
    under = Gear(teeth=12, **mk)
    thin = Gear(teeth=14, profile_shift=0.75, **mk)
    assert not thin.pointed and thin.tip_thickness < 0.2 * 0.006
    pair = GearPair(under, Gear(teeth=40, **{**mk, "bore_radius": 0.02}))
    msgs = pair.checks()
    assert msgs[0] == ("pinion: undercut by the generating rack (z = 12, x = 0.0); the involute "
                       "starts below the base circle")
    op = pair.operating(0.0)
    u1 = math.sqrt(under.form_radius ** 2 - under.base_radius ** 2)
    assert (f"interference: the gear tip meets the pinion below its form circle (start of "
            f"contact at roll length {op.s_start * 1e3:.4f} mm < {u1 * 1e3:.4f} mm)") in msgs
    t = GearPair(thin, Gear(teeth=40, **mk)).checks()
    assert f"pinion: thin tip land {thin.tip_thickness * 1e3:.3f} mm (< 0.2 m)" in t
    pointed = Gear(teeth=10, profile_shift=1.2, **mk)
    assert "gear: pointed teeth (flanks meet below the tip circle)" in \
        GearPair(Gear(teeth=40, **mk), pointed).checks()
    paper = paper_case().gear_pair()
    beyond = paper.max_centre_distance_change() + 1e-4
    eps = paper.operating(beyond, check=False).contact_ratio
    assert paper.checks(beyond) == [f"contact ratio {eps:.4f} < 1: the teeth lose contact"]
    assert paper.checks() == []
    # a gear with a large pinion: the pinion tip meets the gear below its form circle
    big = GearPair(Gear(teeth=40, **mk), Gear(teeth=12, **mk))
    assert "interference: the pinion tip meets the gear below its form circle" in big.checks()


def test_summary_reports_every_value_in_its_unit():
    pair = paper_case().gear_pair()
    dd = 0.7e-3
    s = geometry_summary(pair, dd)
    op = pair.operating(dd)
    for name, g in (("pinion", pair.pinion), ("gear", pair.gear)):
        want = {"teeth": g.teeth, "module_m": g.module,
                "pressure_angle_deg": math.degrees(g.pressure_angle),
                "profile_shift": g.profile_shift, "pitch_radius_m": g.pitch_radius,
                "base_radius_m": g.base_radius, "tip_radius_m": g.tip_radius,
                "root_radius_m": g.root_radius, "form_radius_m": g.form_radius,
                "tool_tip_radius_m": g.tool_tip_radius, "tip_thickness_m": g.tip_thickness,
                "root_half_angle_rad": g.root_half_angle, "face_width_m": g.face_width,
                "bore_radius_m": g.bore_radius}
        assert s[name] == want
        assert type(s[name]["teeth"]) is int
    assert s["base_pitch_m"] == pair.base_pitch
    assert s["design_centre_distance_m"] == pair.design_centre_distance
    assert s["design_pressure_angle_deg"] == math.degrees(pair.working_pressure_angle)
    assert s["operating"] == {
        "centre_distance_m": op.centre_distance,
        "centre_distance_change_m": dd,
        "pressure_angle_deg": math.degrees(op.pressure_angle),
        "contact_ratio": {"physical": op.contact_ratio, "paper_eq8": op.contact_ratio_eq8},
        "single_contact_fraction": op.single_contact_fraction,
        "double_contact_fraction": op.double_contact_fraction,
        "contact_start_m": op.s_start, "contact_end_m": op.s_end, "t1t2_m": op.t1t2,
        "normal_backlash_m": op.normal_backlash,
        "circumferential_backlash_m": op.circumferential_backlash,
        "backlash_closing_rotation_rad": op.closing_rotation,
    }
    assert s["max_centre_distance_change_m"] == pair.max_centre_distance_change()
    assert s["checks"] == []
    assert set(s) == {"pinion", "gear", "base_pitch_m", "design_centre_distance_m",
                      "design_pressure_angle_deg", "operating", "max_centre_distance_change_m",
                      "checks"}


def test_displacements_arrays_and_scalars_agree():
    pair = paper_case().gear_pair()
    yp, yg = np.array([-1e-3, 0.0, 2e-4]), np.array([1e-3, 5e-4, 0.0])
    arr = centre_distance_from_displacements(pair, yp, yg)
    assert isinstance(arr, np.ndarray)
    for i in range(3):
        assert arr[i] == pytest.approx(
            centre_distance_from_displacements(pair, float(yp[i]), float(yg[i])), rel=1e-15)
        assert arr[i] == pytest.approx(math.hypot(pair.base_radius_sum, pair.design_t1t2
                                                  + yg[i] - yp[i]), rel=1e-15)
    mixed = centre_distance_from_displacements(pair, 0.0, yg)
    np.testing.assert_allclose(mixed, np.hypot(pair.base_radius_sum, pair.design_t1t2 + yg))


def test_edges_left_by_the_second_mutation_run():
    """Tolerances and defaults: the rack-radius slack is 1e-12 m per m of module; a bore equal to
    the root radius is refused; the module and pressure angle must agree to 1e-12; defaults
    (outline 60/60 points, centre distance change 0) are as documented."""
    g = Gear(**BASE)
    with pytest.raises(InputError):
        Gear(**{**BASE, "tool_tip_radius_coefficient": RHO_MAX + 1e-8})
    with pytest.raises(InputError) as exc:
        Gear(**{**BASE, "bore_radius": g.root_radius})
    assert exc.value.field == "bore_radius"
    with pytest.raises(InputError) as exc:
        g.thickness_at(0.06)
    assert (exc.value.field, exc.value.value) == ("radius", 0.06)
    for field, kw in (("gear.module", {"module": 0.006 * (1 + 1e-10)}),
                      ("gear.pressure_angle", {"pressure_angle": 20 * DEG * (1 + 1e-10)})):
        with pytest.raises(InputError) as exc:
            GearPair(g, Gear(**{**BASE, **kw}))
        assert exc.value.field == field
    o = g.outline()
    assert o.involute.shape == (60, 2) and o.fillet.shape == (60, 2)
    pair = paper_case().gear_pair()
    assert pair.operating().centre_distance == pair.design_centre_distance
    assert geometry_summary(pair) == geometry_summary(pair, 0.0)
    limit = pair.max_centre_distance_change()
    with pytest.raises(GeometryError) as exc:
        pair.operating(limit + 1e-5)
    assert (exc.value.field, exc.value.value) == ("centre_distance_change", limit + 1e-5)


def test_shifted_fillet_joins_the_involute_and_is_sampled_evenly():
    """With a profile shift the rack tip centre moves by x m tan(alpha): the fillet still meets
    the involute at the form point with a common tangent; the fillet points are spread along the
    whole trochoid (no jump before the root point)."""
    for x in (-0.3, 0.4):
        g = Gear(**{**BASE, "profile_shift": x})
        o = g.outline(n_involute=800, n_fillet=800)
        assert np.linalg.norm(o.involute[0] - o.fillet[0]) < 1e-12
        ti = o.involute[1] - o.involute[0]
        tf = o.fillet[0] - o.fillet[1]
        assert ti @ tf / np.linalg.norm(ti) / np.linalg.norm(tf) > math.cos(math.radians(0.1))
        gaps = np.linalg.norm(np.diff(g.outline(n_fillet=60).fillet, axis=0), axis=1)
        assert gaps[-1] < 1.1 * gaps[-2]  # smooth up to the root point


def test_closed_tooth_tip_arc_exactly():
    g = Gear(**BASE)
    o = g.outline(n_involute=30, n_fillet=20)
    rf = o.right_flank()
    half = math.asin(rf[-1, 0] / g.tip_radius)
    ang = np.linspace(-half, half, 9)[1:-1]
    tip = o.closed_tooth()[49:56]
    np.testing.assert_allclose(tip, np.column_stack([g.tip_radius * np.sin(ang),
                                                     g.tip_radius * np.cos(ang)]), rtol=1e-14)


def test_contact_starts_and_ends_exactly_at_the_tips():
    pair = paper_case().gear_pair()
    op = pair.operating(0.0)
    rb1 = pair.pinion.base_radius
    for s in (op.s_start, op.s_end):
        cp = pair.contact_points((s - pair.pitch_point_s) / rb1)
        j = int(np.flatnonzero(cp.pair == 0)[0])
        assert abs(cp.s[j] - s) < 1e-15
        assert cp.in_contact[j]


def test_interference_reports_the_form_roll_lengths():
    """Gear tip below the pinion's form circle (and the mirror case) with a non-undercut 20-tooth
    member, whose form roll length r sin(alpha) - h_g / sin(alpha) = 1.9856 mm is not zero."""
    mk = dict(module=0.004, pressure_angle=20 * DEG, bore_radius=0.01)
    small = Gear(teeth=20, **mk)
    big = Gear(teeth=200, addendum_coefficient=1.2, dedendum_coefficient=1.25,
               **{**mk, "bore_radius": 0.1})
    u = 10 * 0.004 * math.sin(20 * DEG) - (1.25 * 0.004 - RHO_MAX * 0.004 * (1 - math.sin(20 * DEG))
                                          ) / math.sin(20 * DEG)
    assert small.form_roll_length == pytest.approx(u, rel=1e-12)
    pair = GearPair(small, big)
    op = pair.operating(0.0)
    assert pair.checks() == [
        "interference: the gear tip meets the pinion below its form circle (start of contact at "
        f"roll length {op.s_start * 1e3:.4f} mm < {u * 1e3:.4f} mm)"]
    assert GearPair(big, small).checks() == [
        "interference: the pinion tip meets the gear below its form circle"]


def test_real_numbers_only_and_the_error_text_made_on_an_error():
    """``geometry._real``: Python and NumPy reals (0-d arrays included) as floats; a bool, a
    string, None, an array of several values or a complex refused, naming the field and the
    value; non-finite values refused unless ``finite=False``; the allowed text given as such or
    made by a function, which is called only on an error."""
    from geardyn.geometry import _real

    calls = []

    def text():
        calls.append(1)
        return "a number, made"

    for value in (2, 2.5, np.float32(2.5), np.int64(3), np.array(4.0), np.array(5, np.uint8)):
        out = _real(value, "f", text)
        assert type(out) is float and out == float(value)
    assert calls == []
    for bad in (True, "1 mm", None, np.array([1.0, 2.0]), np.array([3.0]), 1 + 2j,
                np.complex128(1.0), np.array("x")):
        with pytest.raises(InputError) as exc:
            _real(bad, "f", "a number")
        assert (exc.value.field, exc.value.allowed) == ("f", "a number")
        assert exc.value.value is bad
    with pytest.raises(InputError) as exc:
        _real(math.nan, "f", text)
    assert (exc.value.field, exc.value.allowed, calls) == ("f", "a number, made", [1])
    assert math.isnan(exc.value.value)
    with pytest.raises(InputError) as exc:
        _real(np.float64(-math.inf), "f", "finite")
    assert (exc.value.field, exc.value.value, exc.value.allowed) == ("f", -math.inf, "finite")
    assert math.isinf(_real(math.inf, "f", "any", finite=False))
    assert math.isnan(_real(np.float64(math.nan), "f", "any", finite=False))
