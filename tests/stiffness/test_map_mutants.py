"""StiffnessMap (stiffness/map.py) at its edges: user tables refused in full, zone boundaries
against their closed form, range tests at the tolerance, the period wrap, the regular resampling.

Written against the mutants that survived the first mutation run of ``stiffness/map.py``
(docs/mutation.md, issue 20 item 6; run with the numba decorators removed and
``NUMBA_DISABLE_JIT=1`` so that :func:`lookup` is mutated too). Oracles: the zone lengths
``(ceil(eps) - eps) Theta_m`` and exit phases ``(s_end - s_pitch) / r_b1 mod Theta_m`` of the
module docstring; analytic stiffness functions tabulated by :meth:`StiffnessMap.from_function`
(the map must return them at its nodes); the compiled :func:`lookup` against its independent
NumPy twin :func:`lookup_reference` at the exact edge cases.
"""

from __future__ import annotations

import math

import numpy as np
import pytest

from geardyn import paper_case
from geardyn.errors import InputError
from geardyn.stiffness.map import StiffnessMap, lookup, lookup_reference, zone_boundaries

Z1 = 23


@pytest.fixture(scope="module")
def pair():
    return paper_case().gear_pair()


def _k(th, d):
    """An analytic stiffness [N/m] smooth in theta and linear in d."""
    return 1e8 * (1 + 0.1 * np.cos(Z1 * np.asarray(th))) * (1 + 100.0 * d)


@pytest.fixture(scope="module")
def line1(pair):
    return StiffnessMap.from_function(pair, [0.0], lambda th, d: {"k_mb": _k(th, d)}, n_seg=8)


@pytest.fixture(scope="module")
def lines3(pair):
    return StiffnessMap.from_function(pair, [0.0, 5e-4, 1e-3],
                                      lambda th, d: {"k_mb": _k(th, d)}, n_seg=8)


def _refusal(exc) -> tuple:
    return exc.value.field, exc.value.value, exc.value.allowed


# ------------------------------------------------------------------ zone boundaries
def test_zone_boundaries_closed_form_also_beyond_contact_ratio_one(pair):
    """a = (s_end - s_pitch)/r_b1 mod Theta_m (independent of d); zone A length
    (ceil(eps) - eps) Theta_m, also where eps < 1 (the function does not refuse it)."""
    tm = 2 * math.pi / Z1
    rb1, pb = pair.pinion.base_radius, pair.base_pitch
    dmax = pair.max_centre_distance_change()
    dd = np.array([-5e-4, 0.0, 1e-3, dmax + 2e-4])
    pa, la = zone_boundaries(pair, dd)
    rsum = pair.pinion.base_radius + pair.gear.base_radius
    for i, d in enumerate(dd):
        t1t2 = math.sqrt((pair.design_centre_distance + d) ** 2 - rsum ** 2)
        s_end = math.sqrt(pair.pinion.tip_radius ** 2 - rb1 ** 2)
        s_start = t1t2 - math.sqrt(pair.gear.tip_radius ** 2 - pair.gear.base_radius ** 2)
        eps = (s_end - s_start) / pb
        assert pa[i] == pytest.approx(math.fmod(s_end - pair.pitch_point_s, pb) / rb1 % tm,
                                      abs=1e-13)
        assert 0 <= pa[i] < tm
        assert la[i] == pytest.approx((math.ceil(eps) - eps) * tm, abs=1e-12)
    assert pair.operating(dd[-1], check=False).contact_ratio < 1
    assert np.ptp(pa) < 1e-15


