"""The fault library on the PEM side: zero size, monotonic loss, limits, the spall's window and
bad input (issue 15)."""

from __future__ import annotations

import math

import numpy as np
import pytest

from geardyn.config import case_to_toml, load_case
from geardyn.errors import InputError
from geardyn.faults import RootCrack, faults_from_case
from geardyn.stiffness import build_map, map_inputs
from geardyn.stiffness.pem import PEMModel, ToothCrack
from geardyn.stiffness.pem.partial_crack import SlicedTooth
from geardyn.stiffness.pem.tooth import tooth_compliance, tooth_compliance_quad
from geardyn.stiffness.pem.wear import WornSection

from .conftest import faulty

SPALL = {"type": "spall", "tooth": 11, "start": "20 mm", "length": "3 mm", "width": "6 mm",
         "depth": "0.1 mm"}
ZERO = [
    {**SPALL, "width": "0 mm"},
    {"type": "breakage", "tooth": 11, "height": "0 mm"},
    {"type": "root_crack", "tooth": 11, "depth": "0 mm", "width": "8 mm", "front": "linear"},
    {"type": "wear", "tooth": 11, "depth": "0 um", "stiffness": True},
    {**SPALL, "gear": "gear", "length": "0 mm"},
]


@pytest.mark.parametrize("entry", ZERO, ids=lambda e: e["type"])
def test_zero_size_is_the_healthy_map(base, healthy, theta, entry):
    k = faulty(base, entry).mesh_stiffness(theta)
    np.testing.assert_allclose(k, healthy.mesh_stiffness(theta), rtol=1e-14, atol=0)


SIZES = {
    "spall": ("width", ["1 mm", "3 mm", "6 mm", "12 mm", "20 mm"]),
    "breakage": ("height", ["0.5 mm", "1 mm", "2 mm", "3 mm"]),
    "root_crack": ("depth", ["1 mm", "2 mm", "3 mm", "4 mm"]),
    "wear": ("depth", ["10 um", "30 um", "60 um", "100 um"]),
}
ENTRY = {"spall": SPALL, "breakage": {"type": "breakage", "tooth": 11},
         "root_crack": {"type": "root_crack", "tooth": 11, "width": "10 mm",
                        "front": "parabolic", "slices": 8},
         "wear": {"type": "wear", "tooth": 11, "stiffness": True}}


@pytest.mark.parametrize("kind", list(SIZES))
def test_loss_grows_with_size(base, healthy, theta, kind):
    key, values = SIZES[kind]
    kh = healthy.mesh_stiffness(theta)
    losses = []
    for v in values:
        k = faulty(base, {**ENTRY[kind], key: v}).mesh_stiffness(theta)
        assert np.all(k <= kh * (1 + 1e-12))  # a fault never stiffens the mesh
        losses.append(float(np.sum(kh - k)))
    assert losses[0] > 0
    assert np.all(np.diff(losses) > 0), losses


def test_full_width_crack_is_todays_crack(base, theta):
    """faults root_crack through the face = the [crack] section (same numbers)."""
    legacy = PEMModel.from_case(base.with_overrides({"crack.enabled": True}), cracked=True)
    c = base.crack
    new = faulty(base, {"type": "root_crack", "tooth": c.tooth, "depth": c.depth,
                        "angle": c.angle, "limit_line": c.limit_line})
    np.testing.assert_array_equal(new.mesh_stiffness(theta), legacy.mesh_stiffness(theta))


def test_slicing_limits_and_convergence(base, healthy):
    """The slicing of a partial-face crack: one uniform slice through the face is the [crack]
    tooth to round-off; a linear front lies between healthy and through-face and converges
    with the number of slices."""
    pair = base.gear_pair()
    L = base.pair.face_width
    u = np.linspace(0.2, 0.55, 41)
    full = RootCrack(tooth=11, depth=3e-3, face_width=L, slices=1)
    sec = healthy.sections[("pinion", False)]
    model = PEMModel(pair, healthy.E, healthy.nu, ToothCrack(tooth=11, depth=3e-3))
    c_crack = model.tooth_compliance("pinion", u, True)
    sliced = SlicedTooth(PEMModel(pair, healthy.E, healthy.nu), full)
    np.testing.assert_allclose(sliced.compliance(u), c_crack, rtol=1e-12)
    c_h = healthy.tooth_compliance("pinion", u)
    assert sec is not None
    res = []
    for n in (4, 8, 32):
        lin = RootCrack(tooth=11, depth=3e-3, face_width=L, front="linear", slices=n)
        res.append(SlicedTooth(PEMModel(pair, healthy.E, healthy.nu), lin).compliance(u))
    assert np.all((res[-1] > c_h) & (res[-1] < c_crack))
    e1 = np.max(np.abs(res[0] - res[-1]) / res[-1])
    e2 = np.max(np.abs(res[1] - res[-1]) / res[-1])
    assert e2 < e1 / 3 and e2 < 1e-3, (e1, e2)  # midpoint rule: second order in 1/n


