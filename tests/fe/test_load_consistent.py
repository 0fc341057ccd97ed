"""Load-consistent FE stiffness (issue 18.2): the map at the operating torque, secant or tangent.

Oracles:
* the direct two-body contact solve of the same FE bodies (:func:`geardyn.stiffness.fe.direct.
  direct_contact`: node-to-segment contact, Lagrange multipliers, no influence coefficients, no
  assumed pressure patch and no analytical Hertz term) at each torque: its secant
  ``T / (dtheta r_b1^2)`` against the map's secant, and its own central difference
  ``2 h T / ((dtheta(T (1 + h)) - dtheta(T (1 - h))) r_b1^2)`` against the map's tangent;
* the per-position pure-Python evaluation (``compiled=False``) for the tangent's batched path;
* the cache-key identity and the sweep memo for the map's torque.

Physics asserted only where measured: Hertzian contact (the map's local term, the direct solve's
growing contact zone) and gaps that close under load stiffen the contact, so the secant and the
tangent rise with the torque and the tangent exceeds the secant. Measured when written (coarse
mesh, paper's aluminium pair, dd = 0.5 mm): map vs direct within 0.36 % (secant) and 0.35 %
(tangent) at the single- and double-contact positions tested; at a position where the
approaching pair's 8 um gap closes under load (0.25 mesh angles) the secant differs by up to
1.0 % and the tangent by up to 2.6 % (not asserted; docs/verification/stiffness.md, 3.1): the gear's
sharp tip corner carries that pair, by a single node in the direct solve (a mesh-dependent point
compliance) and by the patch plus the Hertz term in the map. With the direct solve's corner
compliance in the map the two agree within 1 % there as well (asserted).
"""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest

from geardyn.cache import cache_key
from geardyn.errors import InputError
from geardyn.stiffness import fe_torque, map_inputs
from geardyn.stiffness.fe import FESettings, FEStiffness
from geardyn.stiffness.fe.model import TANGENT_STEP

from .conftest import coarse_settings

TORQUES = (60.0, 100.0, 140.0)  # the shipped sweep's motor.torque axis [N m]
KEYS = ("k_mb", "load_share", "load_share_exiting", "pairs_in_contact", "transmission_error")


def _models(case, cracked: bool, definition: str) -> dict[float, FEStiffness]:
    base = dataclasses.replace(coarse_settings(case), definition=definition)
    return {t: FEStiffness(case, cracked=cracked, settings=dataclasses.replace(base, torque=t))
            for t in TORQUES}


# ------------------------------------------------------------------------- torque resolution
def test_omitted_torque_is_motor_torque_bit_for_bit(paper_case):
    """``[stiffness.fe] torque`` omitted builds the map at ``motor.torque``: the same settings,
    cache key and map values (bit for bit) as the explicit value; the shipped paper case keeps
    its 100 N m through the default."""
    assert paper_case.stiffness.fe.torque is None and fe_torque(paper_case) == 100.0
    assert FESettings.from_case(paper_case).torque == 100.0
    for t in (60.0, 100.0):
        omitted = paper_case.with_overrides({"motor.torque": t})
        explicit = omitted.with_overrides({"stiffness.fe.torque": t})
        assert explicit.stiffness.fe.torque == t and omitted.stiffness.fe.torque is None
        assert FESettings.from_case(omitted) == FESettings.from_case(explicit)
        for cracked in (False, True):
            assert cache_key(map_inputs(omitted, "fe", cracked)) == \
                cache_key(map_inputs(explicit, "fe", cracked))
        a = FEStiffness(omitted, cracked=True, settings=coarse_settings(omitted))
        b = FEStiffness(explicit, cracked=True, settings=coarse_settings(explicit))
        assert a.settings.torque == t
        theta = np.linspace(-1.3, 1.3, 41) * a.pair.mesh_angle
        for dd in (0.0, 1.07e-3):
            ra, rb = a.evaluate(theta, dd), b.evaluate(theta, dd)
            for k in KEYS:
                np.testing.assert_array_equal(ra[k], rb[k], err_msg=k)
    # an explicit torque other than the operating one is kept (and only it matters to the map)
    other = paper_case.with_overrides({"stiffness.fe.torque": 60.0})
    assert fe_torque(other) == 60.0
    assert cache_key(map_inputs(other, "fe", True)) == cache_key(map_inputs(
        paper_case.with_overrides({"motor.torque": 60.0}), "fe", True))
    # the PEM map does not depend on the load (Yang & Lin's load-independent Hertz term)
    assert cache_key(map_inputs(other, "pem", True)) == cache_key(map_inputs(paper_case, "pem",
                                                                             True))


