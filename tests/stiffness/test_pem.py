"""Potential-energy mesh stiffness: each term against an independent oracle, ISO 6336-1, the
geometry of the operating centre distance, and the crack.

Tiers: exact (closed forms, mpmath, adaptive quadrature: tight tolerances); validation against
ISO 6336-1 (the tolerances the issue sets: 20 % single, 15 % mean); consistency with the geometry
module (contact ratio, pairs in contact: exact up to the sampling step).
"""

from __future__ import annotations

import math
import warnings

import mpmath
import numpy as np
import pytest

import geardyn
from geardyn.errors import GeometryError, InputError
from geardyn.geometry import Gear, GearPair
from geardyn.stiffness.iso import iso_stiffness
from geardyn.stiffness.pem import (
    PEMModel,
    SainsotRangeWarning,
    ToothCrack,
    ToothSection,
    axial_compression_compliance,
    bending_compliance,
    crack_geometry,
    foundation_compliance,
    hertz_compliance,
    pem_map,
    sainsot_validity,
    shear_compliance,
    tooth_compliance,
    tooth_compliance_quad,
)

STEEL = {"material.youngs_modulus": 206e9, "material.poisson_ratio": 0.3}
E_ST, NU_ST = 206e9, 0.3


@pytest.fixture(scope="module")
def case():
    return geardyn.paper_case()


@pytest.fixture(scope="module")
def pair(case):
    return case.gear_pair()


@pytest.fixture(scope="module")
def pitch(pair):
    """Pinion and gear roll angles of the design pitch point [rad]."""
    return (pair.pitch_point_s / pair.pinion.base_radius,
            (pair.design_t1t2 - pair.pitch_point_s) / pair.gear.base_radius)


def _crack(depth=5e-3, line="tip", gear="pinion", tooth=11, angle=45.0):
    return ToothCrack(gear, tooth, depth, math.radians(angle), line)


# ------------------------------------------------------------------------------ Hertz, scaling
def test_hertz_closed_form_and_ross_value():
    # Yang & Lin (1987): k_h = pi E L / (4 (1 - nu^2)); ROSS's test value for 206 GPa, 0.3, 20 mm
    assert 1 / hertz_compliance(206e9, 0.3, 0.02) == pytest.approx(3.5558686e9, rel=1e-7)
    for E, nu, L in ((69e9, 0.33, 0.02), (2.1e11, 0.29, 0.05)):
        assert 1 / hertz_compliance(E, nu, L) == pytest.approx(
            math.pi * E * L / (4 * (1 - nu ** 2)), rel=1e-15)


def test_stiffness_scales_exactly_with_modulus_and_face_width(pair):
    th = np.linspace(0, 2 * math.pi, 997)
    base = PEMModel(pair, 69e9, 0.33, _crack()).mesh_stiffness(th, 0.4e-3)
    stiffer = PEMModel(pair, 2.5 * 69e9, 0.33, _crack()).mesh_stiffness(th, 0.4e-3)
    wider = PEMModel(pair, 69e9, 0.33, _crack(), face_width=3 * 0.02).mesh_stiffness(th, 0.4e-3)
    np.testing.assert_allclose(stiffer / base, 2.5, rtol=1e-12)
    np.testing.assert_allclose(wider / base, 3.0, rtol=1e-12)


