"""Wear by Archard's law along the profile (``law = "archard"``, :mod:`geardyn.faults.wear`).

Oracles:

* the sliding factor ``|1 - v_mate / v_self|`` against the surface speeds of two explicit
  involutes: the arc lengths of both flanks (numerical quadrature of the involute curves, not
  the closed form ``r_b u^2 / 2``) over a small advance of the contact point along the line of
  action; and zero at the pitch point;
* the passage integral: Archard's ``dh = k p ds`` integrated in time while a Hertz band (any
  half-width) passes the flank point at the point's rolling speed, against ``k (W / b) |1 -
  v_mate / v_self|``;
* the idealised load share against a count of the pairs on the line of action;
* the static TE of the worn pair in single contact rises by the profile's depth at the contact
  point (through the deviation tables, an independent sampling path), and zero depth is no wear.
"""

from __future__ import annotations

import math
import warnings
from pathlib import Path

import numpy as np
import pytest
from scipy.integrate import quad

from geardyn.config import load_case
from geardyn.errors import InputError
from geardyn.faults import archard_scale, faults_from_case
from geardyn.faults.wear import rigid_load_share, sliding_factor
from geardyn.modifications import ToothModifications
from geardyn.static_te import static_transmission_error
from geardyn.stiffness import build_map
from geardyn.stiffness.fe.faults import fault_gap

WEAR = Path(__file__).resolve().parents[2] / "examples" / "faults" / "wear.toml"
DELTA = 5e-6


def _case(depth=DELTA, **over):
    return load_case(WEAR, {"faults.0.stiffness": False, "faults.0.depth": depth,
                            "faults.0.law": "archard", "stiffness.centre_distances": 3, **over})


def _arc(rb: float, u: float) -> float:
    """Arc length of the involute x = rb (cos t + t sin t), y = rb (sin t - t cos t) from the
    base circle to roll angle ``u`` [m], by quadrature of |dr/dt|."""
    def speed(t):
        dx = rb * t * math.cos(t)
        dy = rb * t * math.sin(t)
        return math.hypot(dx, dy)
    return quad(speed, 0.0, u, epsabs=0, epsrel=1e-13)[0]


@pytest.mark.parametrize("which", ["pinion", "gear"])
def test_sliding_factor_against_the_arc_lengths_of_explicit_involutes(which):
    pair = _case().gear_pair()
    op = pair.operating(0.0)
    rb1, rb2 = pair.pinion.base_radius, pair.gear.base_radius
    ds = 1e-6  # advance of the contact point along the line of action, either side [m]
    for s in np.linspace(op.s_start + 1e-4, op.s_end - 1e-4, 9):
        # contact at roll length s from T1: pinion roll s / rb1, gear roll (T1T2 - s) / rb2;
        # central differences of the arc lengths (error (ds / rho)^2, about 1e-8)
        arc_p = _arc(rb1, (s + ds) / rb1) - _arc(rb1, (s - ds) / rb1)
        arc_g = _arc(rb2, (op.t1t2 - s + ds) / rb2) - _arc(rb2, (op.t1t2 - s - ds) / rb2)
        self_arc, mate_arc = (arc_p, arc_g) if which == "pinion" else (arc_g, arc_p)
        expect = abs(1.0 - mate_arc / self_arc)
        roll = s / rb1 if which == "pinion" else (op.t1t2 - s) / rb2
        assert sliding_factor(pair, which, roll) == pytest.approx(expect, rel=2e-6, abs=1e-9)
    # no sliding at the pitch point
    s_p = pair.pitch_point_s
    roll_p = s_p / rb1 if which == "pinion" else (op.t1t2 - s_p) / rb2
    assert sliding_factor(pair, which, roll_p) == pytest.approx(0.0, abs=1e-12)


def test_archard_passage_integral_is_load_per_width_times_sliding():
    """Integrate dh = k p |v_self - v_mate| dt while a Hertz band of half-width a passes at
    speed v_self; the result does not depend on a."""
    k, w_per_b = 1e-16, 2.5e5  # wear coefficient [m^2/N], load per width [N/m]
    v_self, v_mate = 1.7, 1.1  # surface speeds [m/s]
    for a in (0.05e-3, 0.2e-3):
        p0 = 2.0 * w_per_b / (math.pi * a)  # Hertz peak pressure of a line contact [Pa]

        def rate(t, a=a, p0=p0):
            x = v_self * t - a  # band centre relative to the point, entering at -a
            return k * p0 * math.sqrt(max(0.0, 1.0 - (x / a) ** 2)) * abs(v_self - v_mate)

        h = quad(rate, 0.0, 2 * a / v_self, epsabs=0, epsrel=1e-12)[0]
        assert h == pytest.approx(k * w_per_b * abs(1 - v_mate / v_self), rel=1e-9)