def test_definition_in_key_and_checked(paper_case):
    """The secant default keeps the earlier keys (no ``definition`` entry); the tangent and its
    step enter the key; a bad definition is refused naming the field."""
    sec = map_inputs(paper_case, "fe", True)
    assert "definition" not in sec["fe"] and sec["fe"]["torque"] == 100.0
    tan_case = paper_case.with_overrides({"stiffness.fe.definition": "tangent"})
    tan = map_inputs(tan_case, "fe", True)
    assert tan["fe"]["definition"] == "tangent" and tan["fe"]["tangent_step"] == TANGENT_STEP
    assert cache_key(tan) != cache_key(sec)
    with pytest.raises(InputError, match="stiffness.fe.definition"):
        dataclasses.replace(FESettings.from_case(paper_case), definition="chord").check()
    with pytest.raises(InputError, match="stiffness.fe.definition"):
        paper_case.with_overrides({"stiffness.fe.definition": "chord"})


def test_shipped_torque_sweep_has_one_map_per_torque():
    """The shipped sweep (crack depth x motor torque x bearing stiffness): its runs' map keys
    (the sweep memo's and the disk cache's, GeardynEvaluator.prepare_key) differ for each torque
    and crack depth, and are shared across the bearing stiffness (which the map does not
    depend on)."""
    from importlib import resources

    from geardyn.studies.sweep import load_sweep
    from geardyn.studies.sweep.evaluate import GeardynEvaluator

    path = resources.files("geardyn.cases") / "sweep_crack_torque_bearing.toml"
    sweep = load_sweep(str(path))
    plan = sweep.plan()
    keys: dict[tuple, set] = {}
    ev = GeardynEvaluator()
    for run in range(plan.n_runs):
        ov = plan.overrides(run)
        case = sweep.base_case.with_overrides(ov)
        assert case.stiffness.method == "fe" and case.stiffness.fe.torque is None
        keys.setdefault((ov["crack.depth"], ov["motor.torque"]), set()).add(ev.prepare_key(case))
    assert sorted({t for _, t in keys}) == list(TORQUES)
    assert all(len(v) == 1 for v in keys.values())  # bearings share the map
    assert len({next(iter(v)) for v in keys.values()}) == len(keys) == 21


# ------------------------------------------------------------------------- secant and tangent
@pytest.mark.parametrize("cracked", [False, True], ids=["healthy", "cracked"])
def test_stiffening_over_the_whole_map(paper_case, cracked):
    """Over one mesh cycle (healthy) or the pinion revolution (cracked) at four centre
    distances: secant and tangent rise with the torque at every node (60 < 100 < 140 N m), and
    the tangent exceeds the secant at every node. Measured when written: at least +0.6 % per
    step of the torque, tangent / secant 1.018 to 1.51."""
    sec, tan = _models(paper_case, cracked, "secant"), _models(paper_case, cracked, "tangent")
    tm = sec[100.0].pair.mesh_angle
    theta = np.linspace(0, 23 * tm, 23 * 24, endpoint=False) if cracked else \
        np.linspace(0, tm, 97)
    for dd in (-0.5e-3, 0.0, 1.07e-3, 2e-3):
        s = {t: m.evaluate(theta, dd) for t, m in sec.items()}
        k = {t: m.evaluate(theta, dd) for t, m in tan.items()}
        for a, b in zip(TORQUES[:-1], TORQUES[1:], strict=True):
            assert np.all(s[b]["k_mb"] > s[a]["k_mb"]), (dd, a, b)
            assert np.all(k[b]["k_mb"] > k[a]["k_mb"]), (dd, a, b)
        for t in TORQUES:
            assert np.all(k[t]["k_mb"] > s[t]["k_mb"]), (dd, t)
            # everything but k_mb is the secant evaluation's (at T)
            for name in KEYS[1:]:
                np.testing.assert_array_equal(k[t][name], s[t][name], err_msg=name)