# ------------------------------------------------------------------------------ term values
def test_terms_at_the_pitch_point_match_the_design_table(pair, pitch):
    """stiffness.md section 1.3 (steel, L = 1 m, r_int = 20 mm) lists our own earlier PEM
    computation with the classic tooth (base-circle involute + root rectangle) and theta_f =
    alpha_3. It is not an independent source: an order-of-magnitude check at 20 %."""
    g = pair.pinion
    roll = pitch[0]
    t = tooth_compliance(ToothSection(g, model="classic"), [roll], E_ST, NU_ST, 1.0, terms=True)
    a3 = math.asin(g.base_radius * math.sin(g.base_half_angle) / g.root_radius)
    kf = foundation_compliance(g, [roll], E_ST, 1.0, theta_f=a3)[0]
    table = {"bending": 3.5e-12, "shear": 1.0e-11, "axial": 2.7e-13}
    for name, ref in table.items():
        assert t[name][0] == pytest.approx(ref, rel=0.2), name
    assert kf == pytest.approx(3.2e-11, rel=0.2)
    assert hertz_compliance(E_ST, NU_ST, 1.0) == pytest.approx(5.6e-12, rel=0.2)
    # the exact tooth (trochoid fillet wider than the rectangle) bends less; the real theta_f
    # (3.013/z > alpha_3) makes the foundation stiffer (trap T8)
    te = tooth_compliance(ToothSection(g), [roll], E_ST, NU_ST, 1.0, terms=True)
    assert te["bending"][0] < t["bending"][0]
    assert te["foundation"][0] < kf
    assert g.root_half_angle == pytest.approx(3.013 / 23, rel=1e-3)


def test_foundation_load_line_point_is_on_the_centreline(pair):
    """u_f = r_b / cos(alpha_1) - r_f equals x_F - h_F tan(alpha_1) - r_f (trap T9)."""
    g = pair.pinion
    sec = ToothSection(g)
    roll = np.linspace(sec.u_min, sec.u_tip, 13)
    y, h, a1 = sec.load_point(roll)
    np.testing.assert_allclose(y - h * np.tan(a1), g.base_radius / np.cos(a1), rtol=1e-14)


# ------------------------------------------------------------------------------ oracles
def _tian_integrals(gear, roll, a_end):
    """Closed-form integrands of Tian (2004) over the involute, alpha in [-alpha_1, a_end],
    integrated by mpmath at 30 digits; returned per unit E L (1/k times E L)."""
    mpmath.mp.dps = 30
    a2 = mpmath.mpf(gear.base_half_angle)
    a1 = mpmath.mpf(roll) - a2
    ca1, sa1 = mpmath.cos(a1), mpmath.sin(a1)

    def den(a):
        return mpmath.sin(a) + (a2 - a) * mpmath.cos(a)

    def fb(a):
        return (3 * (1 + ca1 * ((a2 - a) * mpmath.sin(a) - mpmath.cos(a))) ** 2
                * (a2 - a) * mpmath.cos(a) / (2 * den(a) ** 3))

    def fs(a):
        return (a2 - a) * mpmath.cos(a) / den(a)

    b = mpmath.quad(fb, [-a1, a_end])
    j = mpmath.quad(fs, [-a1, a_end])
    return float(b), float(j), float(ca1 ** 2), float(sa1 ** 2)


@pytest.mark.parametrize("frac", [0.05, 0.5, 0.97])
def test_bending_shear_axial_against_mpmath_and_root_rectangle(pair, frac):
    """Classic tooth, root circle inside the base circle: our Gauss quadrature of the section
    equals the mpmath integral of Tian's closed-form integrands over the involute plus the
    closed-form root-rectangle terms of Wan et al. (2014) / stiffness.md 1.2."""
    g = pair.pinion
    sec = ToothSection(g, model="classic")
    roll = sec.u_min + frac * (sec.u_tip - sec.u_min)
    a2, rb, rf = g.base_half_angle, g.base_radius, g.root_radius
    b_inv, j_inv, c2, s2 = _tian_integrals(g, roll, a2)
    a1 = roll - a2
    a3 = math.asin(rb * math.sin(a2) / rf)
    d_b = (((1 - rf / rb * math.cos(a1) * math.cos(a3)) ** 3 - (1 - math.cos(a1) * math.cos(a2))
            ** 3) / (2 * math.cos(a1) * math.sin(a2) ** 3))
    d_j = (math.cos(a2) - rf / rb * math.cos(a3)) / math.sin(a2)
    E, nu, L = E_ST, NU_ST, 0.02
    assert bending_compliance(sec, roll, E, L)[0] == pytest.approx((b_inv + d_b) / (E * L),
                                                                    rel=1e-11)
    assert shear_compliance(sec, roll, E, nu, L)[0] == pytest.approx(
        1.2 * (1 + nu) * c2 * (j_inv + d_j) / (E * L), rel=1e-11)
    assert axial_compression_compliance(sec, roll, E, L)[0] == pytest.approx(
        s2 * (j_inv + d_j) / (2 * E * L), rel=1e-11)


