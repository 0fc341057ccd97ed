"""Body meshes: the real tooth shape, and the crack as a true discontinuity with free faces.

Oracles: the involute's polar equation (flank nodes), the fillet trochoid of geometry.py, the PEM
module's independent construction of the same crack, the topology of a slit (each face a
boundary facet, the tip shared), and LEFM (the crack opens under the loaded-flank load, with an
opening growing like the square root of the distance from the tip).
"""

from __future__ import annotations

import math

import numpy as np
import pytest

from geardyn.errors import InputError
from geardyn.stiffness.fe.mesh import (
    CrackGeometry,
    MeshSettings,
    build_body_mesh,
    crack_segment,
    critical_fillet_point,
)
from geardyn.stiffness.fe.solve import ElasticBody, ElasticMaterial, flank_points

COARSE_MESH = MeshSettings(flank_size=0.1e-3, tooth_size=1e-3, body_size=3e-3, refined_teeth=3)
CRACK = CrackGeometry(depth=5e-3, angle=math.radians(45))


@pytest.fixture(scope="module")
def gear(paper_case):
    return paper_case.gear_pair().pinion


@pytest.fixture(scope="module")
def healthy(gear):
    return build_body_mesh(gear, COARSE_MESH)


@pytest.fixture(scope="module")
def cracked(gear):
    return build_body_mesh(gear, COARSE_MESH, CRACK)


def test_gmsh_finalized(healthy):
    import gmsh

    assert not gmsh.isInitialized()


def test_flank_nodes_on_the_involute(healthy, gear):
    """Every node of the loaded flanks lies on the involute (within 10 nm), from the form circle
    to the tip, for all refined teeth."""
    rb = gear.base_radius
    for j in healthy.offsets:
        nodes = np.unique(healthy.edges[f"flank{j}"])
        x = healthy.p[:, nodes]
        r = np.hypot(*x)
        u = np.sqrt(r * r - rb * rb)
        xi, _ = flank_points(gear, j, u)
        assert np.max(np.hypot(*(xi - x))) < 1e-8  # m: splines through 150 points
        assert r.min() == pytest.approx(gear.form_radius, rel=1e-9)
        assert r.max() == pytest.approx(gear.tip_radius, rel=1e-9)


def test_whole_gear_to_the_bore(healthy, gear):
    r = np.hypot(*healthy.p)
    assert r.min() == pytest.approx(gear.bore_radius, rel=1e-9)
    assert r.max() == pytest.approx(gear.tip_radius, rel=1e-9)
    # every tooth is there: the outline's polar angles cover the circle at the tip radius
    tips = healthy.p[:, np.isclose(r, gear.tip_radius, rtol=1e-7)]
    ang = np.sort(np.mod(np.arctan2(tips[1], tips[0]), 2 * math.pi))
    assert np.max(np.diff(ang)) < 2 * math.pi / gear.teeth
    # bore nodes
    assert healthy.edges["bore"].shape[1] > 20
    # mesh quality: smallest angle of any triangle
    p, t = healthy.p, healthy.t
    ang_min = math.pi
    for a in range(3):
        v1 = p[:, t[(a + 1) % 3]] - p[:, t[a]]
        v2 = p[:, t[(a + 2) % 3]] - p[:, t[a]]
        cosang = np.sum(v1 * v2, axis=0) / np.hypot(*v1) / np.hypot(*v2)
        ang_min = min(ang_min, float(np.min(np.arccos(np.clip(cosang, -1, 1)))))
    assert math.degrees(ang_min) > 15


def test_flank_refinement(healthy, gear):
    seg = healthy.edges["flank0"]
    length = np.hypot(*(healthy.p[:, seg[1]] - healthy.p[:, seg[0]]))
    assert np.max(length) < 1.3 * COARSE_MESH.flank_size


