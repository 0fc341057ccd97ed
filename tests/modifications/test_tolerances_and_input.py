"""ISO 1328-1:2013 tolerances, drawn and tabulated deviations, and bad input."""

from __future__ import annotations

import math

import numpy as np
import pytest

from geardyn.errors import InputError
from geardyn.modifications import ToothModifications, draw_pitch_deviations, iso1328_tolerances

from ._support import case_with


def test_class_5_values_by_hand():
    """Class 5, d = 138 mm, m = 6 mm, formulas (5)-(8) evaluated by hand (um):
    f_pT = 0.138 + 2.4 + 5 = 7.538; F_pT = 0.276 + 0.55 sqrt(138) + 4.2 + 12 = 22.937;
    f_HaT = 2.4 + 0.138 + 4 = 6.538; f_faT = 3.3 + 5 = 8.3."""
    t = iso1328_tolerances(5, 0.138, 0.006, rounded=False)
    assert t["single_pitch"] == pytest.approx(7.538e-6, rel=1e-12)
    assert t["cumulative_pitch"] == pytest.approx((0.276 + 0.55 * math.sqrt(138) + 16.2) * 1e-6,
                                                  rel=1e-12)
    assert t["profile_slope"] == pytest.approx(6.538e-6, rel=1e-12)
    assert t["profile_form"] == pytest.approx(8.3e-6, rel=1e-12)
    # rounding rules of 5.2.3: 5-10 um to 0.5, > 10 um to 1
    r = iso1328_tolerances(5, 0.138, 0.006)
    assert r["single_pitch"] == pytest.approx(7.5e-6) and r["cumulative_pitch"] == pytest.approx(23e-6)


def test_step_factor_between_classes_is_sqrt2():
    for a in range(1, 11):
        lo = iso1328_tolerances(a, 0.138, 0.006, rounded=False)
        hi = iso1328_tolerances(a + 1, 0.138, 0.006, rounded=False)
        for k in lo:
            assert hi[k] / lo[k] == pytest.approx(math.sqrt(2), rel=1e-12)


@pytest.mark.parametrize("grade", [0, 12, -3])
def test_grade_outside_range_names_the_field(grade):
    with pytest.raises(InputError) as exc:
        iso1328_tolerances(grade, 0.138, 0.006, field_name="modifications.pinion.grade")
    assert "modifications.pinion.grade" in str(exc.value) and "11" in str(exc.value)
    with pytest.raises(InputError) as exc:
        case_with(modifications__pinion__grade=grade)
    assert "modifications.pinion.grade" in str(exc.value)


def test_negative_relief_and_bad_tables_are_refused():
    with pytest.raises(InputError) as exc:
        case_with(modifications__gear__tip_relief="-5 um")
    assert "modifications.gear.tip_relief" in str(exc.value)
    with pytest.raises(InputError) as exc:
        ToothModifications.from_case(case_with(modifications__pinion__cumulative_pitch=[1e-6] * 5))
    assert "modifications.pinion.cumulative_pitch" in str(exc.value) and "23" in str(exc.value)
    with pytest.raises(InputError) as exc:
        ToothModifications.from_case(case_with(modifications__pinion__tip_relief="10 um",
                                               modifications__pinion__relief_start="60 deg"))
    assert "modifications.pinion.relief_start" in str(exc.value)


def test_no_section_and_zero_section_are_inactive():
    assert not ToothModifications.from_case(case_with()).active
    zero = case_with(modifications__pinion__tip_relief=0.0, modifications__gear__runout=0.0)
    assert zero.modifications is not None and not ToothModifications.from_case(zero).active


def test_draws_are_reproducible_and_within_tolerance():
    a = ToothModifications.from_case(case_with(modifications__pinion__grade=6))
    b = ToothModifications.from_case(case_with(modifications__pinion__grade=6))
    c = ToothModifications.from_case(case_with(modifications__pinion__grade=6,
                                               modifications__pinion__seed=1))
    assert np.array_equal(a.pinion.pitch, b.pinion.pitch)
    assert np.array_equal(a.pinion.slope, b.pinion.slope)
    assert not np.array_equal(a.pinion.pitch, c.pinion.pitch)
    tol = a.pinion.tolerances
    assert np.all(np.abs(a.pinion.slope) <= tol["profile_slope"])
    assert np.all((a.pinion.form >= 0) & (a.pinion.form <= tol["profile_form"]))
    assert np.max(np.abs(a.pinion.single_pitch())) <= tol["single_pitch"]
    assert not a.gear.has_table  # the gear section is empty


@pytest.mark.parametrize("seed", range(8))
def test_pitch_sequence_integrates_to_the_stated_cumulative_deviation(seed):
    """Oracle (issue 14, must show): the once-per-tooth single pitch deviations, summed, give
    back the cumulative pitch deviation, whose range is the stated F_p, and they close."""
    rng = np.random.default_rng(seed)
    p = draw_pitch_deviations(rng, 23, 11e-6, 32e-6)
    assert np.ptp(p) == pytest.approx(32e-6, rel=1e-12)
    fpt = p - np.roll(p, 1)
    assert abs(fpt.sum()) < 1e-18
    integrated = p[0] + np.concatenate([[0.0], np.cumsum(fpt[1:])])
    np.testing.assert_allclose(integrated, p, rtol=0, atol=1e-18)
    assert np.ptp(integrated) == pytest.approx(32e-6, rel=1e-12)