def test_involute_only_when_root_circle_is_outside_the_base_circle():
    """62/62, m = 2 mm: r_f > r_b; the classic tooth is the involute truncated at r_f
    (alpha_5 = alpha_2 - sqrt((r_f/r_b)^2 - 1)); against mpmath."""
    g = Gear(62, 2e-3, math.radians(20), bore_radius=17.5e-3)
    assert g.root_radius > g.base_radius
    sec = ToothSection(g, model="classic")
    a5 = g.base_half_angle - math.sqrt((g.root_radius / g.base_radius) ** 2 - 1)
    for roll in (sec.u_min + 0.1, 0.5 * (sec.u_min + sec.u_tip), sec.u_tip):
        b, j, c2, s2 = _tian_integrals(g, roll, a5)
        assert bending_compliance(sec, roll, 2e11, 1.0)[0] == pytest.approx(b / 2e11, rel=1e-11)
        assert axial_compression_compliance(sec, roll, 2e11, 1.0)[0] == pytest.approx(
            s2 * j / 2 / 2e11, rel=1e-11)
    # the exact (fillet) tooth works there too and is close to the classic one
    pm_e = PEMModel(GearPair(g, g), 2e11, 0.3)
    pm_c = PEMModel(GearPair(g, g), 2e11, 0.3, model="classic")
    th = np.linspace(0, g.base_pitch / g.base_radius, 50)
    assert np.all(np.abs(pm_e.mesh_stiffness(th) / pm_c.mesh_stiffness(th) - 1) < 0.05)


@pytest.mark.parametrize("crack", [None, "tip", "parallel"])
def test_exact_tooth_gauss_quadrature_against_adaptive_quad(pair, crack):
    """The production Gauss rule against scipy quad at epsabs 1e-14, healthy and cracked
    (7 mm crack so that the two limit lines differ)."""
    cr = _crack(7e-3, crack) if crack else None
    sec = ToothSection(pair.pinion, cr)
    for roll in np.linspace(sec.u_min + 1e-3, sec.u_tip, 5):
        ref = tooth_compliance_quad(sec, roll, E_ST, NU_ST, 0.02)
        assert tooth_compliance(sec, [roll], E_ST, NU_ST, 0.02)[0] == pytest.approx(ref,
                                                                                   rel=1e-10)


def test_exact_section_is_the_generated_outline(pair, pitch):
    """An independent integration on the points of Gear.outline() (trapezoid rule in y on a dense
    outline) gives the bending compliance of the parametric section to 1e-5."""
    g = pair.pinion
    o = g.outline(n_involute=6000, n_fillet=6000)
    flank = o.right_flank()
    y, h = flank[:, 1], flank[:, 0]
    assert np.all(np.diff(y) > 0)
    roll = pitch[0]
    sec = ToothSection(g)
    yF, hF, a1 = sec.load_point(roll)
    yy = np.linspace(y[0], float(yF), 200001)
    hh = np.interp(yy, y, h)
    f = 12 * (g.base_radius - yy * math.cos(a1)) ** 2 / (2 * hh) ** 3
    ref = np.sum((f[1:] + f[:-1]) / 2 * np.diff(yy)) / (E_ST * 0.02)
    assert bending_compliance(sec, roll, E_ST, 0.02)[0] == pytest.approx(ref, rel=1e-5)
    assert sec.y_root == pytest.approx(g.root_radius * math.cos(g.root_half_angle), rel=1e-12)
    probe = np.linspace(y[0] + 1e-6, y[-1] - 1e-6, 9)
    np.testing.assert_allclose(sec.half_thickness(probe), np.interp(probe, y, h), atol=1e-9)


