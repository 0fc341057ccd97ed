"""ToothSection (stiffness/pem/section.py): the section at its two ends against closed forms, and
the breakpoints where a crack's limit line meets the flank, placed at the edges of the scan that
finds them.

Written against the mutants that survived the first mutation run of
``stiffness/pem/section.py`` (docs/mutation.md, issue 20 item 6). Oracles:

* the root chord ``(r_f sin theta_f, r_f cos theta_f)`` and the tip point
  ``r_a (sin beta_a, cos beta_a)``, ``beta_a = pi/(2z) + 2 x tan(alpha)/z + inv(alpha) -
  inv(alpha_a)`` (the textbook tooth-thickness half-angle);
* the involute written in polar form: a point at radius ``r`` lies at ``a2 - inv(acos(r_b/r))``
  from the centreline, solved for the height with scipy ``brentq``;
* cracks built so that their parallel limit line meets the fillet at a chosen height (from the
  crack convention of :mod:`geardyn.stiffness.pem.crack`); the section must be cut there.
"""

from __future__ import annotations

import math

import numpy as np
import pytest
from scipy.optimize import brentq

from geardyn.geometry import Gear
from geardyn.stiffness.pem import ToothCrack, ToothSection, crack_geometry
from geardyn.stiffness.pem.profile import _fillet_xy

DEG = math.pi / 180
N_SCAN = 257  # samples of the limit-line scan per piece (ToothSection._crack_breaks)


def inv(a: float) -> float:
    return math.tan(a) - a


@pytest.fixture(scope="module")
def gear() -> Gear:
    return Gear(20, 6e-3, 20 * DEG, profile_shift=0.3)


@pytest.fixture(scope="module")
def healthy(gear) -> ToothSection:
    return ToothSection(gear)


def _involute_h(gear: Gear, y: float) -> float:
    """Half-thickness of the involute flank at centreline height ``y`` (polar form)."""
    rb, a2 = gear.base_radius, gear.base_half_angle

    def height(r):
        return r * math.cos(a2 - inv(math.acos(rb / r))) - y

    r = brentq(height, rb * (1 + 1e-12), gear.tip_radius * 1.01, xtol=1e-16, rtol=1e-15)
    return r * math.sin(a2 - inv(math.acos(rb / r)))


def test_half_thickness_at_the_root_chord_and_the_tip(gear, healthy):
    """Both ends of the integration belong to the section (closed intervals)."""
    z, x, a = 20, 0.3, 20 * DEG
    rf, tf = gear.root_radius, gear.root_half_angle
    assert healthy.y_root == pytest.approx(rf * math.cos(tf), rel=1e-14)
    aa = math.acos(gear.base_radius / gear.tip_radius)
    beta = math.pi / (2 * z) + 2 * x * math.tan(a) / z + inv(a) - inv(aa)
    assert healthy.y_tip == pytest.approx(gear.tip_radius * math.cos(beta), rel=1e-14)
    h = healthy.half_thickness([healthy.y_root, healthy.y_tip])
    np.testing.assert_allclose(h, [rf * math.sin(tf), gear.tip_radius * math.sin(beta)],
                               rtol=1e-12)


def test_half_thickness_of_a_cracked_section_is_the_healthy_one(gear, healthy):
    """A crack changes the load-carrying width, not the outline: h(y) is the same at every
    height, including the cut points of the split pieces; on the flank it is the polar
    involute."""
    sec = ToothSection(gear, ToothCrack(depth=1.5e-3, limit_line="parallel"))
    assert len(sec.pieces) > len(healthy.pieces)
    ys = sorted({p.y0 for p in sec.pieces} | {p.y1 for p in sec.pieces}
                | set(np.linspace(sec.y_root, sec.y_tip, 9)))
    np.testing.assert_allclose(sec.half_thickness(ys), healthy.half_thickness(ys), rtol=1e-12)
    y_flank = 0.5 * (healthy.pieces[-1].y0 + healthy.y_tip)
    assert sec.half_thickness(y_flank)[0] == pytest.approx(_involute_h(gear, y_flank), rel=1e-10)


def _fillet_samples(sec: ToothSection):
    p = sec.pieces[0]
    assert p.kind == "fillet"
    ts = np.linspace(p.t0, p.t1, N_SCAN)
    return ts, _fillet_xy(sec.gear, ts)