@pytest.mark.parametrize("cracked", [False, True], ids=["healthy", "cracked"])
def test_tangent_compiled_equals_reference(paper_case, cracked):
    """The tangent map's batched evaluation equals the per-position pure-Python reference to
    1e-9 relative (as the secant, tests/fe/test_batched_contact.py), here at 140 N m."""
    m = _models(paper_case, cracked, "tangent")[140.0]
    tm = m.pair.mesh_angle
    theta = np.linspace(-1.6 * tm, 1.6 * tm, 61)
    for dd in (0.0, 1.5e-3):
        fast = m.evaluate(theta, dd, compiled=True)
        ref = m.evaluate(theta, dd, compiled=False)
        for k in KEYS:
            np.testing.assert_allclose(fast[k], ref[k], rtol=1e-9, atol=1e-12, err_msg=k)


def test_tangent_is_the_central_difference_of_the_secant_route(paper_case):
    """The tangent is ``2 h T / ((dtheta(T(1+h)) - dtheta(T(1-h))) r_b1^2)`` of the secant
    evaluations at the two torques (:meth:`FEStiffness.evaluate_at`), with ``h = 0.05``."""
    m = _models(paper_case, False, "tangent")[100.0]
    assert m.settings.tangent_step == TANGENT_STEP == 0.05
    theta = np.linspace(0, m.pair.mesh_angle, 25)
    hi = m.evaluate_at(theta, 0.5e-3, 105.0)["transmission_error"]
    lo = m.evaluate_at(theta, 0.5e-3, 95.0)["transmission_error"]
    rb1 = m.pair.pinion.base_radius
    np.testing.assert_allclose(m.evaluate(theta, 0.5e-3)["k_mb"], 10.0 / (hi - lo) / rb1 ** 2,
                               rtol=1e-12)
    assert "tangent" in m.attrs()["stiffness_definition"] and m.attrs()["torque"] == 100.0


# ------------------------------------------------------------------------- against the direct solve
@pytest.fixture(scope="module")
def direct_setup(paper_case):
    """Secant and tangent maps at each torque and the direct solve's body (paper's healthy pair,
    finer coarse mesh: 0.06 mm flank elements, bodies in a temporary cache)."""
    import tempfile

    from geardyn.cache import Cache
    from geardyn.stiffness.fe.mesh import build_body_mesh
    from geardyn.stiffness.fe.solve import ElasticBody

    case = paper_case
    s = coarse_settings(case, flank_size=0.06e-3, tooth_size=0.8e-3, n_points=32)
    cache = Cache(tempfile.mkdtemp())
    sec = {t: FEStiffness(case, cracked=False, cache=cache,
                          settings=dataclasses.replace(s, torque=t)) for t in TORQUES}
    tan = {t: FEStiffness(case, cracked=False, cache=cache,
                          settings=dataclasses.replace(s, torque=t, definition="tangent"))
           for t in TORQUES}
    m = sec[100.0]
    body = ElasticBody(build_body_mesh(m.pair.gear, s.mesh_settings()), m.material)  # 23/23
    return sec, tan, body, s


#: Direct-contact operators by (fixture, pinion angle): one per position serves every torque
#: (the Delassus matrix is the costly part and does not depend on the load)
_OPERATORS: dict = {}


def _direct(setup, theta, torque):
    from geardyn.stiffness.fe.direct import direct_operator

    sec, _, body, _ = setup
    m = sec[100.0]
    key = (id(setup), theta)
    if key not in _OPERATORS:
        _OPERATORS[key] = direct_operator(body, body, m.pair, theta, 0.5e-3, reach=25e-6)
    return _OPERATORS[key].solve(torque / m.face_width)