def test_tooth_is_continuous_where_fillet_meets_involute(pair):
    """C1 join at the form circle: half-thickness, slope and the bending integrand agree from
    both sides, and the compliance of a load just above the form point is finite and smooth."""
    g = pair.pinion
    sec = ToothSection(g)
    fil, inv = sec.pieces[0], sec.pieces[1]
    assert fil.kind == "fillet" and inv.kind == "involute"
    eps = 1e-7
    hf, yf, dyf = sec._eval(fil, np.array([fil.t1 - eps * (fil.t1 - fil.t0), fil.t1]))
    hi, yi, dyi = sec._eval(inv, np.array([inv.t0, inv.t0 + eps]))
    assert abs(hf[1] - hi[0]) < 1e-12 and abs(yf[1] - yi[0]) < 1e-12
    slope_f = (hf[1] - hf[0]) / (yf[1] - yf[0])
    slope_i = (hi[1] - hi[0]) / (yi[1] - yi[0])
    assert slope_f == pytest.approx(slope_i, abs=1e-5)
    u = sec.u_min + np.array([1e-6, 2e-6, 3e-6])
    c = tooth_compliance(sec, u, E_ST, NU_ST, 0.02)
    assert np.all(np.isfinite(c))
    # second difference ~ 0: no kink at the join
    assert abs(c[0] - 2 * c[1] + c[2]) < 1e-9 * c[1]


def test_compliance_table_matches_direct_quadrature(pair):
    rng = np.random.default_rng(3)
    for cr in (None, _crack(5e-3, "parallel"), _crack(7e-3, "tip")):
        pm = PEMModel(pair, E_ST, NU_ST, cr)
        sec = pm.sections[("pinion", cr is not None)]
        u = rng.uniform(sec.u_min, sec.u_tip, 400)
        c_tab = pm.tooth_compliance("pinion", u, cr is not None)
        c_dir = pm.tooth_compliance_exact("pinion", u, cr is not None)
        np.testing.assert_allclose(c_tab, c_dir, rtol=1e-7)


# ------------------------------------------------------------------------------ ISO 6336-1
def test_steel_pair_against_iso_6336(case, pitch):
    """Steel version of the paper's pair: single-pair stiffness at the pitch point within 20 % of
    ISO c' = 11.96 N/(mm um) and the mean mesh stiffness within 15 % of c_gamma_alpha = 17.27."""
    steel = case.with_overrides(STEEL)
    pair = steel.gear_pair()
    pm = PEMModel.from_case(steel, cracked=False)
    b = steel.pair.face_width
    iso = iso_stiffness(pair, E_ST)
    assert iso.c_single / 1e9 == pytest.approx(11.96, abs=0.01)
    assert iso.c_mesh / 1e9 == pytest.approx(17.27, abs=0.01)
    c1 = pm.pair_stiffness(*pitch) / b
    th = np.linspace(0, pair.mesh_angle, 4000, endpoint=False)
    cmean = pm.mesh_stiffness(th).mean() / b
    assert abs(c1 / iso.c_single - 1) < 0.20, c1 / 1e9
    assert abs(cmean / iso.c_mesh - 1) < 0.15, cmean / 1e9
    # without the foundation the classic PEM is far too stiff (trap T12)
    sec = pm.sections[("pinion", False)]
    t = tooth_compliance(sec, [pitch[0]], E_ST, NU_ST, b, terms=True)
    no_f = 1 / (pm.hertz + 2 * (t["bending"][0] + t["shear"][0] + t["axial"][0])) / b
    assert no_f > 1.5 * iso.c_single