def test_spall_acts_only_in_its_roll_window(base, healthy):
    """Hand calculation of the window: pinion tooth T is pair T at theta = 0..., whose contact
    point is at s = s_p + r_b1 (theta - 2 pi T / z1) along the line of action, i.e. at pinion
    roll u = s / r_b1. The spall [u_a, u_b] is crossed for theta in
    [u_a - s_p/r_b1 + 2 pi T/z1, u_b - s_p/r_b1 + 2 pi T/z1]; there the pair keeps the fraction
    (L - b)/L of its stiffness, and nothing changes elsewhere."""
    pair = base.gear_pair()
    rb1, z1, L = pair.pinion.base_radius, pair.pinion.teeth, base.pair.face_width
    T, start, length, width = 11, 20e-3, 3e-3, 6e-3
    ua, ub = start / rb1, (start + length) / rb1
    # pitch point: distance from the pinion's tangency point along the LOA, sqrt(r_w^2 - r_b^2)
    # with the working pitch radius r_w = r z1 / (z1 + z2) of the (unshifted) paper pair
    a = base.pair.module * (z1 + pair.gear.teeth) / 2
    s_p = math.sqrt((a * z1 / (z1 + pair.gear.teeth)) ** 2 - rb1 ** 2)
    assert s_p == pytest.approx(pair.pitch_point_s, rel=1e-12)
    t_a = ua - s_p / rb1 + 2 * math.pi * T / z1
    t_b = ub - s_p / rb1 + 2 * math.pi * T / z1
    th = np.linspace(t_a - 0.05, t_b + 0.05, 2001)
    m = faulty(base, {**SPALL, "tooth": T, "start": "20 mm", "length": "3 mm",
                      "width": "6 mm"})
    k = m.mesh_stiffness(th)
    r = healthy.evaluate(th)
    inside = (th > t_a + 1e-9) & (th < t_b - 1e-9)
    outside = (th < t_a - 1e-9) | (th > t_b + 1e-9)
    np.testing.assert_array_equal(k[outside], r["k_mb"][outside])
    slot = np.mod(r["pair"], z1) == T
    k_pair = np.sum(np.where(slot, r["load_share"], 0.0), axis=1) * r["k_mb"]
    np.testing.assert_allclose(r["k_mb"][inside] - k[inside],
                               (width / L) * k_pair[inside], rtol=1e-12)
    assert np.all(k[inside] < r["k_mb"][inside])


def test_breakage_ends_contact_early(base, healthy):
    """Above the cut (roll u_c = sqrt((r_a - dh)^2/r_b^2 - 1)) the broken tooth's pair carries
    nothing; below it the mesh is the healthy one."""
    pair = base.gear_pair()
    g = pair.pinion
    rb1, z1, dh, T = g.base_radius, g.teeth, 2e-3, 11
    uc = math.sqrt(((g.tip_radius - dh) / rb1) ** 2 - 1)
    tm = 2 * math.pi / z1
    th = np.linspace(T * tm - 2 * tm, T * tm + 2 * tm, 3001)
    r = healthy.evaluate(th)
    k = faulty(base, {"type": "breakage", "tooth": T, "height": "2 mm"}).mesh_stiffness(th)
    slot = np.mod(r["pair"], z1) == T
    u = np.max(np.where(slot & np.isfinite(r["pinion_roll"]), r["pinion_roll"], -1.0), axis=1)
    above = u > uc + 1e-9
    below = ~above
    k_pair = np.sum(np.where(slot, r["load_share"], 0.0), axis=1) * r["k_mb"]
    assert np.any(above) and np.any(below)
    np.testing.assert_allclose(k[above], r["k_mb"][above] - k_pair[above], rtol=1e-12)
    np.testing.assert_array_equal(k[below], r["k_mb"][below])


def test_worn_section_against_quad(base):
    """The thinner section of a worn tooth: Gauss tables against adaptive scipy quad of the same
    beam integrals (tooth_compliance_quad reads the section's width)."""
    c = base.with_overrides({"faults": [{"type": "wear", "tooth": 2, "depth": "80 um",
                                         "stiffness": True, "start": "15 mm",
                                         "length": "10 mm"}]})
    w = faults_from_case(c)[0]
    g = c.gear_pair().pinion
    sec = WornSection(g, w)
    E, nu, L = c.material.youngs_modulus, c.material.poisson_ratio, c.pair.face_width
    for u in (0.2, 0.3, 0.45, 0.55):
        got = float(tooth_compliance(sec, u, E, nu, L)[0])
        ref = tooth_compliance_quad(sec, u, E, nu, L)
        assert got == pytest.approx(ref, rel=1e-9)