@pytest.mark.slow
def test_one_operator_serves_every_torque(direct_setup):
    """``direct_contact`` (operator built for the call) and a reused operator's ``solve`` give
    the same contact, bit for bit, at two torques."""
    from geardyn.stiffness.fe.direct import direct_contact

    sec, _, body, _ = direct_setup
    m = sec[100.0]
    th = 0.5 * m.pair.mesh_angle
    for t in (60.0, 140.0):
        a = direct_contact(body, body, m.pair, th, 0.5e-3, t / m.face_width, reach=25e-6)
        b = _direct(direct_setup, th, t)
        assert a.rotation == b.rotation and a.pair_force == b.pair_force and a.rotation > 0
        np.testing.assert_array_equal(a.node_force, b.node_force)
        np.testing.assert_array_equal(a.node_compliance, b.node_compliance)


@pytest.mark.slow
def test_secant_and_tangent_against_direct_solve(direct_setup):
    """Map (influence coefficients, compiled evaluation) against the direct two-body FE contact
    solve at 60, 100 and 140 N m, healthy pair, dd = 0.5 mm: single contact at the pitch point
    (0 mesh angles), double contact mid-zone (0.5) and near the exit with the pinion tip
    loaded (-0.21). Secant within 1 % at each torque; the map's tangent within 1 % of the
    direct solve's central difference at T (1 +/- 0.05); both rise with the torque and the
    tangent exceeds the secant, in the map and in the direct solve."""
    sec, tan, _, _ = direct_setup
    pair = sec[100.0].pair
    rb1, h, dd = pair.pinion.base_radius, TANGENT_STEP, 0.5e-3

    def rotation(theta, t):
        return _direct(direct_setup, theta, t).rotation

    for f in (0.0, 0.5, -0.21):
        th = f * pair.mesh_angle
        rows = []
        for t in TORQUES:
            k_sec = float(sec[t].evaluate(np.array([th]), dd)["k_mb"][0])
            k_tan = float(tan[t].evaluate(np.array([th]), dd)["k_mb"][0])
            d_sec = t / rotation(th, t) / rb1 ** 2
            d_tan = 2 * h * t / (rotation(th, t * (1 + h)) - rotation(th, t * (1 - h))) / rb1 ** 2
            assert k_sec == pytest.approx(d_sec, rel=0.01), (f, t, k_sec, d_sec)
            assert k_tan == pytest.approx(d_tan, rel=0.01), (f, t, k_tan, d_tan)
            rows.append((k_sec, k_tan, d_sec, d_tan))
        r = np.array(rows)
        assert np.all(np.diff(r, axis=0) > 0), (f, r)  # each rises with the torque
        assert np.all(r[:, 1] > r[:, 0]) and np.all(r[:, 3] > r[:, 2]), (f, r)