# ------------------------------------------------------------------ user tables
def test_table_refusals_in_full(pair):
    tm = pair.mesh_angle
    th = np.arange(10) * tm / 10
    k = _k(th, 0.0)
    cases = [
        (dict(theta=th[:3], k_mb=k[:3]),
         ("theta", (3,), "an increasing 1-D array of >= 4 angles [rad]")),
        (dict(theta=th[::-1], k_mb=k),
         ("theta", (10,), "an increasing 1-D array of >= 4 angles [rad]")),
        (dict(theta=np.r_[th[:5], th[4], th[6:]], k_mb=k),
         ("theta", (10,), "an increasing 1-D array of >= 4 angles [rad]")),
        (dict(theta=th[None, :], k_mb=k),
         ("theta", (1, 10), "an increasing 1-D array of >= 4 angles [rad]")),
        (dict(theta=th, k_mb=k[:9]), ("k_mb", (1, 9), "last axis of length 10 (as theta)")),
        (dict(theta=th, k_mb=np.stack([k, k])),
         ("dd", None, "2 centre distance changes for the rows")),
        (dict(theta=th, k_mb=np.stack([k, k]), dd=[0.0, 1e-3, 2e-3]),
         ("dd", 3, "one centre distance change per row (2)")),
    ]
    whole = f"a whole number of mesh cycles ({tm:.6g} rad each) on a regular grid"
    for n in (15, 4):                      # 1.5 and 0.4 mesh cycles
        t = np.arange(n) * tm / 10
        span = t[-1] - t[0] + (t[1] - t[0])
        assert span == pytest.approx(n * tm / 10, rel=1e-14)
        cases.append((dict(theta=t, k_mb=_k(t, 0.0)), ("theta", f"span {span:.6g} rad", whole)))
    for kwargs, expected in cases:
        with pytest.raises(InputError) as exc:
            StiffnessMap.from_table(pair, **kwargs)
        assert _refusal(exc) == expected
    # four angles over one whole cycle are enough
    assert StiffnessMap.from_table(pair, np.arange(4) * tm / 4, k[:4]).n_seg == 64


def test_table_defaults_and_an_offset_grid(pair):
    """One row: centre distance change 0, 64 nodes per zone, one pinion revolution; a grid that
    starts at 0.3 rad covers one mesh cycle all the same (span = n dtheta)."""
    tm = pair.mesh_angle
    th = 0.3 + np.arange(40) * tm / 40
    m = StiffnessMap.from_table(pair, th, _k(th, 0.0))
    assert m.dd.tolist() == [0.0] and m.n_seg == 64 and m.n_cycles == Z1
    assert m.attrs["method"] == "table"
    nodes = m.node_theta()[0]
    expect = np.interp(nodes, th, _k(th, 0.0), period=40 * (tm / 40))
    np.testing.assert_allclose(m.k_mb[0], expect, rtol=1e-14)


# ------------------------------------------------------------------ range and defaults
def test_covers_at_the_tolerance(line1, lines3):
    for d in (-1.0, 0.0, 7.0):
        assert line1.covers(d)
    lo, hi = lines3.dd[0], lines3.dd[-1]
    assert lines3.covers(lo - 1e-12) and lines3.covers(hi + 1e-12)
    assert lines3.covers(lo) and lines3.covers(hi) and lines3.covers(0.5 * (lo + hi))
    assert not lines3.covers(lo - 3e-12) and not lines3.covers(hi + 3e-12)
    assert not lines3.covers(lo - 0.5) and not lines3.covers(hi + 0.5)


def test_torsional_defaults_to_the_nominal_centre_distance(lines3, pair):
    th = np.linspace(0, 0.5, 7)
    np.testing.assert_allclose(lines3.torsional(th),
                               lines3(th, 0.0) * pair.pinion.base_radius ** 2, rtol=1e-15)


# ------------------------------------------------------------------ lookup edge cases
def _both(m, th, dd):
    arr = m.arrays()
    fast = np.array([lookup(float(t), float(d), *arr) for t, d in zip(th, dd, strict=True)])
    return fast, lookup_reference(np.asarray(th), np.asarray(dd), arr)