def _parallel_crack_through(gear, xt: float, yt: float) -> ToothCrack:
    """The crack from the 30 deg mouth whose tip is (xt, yt): depth and angle of the convention
    (tip q sin v nearer the centreline, q cos v lower than the mouth)."""
    xm, ym = crack_geometry(gear, ToothCrack(depth=1e-3)).mouth
    return ToothCrack(depth=math.hypot(xm - xt, ym - yt), angle=math.atan2(xm - xt, ym - yt),
                      limit_line="parallel")


def _has_cut_at(sec: ToothSection, y: float) -> bool:
    return min(abs(p.y0 - y) for p in sec.pieces) < 1e-13


def test_limit_line_meeting_the_fillet_in_the_last_scan_interval(gear, healthy):
    """The parallel limit line x = x_tip meets the fillet between the last two scan samples
    (just below the form point): the section is cut there."""
    ts, pts = _fillet_samples(healthy)
    g_star = 0.5 * (ts[-2] + ts[-1])
    xs, ys = (float(v) for v in _fillet_xy(gear, np.array([g_star]))[0])
    ym = crack_geometry(gear, ToothCrack(depth=1e-3)).mouth[1]
    sec = ToothSection(gear, _parallel_crack_through(gear, xs, ym - 0.5e-3))
    assert pts[-2, 1] < ys < pts[-1, 1]
    assert _has_cut_at(sec, ys)


def test_limit_line_meeting_the_fillet_in_the_first_scan_interval_above_the_crack_tip(
        gear, healthy):
    """Crack tip just below the mouth's height, limit line meeting the fillet in the first
    scan interval that lies wholly above the tip: the section is cut there."""
    ts, pts = _fillet_samples(healthy)
    xm, ym = crack_geometry(gear, ToothCrack(depth=1e-3)).mouth
    y = pts[:, 1]
    k0 = int(np.argmax(y > ym))
    yt = 0.5 * (y[k0 - 1] + ym)
    g_star = 0.5 * (ts[k0] + ts[k0 + 1])
    xs, ys = (float(v) for v in _fillet_xy(gear, np.array([g_star]))[0])
    sec = ToothSection(gear, _parallel_crack_through(gear, xs, yt))
    assert y[k0 - 1] < sec.crack_geometry.tip[1] < y[k0] < ys < y[k0 + 1]
    assert _has_cut_at(sec, ys) and _has_cut_at(sec, sec.crack_geometry.tip[1])


# ------------------------------------------------------------------ refusals in full
def _refusal(exc) -> tuple:
    return exc.value.field, exc.value.value, exc.value.allowed


def test_section_refusals_in_full(gear):
    from geardyn.errors import GeometryError, InputError

    with pytest.raises(InputError) as exc:
        ToothSection(gear, model="fe")
    assert _refusal(exc) == ("model", "fe", "'exact' or 'classic'")
    pointed = Gear(8, 6e-3, 20 * DEG, profile_shift=0.6)
    assert pointed.pointed
    with pytest.raises(GeometryError) as exc:
        ToothSection(pointed)
    assert _refusal(exc) == ("teeth", 8, "teeth that are not pointed (the PEM needs a tip land)")
    undercut = Gear(10, 6e-3, 20 * DEG)
    assert undercut.undercut and not undercut.pointed
    with pytest.raises(GeometryError) as exc:
        ToothSection(undercut)
    assert _refusal(exc) == ("teeth", 10,
                             "a tooth without undercut for the PEM (use the FE method)")
    # x = 0.9 on 14 teeth: the trochoid's height is not monotonic along the fillet
    looped = Gear(14, 6e-3, 20 * DEG, profile_shift=0.9)
    yy = _fillet_xy(looped, np.linspace(looped.pressure_angle, math.pi / 2, 400))[:, 1]
    assert np.any(np.diff(yy) > 0)
    with pytest.raises(GeometryError) as exc:
        ToothSection(looped)
    assert _refusal(exc) == ("teeth", 14,
                             "a fillet whose height decreases monotonically to the root (this "
                             "tooth is not a cantilever the PEM can integrate)")


def test_roll_refusal_in_full(healthy):
    from geardyn.errors import GeometryError

    healthy.check_roll([healthy.u_min, healthy.u_tip])          # the ends are inside
    with pytest.raises(GeometryError) as exc:
        healthy.check_roll([0.3, healthy.u_tip + 1e-6])
    assert _refusal(exc) == (
        "roll", (0.3, healthy.u_tip + 1e-6),
        f"roll angles in [{healthy.u_min:.6g}, {healthy.u_tip:.6g}] rad (form circle to tip); "
        "contact below the form circle is interference")


