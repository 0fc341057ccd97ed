"""The adaptive-quadrature reference ``tooth_compliance_quad`` (stiffness/pem/tooth.py): its
default tolerances, the classic root rectangle at small roll angles and the half-angle override.

Written against the mutants that survived the first mutation run of ``stiffness/pem/tooth.py``
(docs/mutation.md, issue 20 item 6). Oracle: the same integrals by an 80-point Gauss-Legendre
rule per piece (a second method; for the classic model the integrands are polynomial-like and
both agree to rounding).
"""

from __future__ import annotations

import math

import pytest

from geardyn import paper_case
from geardyn.stiffness.pem import ToothCrack, ToothSection, tooth_compliance, tooth_compliance_quad

E, NU, L = 69e9, 0.33, 0.02


@pytest.fixture(scope="module")
def pinion():
    return paper_case().gear_pair().pinion


@pytest.mark.parametrize("crack", [None, ToothCrack(tooth=1, depth=5e-3, limit_line="parallel")])
def test_quad_reference_meets_its_default_tolerance(pinion, crack):
    """With its defaults (epsabs 1e-14 1/m, epsrel 1e-12) the reference agrees with an
    80-point Gauss rule to 1e-11; looser tolerances stop QUADPACK after its first 21-point
    rule, about 2e-11 off on the trochoid fillet."""
    sec = ToothSection(pinion, crack)
    fine = ToothSection(pinion, crack, n_gauss=80)
    for roll in (0.3, 0.55):
        ref = tooth_compliance(fine, roll, E, NU, L)[0]
        assert abs(tooth_compliance_quad(sec, roll, E, NU, L) / ref - 1) < 1e-11


def test_quad_reference_of_the_classic_tooth_below_the_rectangle_heights(pinion):
    """Classic model (root rectangle up to the base circle, involute from roll 0): at a roll
    angle numerically smaller than the rectangle's heights (0.03 rad < 0.06 m) the rectangle
    still counts in full."""
    sec = ToothSection(pinion, model="classic")
    rect = sec.pieces[0]
    assert rect.kind == "rect" and 0.03 < rect.t0
    for roll in (0.0, 0.03, 0.3):
        g = tooth_compliance(sec, roll, E, NU, L)[0]
        assert tooth_compliance_quad(sec, roll, E, NU, L) == pytest.approx(g, rel=1e-12)


def test_quad_reference_uses_the_given_half_angle(pinion):
    sec = ToothSection(pinion)
    own = tooth_compliance_quad(sec, 0.4, E, NU, L)
    other = tooth_compliance_quad(sec, 0.4, E, NU, L, theta_f=0.05)
    assert other == pytest.approx(tooth_compliance(sec, 0.4, E, NU, L, theta_f=0.05)[0],
                                  rel=1e-10)
    assert abs(other / own - 1) > 1e-3
    assert own == pytest.approx(tooth_compliance(sec, 0.4, E, NU, L)[0], rel=1e-10)


def test_gauss_and_quad_agree_on_a_flank_split_in_three():
    """Classic 40-tooth section with the crack tip on the involute: the flank is split at the
    tip and where the limit line meets it; load points on every part (each quadrature piece
    stops at its own end, whatever the roll)."""
    from geardyn.geometry import Gear

    g = Gear(40, 6e-3, 20 * math.pi / 180, bore_radius=0.04)
    sec = ToothSection(g, ToothCrack(depth=0.5e-3), model="classic")
    assert [p.kind for p in sec.pieces].count("involute") == 3
    for roll in (0.05, 0.12, 0.3, 0.49):
        gauss = tooth_compliance(sec, roll, E, NU, L)[0]
        assert tooth_compliance_quad(sec, roll, E, NU, L) == pytest.approx(gauss, rel=1e-12)


def test_load_points_off_the_modelled_flank_are_refused(pinion):
    from geardyn.errors import GeometryError

    sec = ToothSection(pinion)
    for roll in ([sec.u_min - 1e-6], [0.3, sec.u_tip + 1e-6]):
        with pytest.raises(GeometryError) as exc:
            tooth_compliance(sec, roll, E, NU, L)
        assert exc.value.field == "roll"