def test_single_grid_line_is_constant_in_d(line1):
    idx = [3, 5, 17, 42]                   # interior nodes (end nodes are nudged into the zone)
    th = line1.node_theta()[0][idx]
    for d in (0.0, -3e-3, 2e-3):
        fast, ref = _both(line1, th, [d] * th.size)
        np.testing.assert_allclose(ref, line1.k_mb[0][idx], rtol=1e-14)
        np.testing.assert_allclose(fast, ref, rtol=1e-15)


def test_interpolation_in_d_and_its_end_clamp(lines3):
    """Linear in d between grid lines (the analytic k is linear in d, so exact); beyond the
    last line by less than 1e-9 of the spacing the last line is returned, not extrapolated."""
    th = lines3.node_theta()[0][[3, 30, 201]]
    for d in (2.5e-4, 7.5e-4):
        fast, ref = _both(lines3, th, [d] * 3)
        np.testing.assert_allclose(ref, fast, rtol=1e-14)
    hi = lines3.dd[-1]
    d_over = hi + 0.5e-9 * (lines3.dd[1] - lines3.dd[0])
    th_last = lines3.node_theta()[-1][[3, 30, 201]]
    fast, ref = _both(lines3, th_last, [d_over] * 3)
    np.testing.assert_allclose(ref, lines3.k_mb[-1][[3, 30, 201]], rtol=1e-15)
    np.testing.assert_allclose(fast, ref, rtol=1e-15)


def test_angle_just_below_the_period_start_wraps_to_the_end(line1):
    """theta one ulp below the exit phase: (theta - a) mod period rounds to the period itself;
    both implementations return the last node of the revolution (= the first by periodicity)."""
    a = float(line1.phase_a[0])
    th = math.nextafter(a, -math.inf)
    assert np.mod(th - a, line1.period) == line1.period
    fast, ref = _both(line1, [th], [0.0])
    assert ref[0] == pytest.approx(line1.k_mb[0][-1], rel=1e-15)
    assert fast[0] == pytest.approx(ref[0], rel=1e-15)


def test_exact_zone_boundary_belongs_to_zone_b(pair):
    """At r == length_a exactly the angle is the first node of zone B (the entry handover),
    in both implementations: a map whose zones hold different constants shows it."""
    pa, la = zone_boundaries(pair, [0.0])

    def fn(th, d):
        r = np.mod(th - pa[0], pair.mesh_angle)
        return {"k_mb": np.where(r < la[0], 1e8, 2e8)}

    m = StiffnessMap.from_function(pair, [0.0], fn, n_seg=4)
    a, length = float(m.phase_a[0]), float(m.length_a[0])
    th = a + length
    for _ in range(100):
        r = float(np.mod(th - a, m.period))
        if r == length:
            break
        th = math.nextafter(th, math.inf if r < length else -math.inf)
    if float(np.mod(th - a, m.period)) != length:  # numpy 1.26's mod: no exact tie near here
        pytest.skip("no pinion angle with r == length_a exactly on this numpy build")
    fast, ref = _both(m, [th], [0.0])
    assert fast[0] == ref[0] == 2e8


# ------------------------------------------------------------------ regular resampling
def test_regular_resampling(lines3):
    da = lines3.regular()
    assert da.name == "k_mb" and da.dims == ("centre_distance_change", "theta")
    assert da.shape == (3, 360)
    assert da.attrs == {"units": "N/m", "long_name": "mesh stiffness along the LOA"}
    assert da["theta"].attrs == {"units": "rad"}
    assert da["centre_distance_change"].attrs == {"units": "m"}
    th = np.arange(360) * lines3.period / 360
    np.testing.assert_allclose(da["theta"].values, th, rtol=1e-15, atol=0)
    np.testing.assert_array_equal(da["centre_distance_change"].values, lines3.dd)
    np.testing.assert_array_equal(da.values, lines3(da["theta"].values[None, :],
                                                    lines3.dd[:, None]))
    sub = lines3.regular(12, dd=2.5e-4)
    assert sub.shape == (1, 12)
    np.testing.assert_allclose(sub.values[0], lines3(np.arange(12) * lines3.period / 12, 2.5e-4),
                               rtol=1e-14)
    # the analytic k at the nodes: the resampled values follow k(theta, d) to interpolation
    # accuracy (8 nodes per zone)
    np.testing.assert_allclose(da.values, _k(th[None, :], lines3.dd[:, None]), rtol=3e-2)