def test_crack_same_as_pem(gear):
    """The FE crack (loaded side mirrored to x < 0) is the PEM's crack (independent code)."""
    from geardyn.stiffness.pem import ToothCrack, crack_geometry

    mouth, tip = crack_segment(gear, CRACK)
    pem = crack_geometry(gear, ToothCrack(gear="pinion", tooth=0, depth=5e-3,
                                          angle=math.radians(45), limit_line="tip"))
    assert np.allclose(mouth * [-1, 1], pem.mouth, atol=1e-8)
    assert np.allclose(tip * [-1, 1], pem.tip, atol=1e-8)
    assert np.hypot(*(tip - mouth)) == pytest.approx(5e-3, rel=1e-12)
    # 30 deg tangent (ISO 6336-3) at the mouth
    m = critical_fillet_point(gear)
    fil = gear.outline(4, 4001).fillet * [-1, 1]
    k = int(np.argmin(np.hypot(*(fil - m).T)))
    d = fil[k + 1] - fil[k - 1]
    assert math.degrees(math.atan2(abs(d[0]), abs(d[1]))) == pytest.approx(30, abs=0.05)


def test_crack_is_a_slit(cracked, healthy):
    plus, minus = cracked.edges["crack+"], cracked.edges["crack-"]
    n_seg = plus.shape[1]
    assert n_seg >= 10
    crack_nodes = np.unique(plus)
    dup = np.unique(minus[minus != plus])
    # every crack node but the tip is duplicated, at the same place
    assert dup.size == crack_nodes.size - 1
    tip_node = np.intersect1d(np.unique(plus), np.unique(minus))
    assert tip_node.size == 1
    assert np.allclose(cracked.p[:, tip_node[0]], cracked.crack_tip, atol=1e-12)
    for a, b in zip(plus.ravel(), minus.ravel(), strict=True):
        assert np.allclose(cracked.p[:, a], cracked.p[:, b])
    # topology: each face segment belongs to exactly one triangle (a boundary facet)
    from skfem import MeshTri

    m = MeshTri(np.ascontiguousarray(cracked.p), np.ascontiguousarray(cracked.t))
    bf = m.facets[:, m.boundary_facets()]
    bset = {tuple(sorted(e)) for e in bf.T}
    for seg in (plus, minus):
        for e in seg.T:
            assert tuple(sorted(e)) in bset
    # 2 x n_seg more boundary facets than the uncracked mesh of the same gear (whose crack line
    # would be interior) up to the mesh differences around the crack: count directly
    mh = MeshTri(np.ascontiguousarray(healthy.p), np.ascontiguousarray(healthy.t))
    assert m.boundary_facets().size > mh.boundary_facets().size + 2 * n_seg - 10
    # the mouth is on the outer outline (the fillet), the tip inside
    r = np.hypot(*cracked.crack_mouth)
    assert cracked.edges["fillet0"].size > 0
    fil_nodes = np.unique(cracked.edges["fillet0"])
    assert np.min(np.hypot(*(cracked.p[:, fil_nodes] - cracked.crack_mouth[:, None]))) < 1e-12
    assert gear_inside(cracked, cracked.crack_tip) and r > np.hypot(*cracked.crack_tip)


def gear_inside(bm, pt) -> bool:
    from geardyn.stiffness.fe.mesh import _closed_polygon, _inside

    return bool(_inside(_closed_polygon(bm.gear), pt[None, :])[0])


def test_crack_opens_like_lefm(cracked, gear):
    """A load on the cracked tooth's flank opens the crack (faces free, no interpenetration);
    the opening near the tip grows like r^0.5 (LEFM)."""
    body = ElasticBody(cracked, ElasticMaterial(69e9, 0.33))
    u_pitch = math.sqrt(gear.pitch_radius ** 2 - gear.base_radius ** 2)
    X = body.solve(body.patch_loads(0, np.array([u_pitch]), 0.24e-3)[:, 0])
    plus, minus = cracked.edges["crack+"], cracked.edges["crack-"]
    d = cracked.crack_tip - cracked.crack_mouth
    length = np.hypot(*d)
    d /= length
    nrm = np.array([-d[1], d[0]])
    nd = body.basis.nodal_dofs
    r, cod = [], []
    for a, b in {(int(a), int(b)) for a, b in zip(plus.ravel(), minus.ravel(), strict=True)
                 if a != b}:
        r.append(np.hypot(*(cracked.p[:, a] - cracked.crack_tip)))
        cod.append((X[nd[:, a]] - X[nd[:, b]]) @ nrm)
    r, cod = np.array(r), np.array(cod)
    o = np.argsort(r)
    r, cod = r[o], cod[o]
    assert np.all(cod > 0)
    assert np.all(np.diff(cod) > 0)  # widest at the mouth
    sel = (r < 0.4 * length) & (r > 1.5 * r[0])
    slope = np.polyfit(np.log(r[sel]), np.log(cod[sel]), 1)[0]
    assert 0.4 < slope < 0.7


