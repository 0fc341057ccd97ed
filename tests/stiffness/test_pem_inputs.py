"""PEM term functions at their edges: refusals in full, range bounds at the bound, vector inputs.

Written against the mutants that survived the first mutation run of the PEM term modules
(docs/mutation.md): every refusal is compared field by field, each fitted-range bound is tried
exactly at the bound, and the per-roll results of vector calls are compared with scalar calls.
"""

from __future__ import annotations

import math
import os

import numpy as np
import pytest

from geardyn import Gear, paper_case
from geardyn.errors import InputError
from geardyn.stiffness.pem import (
    ToothSection,
    axial_compression_compliance,
    bending_compliance,
    body_torsion_compliance,
    sainsot_validity,
    shear_compliance,
)
from geardyn.stiffness.pem.foundation import root_half_angle

DEG = math.pi / 180
E, NU, B = 206e9, 0.3, 0.02


@pytest.fixture(scope="module")
def pinion() -> Gear:
    return paper_case().gear_pair().pinion


def _gear_and_bore(h_f: float) -> tuple[Gear, float]:
    """A gear and a bore radius with r_f / r_int == h_f exactly in floating point."""
    for z in range(20, 80):
        g = Gear(teeth=z, module=4e-3, pressure_angle=20 * DEG, bore_radius=0.01)
        rf = g.root_radius
        b0 = rf / h_f
        for k in range(-50, 50):
            b = b0 + k * np.spacing(b0)
            if rf / b == h_f:
                return g, float(b)
    raise AssertionError("no exact bore found")


def test_half_angle_refusals_in_full(pinion):
    with pytest.raises(InputError) as exc:
        root_half_angle(pinion, "Rectangle")
    assert (exc.value.field, exc.value.value, exc.value.allowed) == (
        "stiffness.foundation_half_angle", "Rectangle",
        "'fillet', 'ross', 'alpha3' or an angle in rad")
    for bad in (0.0, math.pi / 23, math.nan):
        with pytest.raises(InputError) as exc:
            root_half_angle(pinion, bad)
        assert exc.value.field == "stiffness.foundation_half_angle"
        assert exc.value.value is bad or exc.value.value == bad
        assert exc.value.allowed == f"an angle in (0, pi/z) = (0, {math.pi / 23:.4g}) rad"
    assert root_half_angle(pinion, " ROSS ") == root_half_angle(pinion, "ross")
    big = Gear(teeth=60, module=4e-3, pressure_angle=20 * DEG, bore_radius=0.03)
    with pytest.raises(InputError) as exc:
        root_half_angle(big, "alpha3")
    assert (exc.value.field, exc.value.value) == ("stiffness.foundation_half_angle", "alpha3")
    assert exc.value.allowed == ("'fillet', 'ross' or an angle: alpha3 (the root rectangle of Wan "
                                 "et al.) needs a root circle below the base circle (60 teeth "
                                 "have none)")


def test_fitted_range_bounds_are_inclusive(pinion):
    rf, tf = pinion.root_radius, pinion.root_half_angle
    for h in (1.4, 7.0):
        g, bore = _gear_and_bore(h)
        assert g.root_radius / bore == h
        assert not any(m.startswith("h_f") for m in sainsot_validity(g, 0.1, bore))
        assert any(m.startswith("h_f") for m in sainsot_validity(g, 0.1, bore * (1 - 1e-9)
                                                                  if h == 7.0 else bore * 1.001))
    lo = sainsot_validity(pinion, tf, rf / 1.39)
    assert lo[0] == ("h_f = r_f/r_int = 1.39 outside the fitted range [1.4, 7.0] of Sainsot "
                     "et al. (2004)")
    # the theta_f box [0.01, 0.12] (a note only) is inclusive at both ends
    bore = pinion.bore_radius
    for t in (0.12, 0.01, 0.04):
        assert not any(m.startswith("theta_f") for m in sainsot_validity(pinion, t, bore,
                                                                          notes=True))
    note = sainsot_validity(pinion, 0.1201, bore, notes=True)[-1]
    assert note == ("theta_f = 0.1201 rad outside [0.01, 0.12] rad, a bound of unknown source (a "
                    "commented-out line of the ROSS code); the fitted coefficients stay in their "
                    "range")
    assert not any(m.startswith("theta_f") for m in sainsot_validity(pinion, 0.1201, bore))


def test_coefficient_envelope_message(pinion):
    msgs = sainsot_validity(pinion, 0.01)
    assert msgs[0] == ("L* = 6.718 outside the range [6.82, 6.94] of the fitted coefficients of "
                       "Sainsot et al. (2004) (h_f = 3.075, theta_f = 0.01 rad)")


def test_body_torsion_face_width_override(pinion):
    c20 = body_torsion_compliance(pinion, E, NU)
    assert body_torsion_compliance(pinion, E, NU, 0.01) == pytest.approx(2 * c20, rel=1e-14)
    assert body_torsion_compliance(pinion, E, NU, 0.02) == pytest.approx(c20, rel=1e-14)


def test_vector_calls_equal_scalar_calls(pinion):
    sec = ToothSection(pinion)
    rolls = np.array([0.25, 0.36, 0.5])
    for fn, args in ((bending_compliance, (E, B)), (shear_compliance, (E, NU, B)),
                     (axial_compression_compliance, (E, B))):
        vec = fn(sec, rolls, *args)
        assert vec.shape == (3,)
        for i, r in enumerate(rolls):
            assert vec[i] == pytest.approx(fn(sec, float(r), *args)[0], rel=1e-13)
        assert vec[0] != pytest.approx(vec[2], rel=1e-3)


def test_foundation_warns_only_when_asked_and_for_the_angle_used(pinion):
    """No warning by default; with ``warn=True`` the check uses the theta_f actually passed and
    points at the caller's line."""
    import warnings

    from geardyn.stiffness.pem import SainsotRangeWarning, foundation_compliance

    with warnings.catch_warnings():
        warnings.simplefilter("error", SainsotRangeWarning)
        foundation_compliance(pinion, [0.4], E, B, theta_f=0.01)
        foundation_compliance(pinion, [0.4], E, B, warn=True)  # the default theta_f is fine
    with pytest.warns(SainsotRangeWarning) as rec:
        foundation_compliance(pinion, [0.4], E, B, theta_f=0.01, warn=True)
    assert str(rec[0].message).startswith("L* = 6.718 outside the range [6.82, 6.94]")
    # mutmut's trampoline adds a stack frame, so the caller's line is checked outside mutmut only
    if "MUTANT_UNDER_TEST" not in os.environ:
        assert rec[0].filename == __file__