# ------------------------------------------------------------------ load-share slots
def test_slot_teeth_follow_the_pairs_of_the_pem_model(pair):
    """Slot k of cycle c holds pinion tooth (n_exit + 1 + k) mod z1; the PEM model finds the
    pair numbers independently (floor of the contact position along the LOA) at the middle of
    each cycle."""
    from geardyn.stiffness.map import slot_teeth
    from geardyn.stiffness.pem import PEMModel

    pa, _ = zone_boundaries(pair, [0.0])
    st = slot_teeth(pair, float(pa[0]), Z1)
    assert st.shape == (Z1, 3) and st.dtype == np.int64
    pm = PEMModel(pair, 2e11, 0.3)
    mid = pa[0] + (np.arange(Z1) + 0.5) * pair.mesh_angle
    np.testing.assert_array_equal(st, np.mod(pm.evaluate(mid)["pair"], Z1))
    assert st[0].tolist() == [(st[0, 0] + k) % Z1 for k in range(3)]


# ------------------------------------------------------------------ construction and storage
def test_from_function_arguments_and_refusal(pair):
    calls = []
    m = StiffnessMap.from_function(
        pair, [0, 1], lambda th, d: {"k_mb": np.full(th.size, 7), "pairs_in_contact": [2] * th.size},
        n_cycles=2 * Z1, progress=lambda done, total: calls.append((done, total)))
    assert calls == [(1, 2), (2, 2)]
    assert m.n_seg == 24 and m.n_cycles == 2 * Z1 and m.k_mb.shape == (2, 2 * Z1 * 2 * 24)
    assert m.dd.dtype == np.float64 and m.k_mb.dtype == np.float64
    assert m.extra["pairs_in_contact"].dtype == np.float64
    with pytest.raises(InputError) as exc:
        StiffnessMap.from_function(pair, [0.0], lambda th, d: {"load_share": np.zeros((th.size, 3)),
                                                                "pairs_in_contact": th * 0})
    assert _refusal(exc) == ("fn", ["load_share", "pairs_in_contact"],
                             "a function returning at least 'k_mb'")


def test_dataset_variables_dims_and_units(lines3):
    ds = lines3.to_dataset()
    rb = lines3.base_radius
    expected = {
        "k_mb": (("centre_distance_change", "node"),
                 {"units": "N/m", "long_name": "mesh stiffness along the line of action"}),
        "torsional_stiffness": (("centre_distance_change", "node"),
                                {"units": "N m/rad",
                                 "long_name": "combined torsional mesh stiffness K_t = k_mb r_b1^2"}),
        "phase_a": (("centre_distance_change",),
                    {"units": "rad", "long_name": "pinion angle of the exit handover"}),
        "length_a": (("centre_distance_change",),
                     {"units": "rad", "long_name": "length of contact zone A"}),
    }
    for name, (dims, attrs) in expected.items():
        assert ds[name].dims == dims and ds[name].attrs == attrs, name
    np.testing.assert_array_equal(ds["torsional_stiffness"].values, lines3.k_mb * rb ** 2)
    np.testing.assert_array_equal(ds["k_mb"].values, lines3.k_mb)
    assert ds["centre_distance_change"].attrs == {"units": "m", "long_name": "d' - d"}
    assert ds["theta"].dims == ("centre_distance_change", "node")
    assert ds["theta"].attrs == {"units": "rad", "long_name": "pinion angle of the node"}
    np.testing.assert_array_equal(ds["theta"].values, lines3.node_theta())
    assert ds.attrs["mesh_angle_units"] == "rad" and ds.attrs["base_radius_units"] == "m"
    assert ds.attrs["geardyn_object"] == "StiffnessMap" and ds.attrs["n_seg"] == 8
    back = StiffnessMap.from_dataset(ds)
    np.testing.assert_array_equal(back.k_mb, lines3.k_mb)
    assert back.base_radius == rb and back.n_cycles == Z1