# ------------------------------------------------------------------------------ centre distance
def test_stiffness_falls_and_single_zone_lengthens_with_centre_distance(pair):
    pm = PEMModel(pair, 69e9, 0.33)
    th = np.linspace(0, pair.mesh_angle, 20000, endpoint=False)
    means, singles = [], []
    for dd in (0.0, 0.5e-3, 1.0e-3):
        r = pm.evaluate(th, dd)
        eps = pair.operating(dd).contact_ratio
        single = np.mean(r["pairs_in_contact"] == 1)
        assert single == pytest.approx(2 - eps, abs=2e-4)
        assert np.mean(r["pairs_in_contact"] == 2) == pytest.approx(eps - 1, abs=2e-4)
        means.append(r["k_mb"].mean())
        singles.append(single)
    assert means[0] > means[1] > means[2]
    assert singles[0] < singles[1] < singles[2]
    # pointwise: at every angle K at 1 mm is below K at 0 mm in the double-contact zones of both
    k0, k1 = pm.mesh_stiffness(th, 0.0), pm.mesh_stiffness(th, 1e-3)
    n0, n1 = pm.evaluate(th, 0.0)["pairs_in_contact"], pm.evaluate(th, 1e-3)["pairs_in_contact"]
    both2 = (n0 == 2) & (n1 == 2)
    assert np.all(k1[both2] < k0[both2])


def test_pairs_and_load_shares_against_the_geometry(pair):
    pm = PEMModel(pair, 69e9, 0.33, _crack())
    rng = np.random.default_rng(11)
    for _ in range(200):
        th, dd = rng.uniform(-4, 4), rng.uniform(-0.5e-3, 2e-3)
        r = pm.evaluate([th], dd)
        cp = pair.contact_points(th, dd)
        assert r["pairs_in_contact"][0] == int(cp.in_contact.sum())
        assert set(r["pair"][0][r["load_share"][0] > 0]) == set(cp.pair[cp.in_contact])
        assert r["load_share"][0].sum() == pytest.approx(1.0, abs=1e-14)


def test_torsional_stiffness_uses_the_base_radius(pair):
    pm = PEMModel(pair, 69e9, 0.33)
    th = np.linspace(0, 1, 7)
    k = pm.mesh_stiffness(th, 0.7e-3)
    np.testing.assert_allclose(pm.torsional_stiffness(th, 0.7e-3),
                               k * pair.pinion.base_radius ** 2, rtol=1e-15)
    # the pitch radius would be cos^2(alpha) = 11.7 % off (trap T6)
    assert pair.pinion.base_radius ** 2 / pair.pinion.pitch_radius ** 2 == pytest.approx(
        math.cos(math.radians(20)) ** 2)


# ------------------------------------------------------------------------------ crack
def test_crack_geometry_and_angle_convention(pair):
    g = pair.pinion
    cg = crack_geometry(g, _crack(5e-3, angle=45))
    (xm, ym), (xt, yt) = cg.mouth, cg.tip
    assert xm - xt == pytest.approx(5e-3 * math.sin(math.radians(45)), rel=1e-12)
    assert ym - yt == pytest.approx(5e-3 * math.cos(math.radians(45)), rel=1e-12)
    # the mouth is on the fillet, between the root and the form circle
    assert g.root_radius < cg.mouth_radius < g.form_radius
    # the tangent there makes 30 deg with the centreline (ISO 6336-3 critical section)
    sec = ToothSection(g)
    fil = sec.pieces[0]
    t = sec._param_at(fil, ym)
    h, y, _ = sec._eval(fil, np.array([t - 1e-6, t + 1e-6]))
    assert math.degrees(math.atan2(abs(h[1] - h[0]), abs(y[1] - y[0]))) == pytest.approx(30, abs=1e-4)