@pytest.mark.slow
def test_gap_closing_position_differs_by_the_corner_contact_law(direct_setup):
    """Where the approaching pair's unloaded gap closes under the load (0.25 mesh angles,
    dd = 0.5 mm) the gear's tip corner touches the pinion flank. The routes differ only in the
    compliance of that corner contact (docs/verification/stiffness.md, 3.1):

    * the direct solve carries the pair by the corner node alone, with a load-independent point
      compliance ``w_c`` (the Delassus diagonal of that node), while the map uses the patch
      compliance plus the Hertz term with the involute curvatures, smaller than ``w_c`` here;
    * the unloaded gaps agree within the chord error of the P2 flank segment on the pinion
      flank, ``h^2 / (8 rho_1)`` (``h`` flank element size, ``rho_1 = u_1``, its involute radius
      of curvature), so the gap is not the cause;
    * with ``w_c`` in place of the map's corner compliance (everything else the map's: FE
      influence coefficients, exact gap and lever arm, the other pair's Hertz term) secant and
      tangent agree with the direct solve within 1 % at 60, 100 and 140 N m (measured when
      written: within 0.34 %; with the map as it is: up to +1.0 % and +2.6 %)."""
    from geardyn.stiffness.fe.contact import GEAR_TIP, candidates, solve_compatibility

    sec, _, _, s = direct_setup
    m = sec[100.0]
    pair, cm, width = m.pair, m.model, m.face_width
    rb1, h, dd = pair.pinion.base_radius, TANGENT_STEP, 0.5e-3
    th = 0.25 * pair.mesh_angle
    cand = candidates(pair, th, dd)
    (i,) = np.nonzero(cand.pair == 1)[0]
    assert cand.kind[i] == GEAR_TIP and cand.gap[i] > 0
    c0 = cm.compliance(cand)
    loads = sorted({t * (1 + e) for t in TORQUES for e in (-h, 0.0, h)})
    direct, wc = {}, set()
    for t in loads:
        d = _direct(direct_setup, th, t)
        on = (d.node_pair == 1) & (d.node_force > 0)
        assert list(d.node_kind[on]) == ["g"], (t, d.node_kind[on])  # the corner node alone
        assert abs(d.node_gap[on][0] - cand.gap[i]) <= s.flank_size ** 2 / (8 * cand.u1[i])
        wc.add(float(d.node_compliance[on][0]))
        direct[t] = d.rotation
    w_c = wc.pop()
    assert not wc  # one linear point compliance whatever the load

    def map_rotation(t, corner):
        def local(f):
            out = cm.local_term(cand, f)
            if corner is not None:
                out[i] = corner - c0[i, i]
            return out
        res = solve_compatibility(c0, cand.gap, cand.arm, t / width, local)
        if corner is None:
            assert c0[i, i] + cm.local_term(cand, res.force)[i] < w_c, t
        return res.rotation

    for t in TORQUES:
        lo, hi = t * (1 - h), t * (1 + h)
        d_sec = t / direct[t] / rb1 ** 2
        d_tan = 2 * h * t / (direct[hi] - direct[lo]) / rb1 ** 2
        rot = {x: map_rotation(x, w_c) for x in (lo, t, hi)}
        assert t / rot[t] / rb1 ** 2 == pytest.approx(d_sec, rel=0.01), t
        assert 2 * h * t / (rot[hi] - rot[lo]) / rb1 ** 2 == pytest.approx(d_tan, rel=0.01), t
        # the map as it is: its own (compiled) evaluation is this solve with the Hertz term
        k_map = float(m.evaluate_at(np.array([th]), dd, t)["k_mb"][0])
        assert k_map == pytest.approx(t / map_rotation(t, None) / rb1 ** 2, rel=1e-9), t


@pytest.mark.slow
def test_sweep_memo_builds_one_fe_map_per_torque():
    """The sweep's per-process map memo (studies.sweep.evaluate._stiffness_map) builds one FE
    map per motor torque (coarse mesh, small grid) with ``attrs["torque"]`` the run's torque and
    a mean stiffness rising with it; a second run at a torque already seen reuses its map."""
    import geardyn
    from geardyn.studies.sweep.evaluate import _cached_map, _stiffness_map

    case = geardyn.paper_case({"stiffness.fe.mesh_size": 1e-3, "stiffness.fe.teeth_in_model": 3,
                               "stiffness.centre_distances": 2,
                               "stiffness.nodes_per_segment": 4,
                               "stiffness.centre_distance_max": 1.5e-3})
    _cached_map.cache_clear()
    maps = [_stiffness_map(case.with_overrides({"motor.torque": t})) for t in TORQUES]
    assert [mp.attrs["torque"] for mp in maps] == list(TORQUES)
    assert len({mp.attrs["inputs_hash"] for mp in maps}) == 3
    means = [float(np.mean(mp.k_mb)) for mp in maps]
    assert means[0] < means[1] < means[2]
    again = _stiffness_map(case.with_overrides({"motor.torque": 100.0,
                                                "pinion.bearing_stiffness": 2e6}))
    assert again is maps[1]
    info = _cached_map.cache_info()
    assert (info.hits, info.misses) == (1, 3)
