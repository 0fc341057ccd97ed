"""Contact kinematics, the compatibility solver, and the independent two-body check.

Oracles:
* unloaded gaps beyond the path of contact against a brute-force distance between the tip corner
  and the mating flank, both teeth placed by their angular positions (independent of the
  involute-coordinate formulas of contact.py);
* the active-set solution of the compatibility problem against a general-purpose constrained
  optimiser (SLSQP) and its KKT conditions;
* load sharing and hub rotation of the influence-coefficient route against a direct two-body
  contact solve of the FE meshes (node-to-segment, Lagrange multipliers, no assumed pressure
  distribution and no analytical local term), at four positions, healthy and cracked.
"""

from __future__ import annotations

import math

import numpy as np
import pytest
from scipy.optimize import minimize, minimize_scalar

from geardyn.stiffness.fe.contact import GEAR_TIP, PATH, PINION_TIP, candidates, solve_compatibility
from geardyn.stiffness.fe.solve import flank_points

from .conftest import coarse_settings


def _placed_flank(gear, rot, centre, u):
    x, _ = flank_points(gear, 0, u)
    c, s = math.cos(rot), math.sin(rot)
    return (np.array([[c, -s], [s, c]]) @ x) + np.asarray(centre)[:, None]


def _brute_gap(pair, theta, dd, which):
    """Distance from the tip corner of pair 0's pinion (or gear) tooth to the mating flank, with
    both bodies rotated into place; positive when separated [m]."""
    p1, p2 = pair.pinion, pair.gear
    rb1, rb2 = p1.base_radius, p2.base_radius
    op = pair.operating(dd, check=False)
    s0 = pair.pitch_point_s + rb1 * theta
    rho1 = s0 / rb1 - math.pi / 2 - p1.base_half_angle
    rho2 = math.pi / 2 + (op.t1t2 - s0) / rb2 - p2.base_half_angle
    o2 = np.array([rb1 + rb2, op.t1t2])
    ua1 = math.sqrt(p1.tip_radius ** 2 - rb1 ** 2)
    ua2 = math.sqrt(p2.tip_radius ** 2 - rb2 ** 2)
    if which == "pinion":
        corner = _placed_flank(p1, rho1, (0, 0), np.array([ua1]))[:, 0]
        gear, rot, centre, ua = p2, rho2, o2, ua2
    else:
        corner = _placed_flank(p2, rho2, o2, np.array([ua2]))[:, 0]
        gear, rot, centre, ua = p1, rho1, (0, 0), ua1

    def dist(u):
        return float(np.hypot(*(_placed_flank(gear, rot, centre, np.array([u]))[:, 0] - corner)))

    res = minimize_scalar(dist, bounds=(1e-4, ua), method="bounded",
                          options={"xatol": 1e-12})
    # sign: the corner is outside the mating tooth if it lies on the far side of the flank
    # from that tooth's material, i.e. against the inward normal
    foot = _placed_flank(gear, rot, centre, np.array([res.x]))[:, 0]
    _, n_in = flank_points(gear, 0, np.array([res.x]))
    c, s = math.cos(rot), math.sin(rot)
    n_in = np.array([[c, -s], [s, c]]) @ n_in[:, 0]
    return math.copysign(res.fun, -float((corner - foot) @ n_in)), res.x


@pytest.mark.parametrize("dd", [0.0, 1.0e-3])
@pytest.mark.parametrize("beyond", [0.2e-3, 1.0e-3, 3.0e-3])
def test_tip_corner_gaps_against_brute_force(paper_case, dd, beyond):
    pair = paper_case.gear_pair()
    rb1 = pair.pinion.base_radius
    op = pair.operating(dd)
    # pair 0 beyond the end of the path: pinion tip corner
    th = (op.s_end + beyond - pair.pitch_point_s) / rb1
    cand = candidates(pair, th, dd)
    k = int(np.nonzero(cand.pair == 0)[0][0])
    assert cand.kind[k] == PINION_TIP
    g, u_foot = _brute_gap(pair, th, dd, "pinion")
    assert g > 0
    assert cand.gap[k] == pytest.approx(g, rel=1e-6, abs=1e-12)
    assert cand.u2[k] == pytest.approx(u_foot, abs=1e-8)
    # pair 0 before the start: gear tip corner
    th = (op.s_start - beyond - pair.pitch_point_s) / rb1
    cand = candidates(pair, th, dd)
    k = int(np.nonzero(cand.pair == 0)[0][0])
    assert cand.kind[k] == GEAR_TIP
    g, u_foot = _brute_gap(pair, th, dd, "gear")
    assert cand.gap[k] == pytest.approx(g, rel=1e-6, abs=1e-12)
    assert cand.u1[k] == pytest.approx(u_foot, abs=1e-8)