def test_crack_lowers_stiffness_only_while_the_cracked_tooth_meshes(pair):
    th = np.linspace(0, 2 * math.pi, 23 * 400, endpoint=False)
    healthy = PEMModel(pair, 69e9, 0.33)
    for gear in ("pinion", "gear"):
        pm = PEMModel(pair, 69e9, 0.33, _crack(gear=gear, tooth=11))
        for dd in (0.0, 1e-3):
            r = pm.evaluate(th, dd)
            k0 = healthy.mesh_stiffness(th, dd)
            z = pair.pinion.teeth if gear == "pinion" else pair.gear.teeth
            in_mesh = np.any((np.mod(r["pair"], z) == 11) & (r["load_share"] > 0), axis=1)
            np.testing.assert_array_equal(r["k_mb"][~in_mesh], k0[~in_mesh])
            assert np.all(r["k_mb"][in_mesh] < k0[in_mesh])
            # pinion tooth 11 passes the pitch point at 2 pi 11 / 23
            assert np.min(np.abs(th[in_mesh] - 11 * pair.mesh_angle)) < 1e-3


def test_crack_effect_grows_with_depth_and_limit_lines_differ_as_documented(pair):
    th = np.linspace(0, 2 * math.pi, 23 * 300, endpoint=False)
    k0 = PEMModel(pair, 69e9, 0.33).mesh_stiffness(th)
    drops = {}
    for line in ("tip", "parallel"):
        drops[line] = []
        for q in (1e-3, 3e-3, 5e-3, 7e-3, 8e-3):
            k = PEMModel(pair, 69e9, 0.33, _crack(q, line)).mesh_stiffness(th)
            drops[line].append(1 - np.min(k / k0))
        assert np.all(np.diff(drops[line]) > 0), drops[line]
    # the parallel line removes at least as much material as the line to the tip corner: equal
    # while the crack tip is farther from the centreline than the tip corner (up to ~5 mm here),
    # strictly larger for deeper cracks (T18)
    d_tip, d_par = np.array(drops["tip"]), np.array(drops["parallel"])
    assert np.all(d_par >= d_tip - 1e-15)
    assert d_par[3] > d_tip[3] * 1.1 and d_par[4] > d_tip[4] * 1.2
    np.testing.assert_allclose(d_par[:3], d_tip[:3], rtol=1e-12)


def test_crack_input_errors(pair):
    with pytest.raises(InputError, match="crack.tooth"):
        PEMModel(pair, 69e9, 0.33, _crack(tooth=23))
    with pytest.raises(InputError, match="crack.angle"):
        ToothCrack("pinion", 0, 5e-3, math.radians(95), "tip")
    with pytest.raises(InputError, match="crack.limit_line"):
        ToothCrack("pinion", 0, 5e-3, 0.5, "diagonal")
    # a parallel line beyond the centreline would cut the loaded flank off
    with pytest.raises(InputError, match="crack.depth"):
        ToothSection(pair.pinion, _crack(9.5e-3, "parallel"))
    with pytest.raises(InputError, match="crack.depth"):
        ToothSection(pair.pinion, _crack(30e-3, "tip"))


# ------------------------------------------------------------------------------ validity, map
def test_sainsot_validity_warning():
    small = Gear(23, 6e-3, math.radians(20), bore_radius=20e-3)
    # 3.013/23 = 0.131 > 0.12: the unsourced theta_f box is a note, not a warning (issue 13)
    assert sainsot_validity(small) == []
    assert any("theta_f" in m for m in sainsot_validity(small, notes=True))
    big = Gear(40, 6e-3, math.radians(20), bore_radius=50e-3)
    assert sainsot_validity(big) == []
    with pytest.warns(SainsotRangeWarning):
        foundation_compliance(small, [0.4], 2e11, 0.02, warn=True, bore_radius=8e-3)
    tiny_bore = Gear(40, 6e-3, math.radians(20), bore_radius=10e-3)
    assert any("h_f" in m for m in sainsot_validity(tiny_bore))