def test_crack_must_stay_in_the_body(gear):
    with pytest.raises(InputError):
        crack_segment(gear, CrackGeometry(depth=40e-3, angle=math.radians(10)))


def test_inside_the_outline_as_matplotlib_says(gear):
    """The crack checks' point-in-polygon test (NumPy, even-odd rule) against matplotlib's
    ``Path.contains_points`` (an independent implementation) on the whole gear's outline:
    2000 random points over the gear's box, the polygon's own square, a ring and a triangle,
    leaving out points within 1 um of an edge, where the rules may differ."""
    from matplotlib.path import Path

    from geardyn.stiffness.fe.mesh import _closed_polygon, _inside

    def near_an_edge(poly, pts, tol):
        a, b = poly, np.roll(poly, -1, axis=0)
        d = b - a
        t = np.clip(np.einsum("kij,ij->ki", pts[:, None, :] - a[None], d)
                    / np.einsum("ij,ij->i", d, d), 0.0, 1.0)
        gap = pts[:, None, :] - (a[None] + t[..., None] * d[None])
        return np.hypot(gap[..., 0], gap[..., 1]).min(axis=1) < tol

    rng = np.random.default_rng(7)
    poly = _closed_polygon(gear)
    r = 1.05 * gear.tip_radius
    pts = rng.uniform(-r, r, (2000, 2))
    keep = ~near_an_edge(poly, pts, 1e-6)
    ours, theirs = _inside(poly, pts[keep]), Path(poly).contains_points(pts[keep])
    np.testing.assert_array_equal(ours, theirs)
    assert 300 < ours.sum() < keep.sum() - 300  # points on both sides
    square = np.array([[0.0, 0.0], [1.0, 0.0], [1.0, 1.0], [0.0, 1.0]])
    # a ray through a vertex (y = 1 at the corner (1, 1)) and along an edge's height
    np.testing.assert_array_equal(
        _inside(square, np.array([[0.5, 0.5], [1.5, 0.5], [-0.5, 1.0], [0.5, 0.999], [0.5, 2.0]])),
        [True, False, False, True, False])
    triangle = np.array([[0.0, 0.0], [2.0, 0.0], [1.0, 2.0]])
    np.testing.assert_array_equal(_inside(triangle, np.array([[1.0, 1.0], [1.0, 2.5], [-1.0, 0.0]])),
                                  [True, False, False])


def test_bad_settings():
    with pytest.raises(InputError):
        MeshSettings(flank_size=1e-3, tooth_size=0.5e-3, body_size=2e-3)
    with pytest.raises(InputError):
        MeshSettings(flank_size=-1.0, tooth_size=0.5e-3, body_size=2e-3)
    with pytest.raises(InputError):
        CrackGeometry(depth=1e-3, angle=2.0)


def test_the_last_body_meshes_are_kept_for_the_figure():
    """``build_body_mesh`` returns the mesh it just built for the same arguments (the figure of
    the mesh reuses its body's mesh), read-only; other arguments mesh again."""
    import geardyn
    from geardyn.stiffness.fe.mesh import MeshSettings, build_body_mesh

    g = geardyn.paper_case().gear_pair().pinion
    ms = MeshSettings(flank_size=0.2e-3, tooth_size=1.6e-3, body_size=4.8e-3, refined_teeth=3)
    a = build_body_mesh(g, ms)
    assert build_body_mesh(g, ms) is a
    assert not a.p.flags.writeable and not a.t.flags.writeable
    coarser = MeshSettings(flank_size=0.25e-3, tooth_size=2.0e-3, body_size=6e-3,
                           refined_teeth=3)
    b = build_body_mesh(g, coarser)
    assert b is not a and b.n_nodes < a.n_nodes