def test_rigid_load_share_counts_the_pairs_on_the_line_of_action():
    pair = _case().gear_pair()
    op = pair.operating(0.0)
    rb1, pb = pair.pinion.base_radius, pair.base_pitch
    s = np.linspace(op.s_start, op.s_end, 2001)[1:-1]
    count = np.ones(s.size, int)
    for m in range(1, 4):
        count += ((s + m * pb) <= op.s_end).astype(int) + ((s - m * pb) >= op.s_start).astype(int)
    np.testing.assert_array_equal(rigid_load_share(pair, "pinion", s / rb1), 1.0 / count)
    assert set(np.unique(count)) == {1, 2}


def test_the_profile_is_zero_at_the_pitch_point_and_largest_at_the_root():
    case = _case()
    pair = case.gear_pair()
    (f,) = faults_from_case(case, legacy_crack=False)
    assert f.law == "archard"
    a, b = f.window
    u = np.linspace(a, b, 5001)
    e = f.deviation(u)
    assert e.max() == pytest.approx(DELTA, rel=1e-12) and e.min() >= 0
    u_pitch = pair.pitch_point_s / pair.pinion.base_radius
    du = (b - a) / 800  # the shape's sample spacing
    assert f.deviation(np.array([u_pitch]))[0] < 1e-3 * DELTA + DELTA * du / (u_pitch - a)
    # the deepest point is in the dedendum (below the pitch point) of the pinion
    assert u[np.argmax(e)] < u_pitch
    # uniform law: the old flat profile
    (g,) = faults_from_case(case.with_overrides({"faults.0.law": "uniform"}), legacy_crack=False)
    np.testing.assert_array_equal(g.deviation(u), np.full(u.size, DELTA))


@pytest.fixture(scope="module")
def healthy_map():
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        return build_map(_case(), cracked=False)


def test_static_te_of_the_worn_pair_rises_by_the_local_depth(healthy_map):
    case = _case()
    pair = case.gear_pair()
    mods = ToothModifications.from_case(case)
    assert "archard profile, largest" in mods.describe()
    th = np.linspace(0.0, 2 * math.pi, 23 * 1000, endpoint=False)
    worn = static_transmission_error(healthy_map, 100.0, modifications=mods, theta=th)
    perfect = static_transmission_error(healthy_map, 100.0,
                                        modifications=ToothModifications.none(pair), theta=th)
    d = (worn.transmission_error.values - perfect.transmission_error.values) * 1e-6  # [m]
    gap = fault_gap(pair, faults_from_case(case, legacy_crack=False), th, 0.0).sum(axis=1)
    # the table samples the profile on its nodes, linear between: where the rigid load share
    # steps (x2 at the ends of single contact) it smears the step over a node spacing, so the
    # points within two spacings of a step are left out of the comparison
    g = mods.pinion
    dth = 2.0 * g.du / pair.pinion.base_radius
    near_step = np.zeros(th.size, bool)
    for sgn in (-1.0, 1.0):
        other = fault_gap(pair, faults_from_case(case, legacy_crack=False), th + sgn * dth,
                          0.0).sum(axis=1)
        near_step |= np.abs(other - gap) > 0.2 * np.maximum(gap, 1e-12)
    single = (worn.loaded_pairs.values == 1) & (gap > 0.05 * DELTA) & ~near_step
    assert single.sum() > 100
    err = np.abs(d[single] - gap[single])
    print(f"single contact: max |dTE - e| = {err.max():.3g} m, median {np.median(err):.3g} m "
          f"({near_step.sum()} points near a step left out)")
    assert err.max() < 1e-3 * DELTA
    zero = _case(0.0)
    assert not ToothModifications.from_case(zero).active


def test_archard_scale():
    pair = _case().gear_pair()
    h = archard_scale(pair, "pinion", wear_coefficient=1e-16, cycles=1e6, torque=100.0,
                      face_width=0.02)
    # k N (W / b) max f with W = T / r_b1
    u = np.linspace(*faults_from_case(_case(), legacy_crack=False)[0].window, 801)
    f = rigid_load_share(pair, "pinion", u) * sliding_factor(pair, "pinion", u)
    assert h == pytest.approx(1e-16 * 1e6 * 100.0 / pair.pinion.base_radius / 0.02 * f.max(),
                              rel=1e-12)
    with pytest.raises(InputError, match="cycles"):
        archard_scale(pair, "pinion", wear_coefficient=1e-16, cycles=-1, torque=100.0,
                      face_width=0.02)