# ------------------------------------------------------------------ width rule
def test_width_rule_below_and_above_the_crack_tip(gear):
    """Chen & Shao 2011 / Mohammed et al. 2013: below the crack tip the whole section carries
    load (w = 2h); above it w = h + min(h, x_limit(y))."""
    sec = ToothSection(gear, ToothCrack(depth=1.5e-3, limit_line="parallel"))
    xt, yt = sec.crack_geometry.tip
    h = np.array([2e-3, 3e-3, 3e-3, 1e-4])
    y = np.array([yt - 1e-3, yt - 1e-9, yt + 1e-4, yt + 1e-3])
    expected = [4e-3, 6e-3, 3e-3 + min(3e-3, xt), 1e-4 + min(1e-4, xt)]
    np.testing.assert_allclose(sec.width(y, h), expected, rtol=1e-15)
    np.testing.assert_array_equal(ToothSection(gear).width(y, h), 2 * h)


# ------------------------------------------------------------------ classic model
def test_classic_section_against_the_root_rectangle_and_the_polar_involute():
    """Classic model (Wan et al. 2014): a rectangle of half-thickness r_b sin(a2) from
    r_f cos(a3) (sin a3 = r_b sin(a2) / r_f) up to the base chord r_b cos(a2), then the
    involute. Beam compliance = the rectangle's polynomial integral in closed form + scipy quad
    of the involute in its roll angle; for z = 60 the root circle is outside the base circle
    and the section starts on the involute at the root circle."""
    from scipy.integrate import quad

    from geardyn.stiffness.pem import tooth_compliance

    E, NU, L = 2e11, 0.3, 0.02
    g = Gear(23, 6e-3, 20 * DEG)
    rb, a2, rf = g.base_radius, g.base_half_angle, g.root_radius
    sec = ToothSection(g, model="classic")
    a3 = math.asin(rb * math.sin(a2) / rf)
    y0, yb, hb = rf * math.cos(a3), rb * math.cos(a2), rb * math.sin(a2)
    assert sec.y_root == pytest.approx(y0, rel=1e-15)
    np.testing.assert_allclose(sec.half_thickness([y0, 0.5 * (y0 + yb), yb]), hb, rtol=1e-14)
    for roll in (0.2, 0.45):
        a1 = roll - a2
        ca, sa = math.cos(a1), math.sin(a1)
        w = 2 * hb
        # int_{y0}^{yb} 12 (rb - y ca)^2 / w^3 dy, in closed form
        bend = 12 / w ** 3 * ((rb - y0 * ca) ** 3 - (rb - yb * ca) ** 3) / (3 * ca)
        rest = (2.4 * (1 + NU) * ca ** 2 + sa ** 2) * (yb - y0) / w

        def f(u, ca=ca, sa=sa):
            a = a2 - u
            h, y, dy = rb * (u * math.cos(a) + math.sin(a)), rb * (math.cos(a) - u * math.sin(a)), \
                rb * u * math.cos(a)
            return (12 * (rb - y * ca) ** 2 / (2 * h) ** 3
                    + (2.4 * (1 + NU) * ca ** 2 + sa ** 2) / (2 * h)) * dy

        inv_part = quad(f, 0.0, roll, epsabs=0, epsrel=1e-13)[0]
        t = tooth_compliance(sec, roll, E, NU, L, terms=True)
        beam = t["bending"] + t["shear"] + t["axial"]
        assert beam.dtype == np.float64
        assert beam[0] == pytest.approx((bend + rest + inv_part) / (E * L), rel=1e-11)
    big = Gear(60, 6e-3, 20 * DEG, bore_radius=0.1)
    assert big.root_radius > big.base_radius
    s60 = ToothSection(big, model="classic")
    r, rb6 = big.root_radius, big.base_radius
    assert s60.u_min == pytest.approx(math.sqrt((r / rb6) ** 2 - 1), rel=1e-15)
    assert s60.y_root == pytest.approx(
        r * math.cos(big.base_half_angle - inv(math.acos(rb6 / r))), rel=1e-14)
    assert [p.kind for p in s60.pieces] == ["involute"]