def test_regular_keeps_float_coordinates(lines3):
    sub = lines3.regular(6, dd=0)
    assert sub["centre_distance_change"].dtype == np.float64
    assert sub["centre_distance_change"].values.tolist() == [0.0]


def test_just_below_the_first_grid_line_reads_the_first_line(lines3):
    """Up to 1e-9 of the spacing below the first grid line the first line is returned."""
    d = lines3.dd[0] - 0.5e-9 * (lines3.dd[1] - lines3.dd[0])
    idx = [3, 30, 201]
    th = lines3.node_theta()[0][idx]
    fast, ref = _both(lines3, th, [d] * 3)
    np.testing.assert_allclose(ref, lines3.k_mb[0][idx], rtol=1e-15)
    np.testing.assert_allclose(fast, ref, rtol=1e-15)
    far = lines3.dd[0] - 2e-9 * (lines3.dd[1] - lines3.dd[0])
    assert np.all(np.isnan(_both(lines3, th, [far] * 3)[0]))


def test_phase_interpolated_between_grid_lines(pair):
    """A hand-made map whose exit phase differs between its two grid lines (geardyn's own maps
    have one phase): both implementations interpolate the phase linearly in d."""
    tm = pair.mesh_angle
    n_seg, nc = 6, 2
    vals = np.linspace(1e8, 2e8, 2 * nc * 2 * n_seg).reshape(2, -1)
    m = StiffnessMap(dd=np.array([0.0, 1e-3]), phase_a=np.array([0.05, 0.09]),
                     length_a=np.array([0.4 * tm, 0.4 * tm]), mesh_angle=tm, n_cycles=nc,
                     n_seg=n_seg, k_mb=vals, base_radius=0.06)
    th = np.linspace(0.0, 2 * tm, 37)
    fast, ref = _both(m, th, [4e-4] * th.size)
    np.testing.assert_allclose(fast, ref, rtol=1e-13)
    shifted = StiffnessMap(dd=np.array([0.0]), phase_a=np.array([0.066]),
                           length_a=np.array([0.4 * tm]), mesh_angle=tm, n_cycles=nc,
                           n_seg=n_seg, k_mb=vals[:1], base_radius=0.06)
    # at d = 4e-4 the phase is 0.066 rad: line 0 read with that phase (weight 0.6)
    part0 = _both(shifted, th, [0.0] * th.size)[1]
    assert not np.allclose(part0, _both(m, th, [0.0] * th.size)[1], rtol=1e-6)


def test_wrap_at_the_period_end_on_a_revolution_periodic_map(pair):
    """Cycles differ (k varies once per revolution): one ulp below the exit phase the last
    node of the last cycle is returned, not a node of another cycle."""
    m = StiffnessMap.from_function(
        pair, [0.0], lambda th, d: {"k_mb": 1e8 * (1 + 0.1 * np.cos(np.asarray(th)))}, n_seg=8)
    a = float(m.phase_a[0])
    th = math.nextafter(a, -math.inf)
    fast, ref = _both(m, [th], [0.0])
    assert ref[0] == pytest.approx(m.k_mb[0][-1], rel=1e-15)
    assert abs(m.k_mb[0][-1] / m.k_mb[0][-1 - 2 * 8] - 1) > 1e-4     # the cycles differ
    assert fast[0] == pytest.approx(ref[0], rel=1e-15)