def test_gaps_on_the_path_and_growth(paper_case):
    pair = paper_case.gear_pair()
    tm = pair.mesh_angle
    for th in np.linspace(0, tm, 7):
        cand = candidates(pair, th, 0.5e-3)
        on = cand.kind == PATH
        assert np.all(cand.gap[on] == 0) and np.all(cand.gap[~on] > 0)
        assert np.all(cand.arm[on] == pair.pinion.base_radius)
    # the gap grows quadratically with the distance beyond the end of the path
    op = pair.operating(0.0)
    g = []
    for b in (0.1e-3, 0.2e-3):
        th = (op.s_end + b - pair.pitch_point_s) / pair.pinion.base_radius
        c = candidates(pair, th, 0.0)
        g.append(c.gap[c.pair == 0][0])
    assert g[1] / g[0] == pytest.approx(4.0, rel=0.02)


def _slsqp(c, g, a, torque):
    n = g.size
    return minimize(lambda x: 0.5 * x @ c @ x + g @ x, np.full(n, 1.0 / n),
                    jac=lambda x: c @ x + g, bounds=[(0, None)] * n,
                    constraints=[{"type": "eq", "fun": lambda x: a @ x - torque,
                                  "jac": lambda x: a}],
                    method="SLSQP", options={"ftol": 1e-15, "maxiter": 500})


def test_compatibility_solver_against_slsqp():
    rng = np.random.default_rng(7)
    for _ in range(40):
        n = int(rng.integers(2, 6))
        a = rng.normal(size=(n, n))
        c = (a @ a.T + n * np.eye(n)) * 1e-10
        gap = np.where(rng.random(n) < 0.5, 0.0, rng.random(n) * 3e-6)
        arm = 0.065 + 0.002 * rng.random(n)
        torque = 5000.0
        res = solve_compatibility(c, gap, arm, torque)
        f = res.force
        # KKT: forces >= 0, torque balance, separations >= 0, complementarity
        assert np.all(f >= 0)
        assert arm @ f == pytest.approx(torque, rel=1e-10)
        w = c @ f + gap - res.rotation * arm
        assert np.all(w >= -1e-12 * res.rotation * arm.max())
        assert np.max(np.abs(w * f)) <= 1e-9 * res.rotation * arm.max() * f.max()
        # independent optimiser
        scale = torque / arm.max()
        out = _slsqp(c * scale ** 2, gap * scale, arm * scale, torque)
        assert np.allclose(out.x * scale, f, atol=1e-5 * scale)


def test_load_dependent_local_term(steel_model):
    """Secant stiffness rises with the torque (Hertzian contact stiffens), while the rotation
    grows almost linearly."""
    tm = steel_model.pair.mesh_angle
    r = []
    for t in (50.0, 100.0, 200.0):
        _, res = steel_model.model.solve(0.3 * tm, 0.0, t / steel_model.face_width)
        r.append(t / res.rotation)
    assert r[0] < r[1] < r[2]
    assert r[2] / r[0] < 1.1


@pytest.mark.slow
def test_direct_two_body_contact_agrees(paper_case):
    """Influence-coefficient route vs a direct two-body contact solve of the same FE bodies
    (coarse mesh, paper's aluminium pair, dd = 0.5 mm): load share per pair and hub rotation
    within 3 % at five positions: healthy single contact at the pitch point, double contact
    mid-zone, and near the exit with the pinion tip loaded; with the 5 mm crack on pinion tooth 0,
    the cracked tooth alone and sharing the load."""
    from geardyn.cache import Cache
    from geardyn.stiffness.fe import FEStiffness
    from geardyn.stiffness.fe.direct import direct_contact
    from geardyn.stiffness.fe.mesh import build_body_mesh
    from geardyn.stiffness.fe.solve import ElasticBody

    dd = 0.5e-3
    for cracked, positions in ((False, (0.0, 0.5, -0.21)), (True, (0.0, 0.4))):
        case = paper_case.with_overrides({"crack.tooth": 0})
        s = coarse_settings(case, flank_size=0.06e-3, tooth_size=0.8e-3, n_points=32)
        import tempfile

        m = FEStiffness(case, cracked=cracked, settings=s, cache=Cache(tempfile.mkdtemp()))
        pair = m.pair
        b2 = ElasticBody(build_body_mesh(pair.gear, s.mesh_settings()), m.material)
        b1 = ElasticBody(build_body_mesh(pair.pinion, s.mesh_settings(), m.crack),
                         m.material) if cracked else b2  # 23/23: one healthy body
        for f in positions:
            th = f * pair.mesh_angle
            cand, res = m.solve(th, dd)
            tot = res.force.sum()
            infl = {int(p): x / tot for p, x in zip(cand.pair, res.force, strict=True)
                    if x > 1e-9 * tot}
            d = direct_contact(b1, b2, pair, th, dd, m.torque_per_width, reach=12e-6)
            direct = d.load_share()
            assert set(infl) == set(direct), (f, infl, direct)
            for k, v in direct.items():
                assert infl[k] == pytest.approx(v, rel=0.03), (cracked, f, infl, direct)
            assert res.rotation == pytest.approx(d.rotation, rel=0.03)