def test_limit_line_cutting_the_tooth_off_is_refused_in_full():
    """Classic 23-tooth section, an 11.48 mm crack at 85 deg with the tip line: the tip lies
    beyond the centreline and the line from it to the tip corner leaves no material in some
    sections (w <= 0 at Gauss nodes); a 10 mm crack at 45 deg is fine."""
    from geardyn.errors import InputError

    g = Gear(23, 6e-3, 20 * DEG, bore_radius=0.01)
    crack = ToothCrack(depth=0.011482758620689655, angle=85 * DEG, limit_line="tip")
    assert crack_geometry(g, crack).tip[0] < 0
    with pytest.raises(InputError) as exc:
        ToothSection(g, crack, model="classic")
    assert _refusal(exc) == (
        "crack.depth", crack.depth,
        "a crack whose limit line leaves material in every section up to the tip (this "
        "crack's limit line to the tip corner cuts the tooth off; use a shorter or shallower "
        "crack)")  # a tip limit line is not told to use limit_line='tip' (mutation run)
    ok = ToothSection(g, ToothCrack(depth=10e-3, limit_line="tip"), model="classic")
    y, w, _ = ok.nodes([ok.u_tip])
    assert np.all(w > 0)


def test_tip_limit_line_meets_the_flank_where_the_section_is_cut():
    """Classic 40-tooth section, crack tip on the involute, tip limit line: the flank is cut at
    the crack tip and where h(y) = x_limit(y) (the definition of the crossing)."""
    g = Gear(40, 6e-3, 20 * DEG, bore_radius=0.04)
    sec = ToothSection(g, ToothCrack(depth=0.5e-3), model="classic")
    cg = sec.crack_geometry
    cuts = [p.y0 for p in sec.pieces if p.kind == "involute"][1:]
    assert len(cuts) == 2 and cuts[0] == pytest.approx(cg.tip[1], abs=1e-15)
    yc = cuts[1]
    assert sec.half_thickness(yc)[0] == pytest.approx(float(cg.limit_x(yc)), abs=1e-14)


def test_crack_above_the_load_point_changes_nothing():
    """The crack only narrows sections above its tip, so for a load point below the tip the
    cracked tooth's compliance is the healthy one. Classic 40-tooth section, tip 0.23 mm above
    the base chord r_b cos(a2) (inside the band up to r_b / cos(a2))."""
    from geardyn.stiffness.pem import tooth_compliance

    g = Gear(40, 6e-3, 20 * DEG, bore_radius=0.04)
    healthy = ToothSection(g, model="classic")
    sec = ToothSection(g, ToothCrack(depth=1e-3), model="classic")
    rb, a2 = g.base_radius, g.base_half_angle
    yt = sec.crack_geometry.tip[1]
    assert rb * math.cos(a2) < yt < rb / math.cos(a2)
    rolls = np.array([0.0, 0.02, 0.04])
    assert np.all(sec.load_point(rolls)[0] < yt)
    np.testing.assert_allclose(tooth_compliance(sec, rolls, 2e11, 0.3, 0.02),
                               tooth_compliance(healthy, rolls, 2e11, 0.3, 0.02), rtol=1e-13)


@pytest.mark.parametrize(("depth", "angle"), [
    # the limit line meets the flank between the crack-tip height and the next scan sample
    (4.792939602694798e-06, 0.2388824205686765),
    # the limit line meets the flank exactly at a scan sample (f = 0 there)
    (0.0005845975722696846, 0.5446875722078858),
])
def test_kink_of_the_limit_line_is_a_breakpoint_in_the_scan_corner_cases(gear, depth, angle):
    """Found by mutation testing (docs/mutation.md): in these two cases the section was not cut
    where the parallel limit line meets the flank, and the Gauss rule integrated across the kink
    (errors 2.3e-8 and -2.0e-6 against adaptive quad, normally ~1e-12). Oracle: scipy quad."""
    from geardyn.stiffness.pem import tooth_compliance, tooth_compliance_quad

    sec = ToothSection(gear, ToothCrack(depth=depth, angle=angle, limit_line="parallel"))
    gauss = float(tooth_compliance(sec, np.array([0.5]), 70e9, 0.3, 0.02)[0])
    ref = tooth_compliance_quad(sec, 0.5, 70e9, 0.3, 0.02)
    assert gauss == pytest.approx(ref, rel=1e-10, abs=0.0)