def test_map_refusals_in_full(lines3):
    base = dict(phase_a=lines3.phase_a, length_a=lines3.length_a, mesh_angle=lines3.mesh_angle,
                n_cycles=Z1, n_seg=8, base_radius=0.06)
    k = lines3.k_mb
    bad = [
        (dict(dd=np.zeros((3, 1)), k_mb=k), "dd", "a 1-D array of centre distance changes [m]"),
        (dict(dd=np.array([]), k_mb=k), "dd", "a 1-D array of centre distance changes [m]"),
        (dict(dd=np.array([0.0, 1e-3, 1e-3]), k_mb=k), "dd", "uniformly spaced, increasing values"),
        (dict(dd=np.array([0.0, 1e-3, 2.1e-3]), k_mb=k), "dd",
         "uniformly spaced, increasing values"),
        (dict(dd=np.array([1e-3, 0.0, -1e-3]), k_mb=k), "dd",
         "uniformly spaced, increasing values"),
        (dict(dd=np.array([0.0, 1e-3, 2e-3]), k_mb=k[:, :-1]), "k_mb", f"shape (3, {Z1 * 16})"),
        (dict(dd=np.array([0.0, 1e-3, 2e-3]), k_mb=np.where(k > 0, -k, k)), "k_mb",
         "finite values >= 0 [N/m]"),
        (dict(dd=np.array([0.0, 1e-3, 2e-3]), k_mb=k * np.nan), "k_mb",
         "finite values >= 0 [N/m]"),
    ]
    for kwargs, field, allowed in bad:
        with pytest.raises(InputError) as exc:
            StiffnessMap(**kwargs, **base)
        assert (exc.value.field, exc.value.allowed) == (field, allowed)
        if field == "k_mb" and "shape" in allowed:
            assert exc.value.value == (3, Z1 * 16 - 1)
        elif field == "k_mb":
            assert exc.value.value == "non-finite or negative entries"
        else:
            assert exc.value.value is kwargs["dd"]
    # accepted: two lines, a zero stiffness (separated teeth), a spacing uniform to 1e-12
    ok = StiffnessMap(dd=np.array([0.0, 1e-3, 2e-3 + 1e-13]), k_mb=k * 0, **base)
    assert ok.k_mb.max() == 0.0
    two = StiffnessMap(dd=np.array([0.0, 1e-3]), k_mb=k[:2], **{**base})
    assert two.dd.size == 2


def test_node_angles_closed_form():
    """Nodes at phase + c Theta_m + f L (zone A) and + L_A + f L_B (zone B), f = j/(n-1);
    end nodes moved 1e-9 Theta_m into their zone (or a quarter node spacing if smaller)."""
    tm, a, la, nc, ns = 0.3, 0.05, 0.12, 2, 5
    th = StiffnessMap.node_angles(a, la, tm, nc, ns).reshape(nc, 2, ns)
    f = np.arange(ns) / (ns - 1)
    nudge = 1e-9 * tm
    for c in range(nc):
        za = a + c * tm + f * la
        zb = a + c * tm + la + f * (tm - la)
        za[0] += nudge
        za[-1] -= nudge
        zb[0] += nudge
        zb[-1] -= nudge
        np.testing.assert_allclose(th[c, 0], za, rtol=0, atol=1e-15)
        np.testing.assert_allclose(th[c, 1], zb, rtol=0, atol=1e-15)
    # a tiny zone: the nudge is limited to a quarter of the node spacing
    small = StiffnessMap.node_angles(a, 4e-9, tm, 1, ns).reshape(2, ns)
    q = 0.25 * 4e-9 / (ns - 1)
    np.testing.assert_allclose(small[0, [0, -1]], [a + q, a + 4e-9 - q], rtol=0, atol=1e-18)
    # one node per zone: no nudge
    np.testing.assert_array_equal(StiffnessMap.node_angles(a, la, tm, 1, 1), [a, a + la])
    nine = StiffnessMap.node_angles(a, la, tm, 1, 2).reshape(2, 2)
    np.testing.assert_allclose(nine[0], [a + nudge, a + la - nudge], rtol=0, atol=1e-15)