def test_wear_gap_is_recorded(base, theta):
    m = faulty(base, {"type": "wear", "tooth": 11, "depth": "30 um"})
    r = m.evaluate(theta)
    z1 = base.pinion.teeth
    on = (np.mod(r["pair"], z1) == 11) & np.isfinite(r["pinion_roll"])
    assert np.any(on)
    np.testing.assert_allclose(r["fault_gap"][on], 30e-6, rtol=1e-15)
    assert np.all(r["fault_gap"][~on] == 0)


@pytest.mark.parametrize("entry, field, text", [
    ({**SPALL, "start": "5 mm"}, "faults[0].start", "active profile"),
    ({**SPALL, "start": "36 mm"}, "faults[0].start", "active profile"),
    ({"type": "root_crack", "tooth": 1, "depth": "30 mm"}, "faults[0].depth", "inside"),
    ({**SPALL, "tooth": 23}, "faults[0].tooth", "[0, 22]"),
    ({**SPALL, "width": "25 mm"}, "faults[0].width", "face width"),
    ({**SPALL, "height": "1 mm"}, "faults[0].height", "spall"),
    ({"type": "breakage", "tooth": 0, "height": "20 mm"}, "faults[0].height", "tooth height"),
    ({**SPALL, "length": "-1 mm"}, "faults[0].length", ">= 0"),
    ({"type": "spall", "tooth": 0, "width": "1 mm", "depth": "1 mm"}, "faults[0].start",
     "position"),
])
def test_bad_input(base, entry, field, text):
    with pytest.raises(InputError) as exc:
        base.with_overrides({"faults": [entry]})
    assert exc.value.field == field
    assert text in exc.value.allowed


def test_overlapping_faults_refused(base):
    other = {**SPALL, "start": "22 mm"}
    with pytest.raises(InputError, match=r"faults\[1\]\.type.*overlap faults\[0\]"):
        base.with_overrides({"faults": [SPALL, other]})
    # the [crack] section and a root_crack on the same tooth
    crack = {"type": "root_crack", "tooth": base.crack.tooth, "depth": "1 mm"}
    with pytest.raises(InputError, match=r"not a second root crack on pinion tooth 11: the "
                                         r"\[crack\] section already cracks it"):
        base.with_overrides({"crack.enabled": True, "faults": [crack]})
    with pytest.raises(InputError, match=r"faults\[1\]\.type.*not a second root crack on "
                                         r"pinion tooth 11: faults\[0\] is one there"):
        base.with_overrides({"faults": [crack, {**crack, "depth": "2 mm"}]})
    # a spall on the part a breakage removed
    brk = {"type": "breakage", "tooth": 11, "height": "3 mm"}
    with pytest.raises(InputError, match="broken tip"):
        base.with_overrides({"faults": [brk, {**SPALL, "start": "33 mm"}]})
    # the same spall on another tooth is fine
    base.with_overrides({"faults": [SPALL, {**other, "tooth": 12}]})


def test_fe_refuses_what_it_does_not_model(base):
    """The FE models every fault type (tests/fe/test_fe_faults.py) but not the thinner worn
    tooth: refused before any body is built, naming the field."""
    c = base.with_overrides({"faults": [{"type": "wear", "tooth": 11, "depth": "30 um",
                                         "stiffness": True}]})
    with pytest.raises(InputError, match="FE method") as exc:
        build_map(c, method="fe")
    assert exc.value.field == "faults[0].stiffness"


def test_cache_identity_and_case_text(base, tmp_path):
    """A case without faults keeps its map key; with faults the key holds them, and the case
    text (case_to_toml) loads back to the same faults."""
    assert "faults" not in map_inputs(base, "pem", True)
    assert "faults" not in case_to_toml(base)
    c = base.with_overrides({"faults": [SPALL, {"type": "breakage", "gear": "gear",
                                                "tooth": 4, "height": "1 mm"}]})
    assert map_inputs(c, "pem", True)["faults"][1]["height"] == pytest.approx(1e-3)
    assert "faults" not in map_inputs(c, "pem", False)  # the healthy map is shared
    p = tmp_path / "c.toml"
    p.write_text(case_to_toml(c))
    assert load_case(p).faults == c.faults
    # --set reaches an entry of the list
    c2 = load_case(p, ["faults.0.width=2 mm"])
    assert c2.faults[0].width == pytest.approx(2e-3)