def test_interference_is_reported(pair):
    pm = PEMModel(pair, 69e9, 0.33)
    with pytest.raises(GeometryError):
        pm.tooth_compliance("pinion", [0.01])  # below the form circle
    with pytest.raises(GeometryError):
        pm.check_range([-2.5e-3])


def test_pem_map_outputs(case):
    small = case.with_overrides({"stiffness.centre_distances": 4, "stiffness.nodes_per_segment": 6})
    dd = np.linspace(0, 1.5e-3, 4)
    with warnings.catch_warnings(record=True) as rec:
        warnings.simplefilter("always")
        m = pem_map(small, dd, cracked=True)
    # the shipped case stays inside the fit: no warning, the theta_f note only (issue 13)
    assert not any(issubclass(w.category, SainsotRangeWarning) for w in rec)
    assert m.attrs["warnings"] == [] and any("theta_f" in n for n in m.attrs["notes"])
    assert m.k_mb.shape == (4, 23 * 2 * 6) and m.n_cycles == 23
    assert m.extra["load_share"].shape == (4, 23 * 2 * 6, 3)
    np.testing.assert_allclose(m.extra["load_share"].sum(axis=2), 1.0, atol=1e-14)
    assert set(np.unique(m.extra["pairs_in_contact"])) == {1.0, 2.0}
    assert m.attrs["method"] == "pem" and m.attrs["parameters"]["crack"]["depth_m"] == 5e-3
    # nodes reproduce the direct model
    pm = PEMModel.from_case(small)
    th = m.node_theta()
    for i, d in enumerate(dd):
        np.testing.assert_allclose(m.k_mb[i], pm.mesh_stiffness(th[i], d), rtol=1e-14)
    # gear crack on a 19/48 pair: the map covers one gear revolution (48 mesh cycles)
    other = small.with_overrides({"pinion.teeth": 19, "gear.teeth": 48, "crack.gear": "gear",
                                  "crack.tooth": 40, "pinion.bore_radius": "15 mm",
                                  "gear.bore_radius": "40 mm"})
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", SainsotRangeWarning)
        mg = pem_map(other, dd[:2], cracked=True)
    assert mg.n_cycles == 48
    # a bore that leaves the fitted h_f range warns and is recorded
    tiny = small.with_overrides({"pinion.bore_radius": "8 mm"})
    with pytest.warns(SainsotRangeWarning, match="h_f"):
        mt = pem_map(tiny, dd[:1], cracked=False)
    assert any("h_f" in w for w in mt.attrs["warnings"])


def test_body_torsion_compliance_is_the_annulus_integral():
    """phi/T = int_{r_int}^{r_f} dr / (2 pi G b r^3), integrated numerically, against the closed
    form; the map's series combination 1/(1/k + r_b1^2 c1 + r_b2^2 c2)."""
    from scipy.integrate import quad

    from geardyn.stiffness.pem import PEMModel, body_torsion_compliance

    case = geardyn.paper_case()
    g = case.gear_pair().pinion
    E, nu = 69e9, 0.33
    G = E / (2 * (1 + nu))
    num, _ = quad(lambda r: 1 / (2 * np.pi * G * g.face_width * r ** 3), g.bore_radius,
                  g.root_radius, epsabs=0, epsrel=1e-13)
    assert body_torsion_compliance(g, E, nu) == pytest.approx(num, rel=1e-11)
    plain = PEMModel.from_case(case, cracked=False)
    tors = PEMModel.from_case(case.with_overrides({"stiffness.body_torsion": True}),
                              cracked=False)
    th = np.linspace(0, 2 * np.pi / 23, 50)
    k, kt = plain.mesh_stiffness(th), tors.mesh_stiffness(th)
    c = 2 * g.base_radius ** 2 * num
    np.testing.assert_allclose(kt, 1 / (1 / k + c), rtol=1e-10)
    np.testing.assert_array_equal(plain.evaluate(th)["load_share"], tors.evaluate(th)["load_share"])
