"""The model of eqs. 9-17 / appendix B: matrices, damping, load laws, static equilibrium,
frequencies, time-step check, operating geometry."""

from __future__ import annotations

import math

import numpy as np
import pytest

import geardyn
from geardyn.dynamics import (
    DynamicModel,
    TorqueLaw,
    check_time_step,
    max_time_step,
    natural_frequencies,
    operating_arrays,
    static_equilibrium,
)
from geardyn.dynamics._kernel import law_torque
from geardyn.errors import InputError

from ._support import geometric_map, short_case


@pytest.fixture(scope="module")
def case():
    return short_case()


@pytest.fixture(scope="module")
def smap(case):
    return geometric_map(case.gear_pair())


@pytest.fixture(scope="module")
def dyn(case, smap):
    return DynamicModel.from_case(case, smap)


def test_matrices_are_appendix_b(dyn):
    """K0 + h k g g^T and C0 + h q g g^T equal appendix B written out term by term (with q_stg
    in the gear row, erratum 3 of eq. 13)."""
    rp, rg = dyn.r_b1, dyn.r_b2
    q = dyn.damping
    kcp, kcg, kyp, kyg = -dyn.K0[0, 2], -dyn.K0[4, 5], dyn.K0[1, 1], dyn.K0[3, 3]
    for h, kmb, qmb in ((1.0, 9.3e7, 123.0), (0.0, 9.3e7, 123.0)):
        K = np.array([
            [kcp, 0, -kcp, 0, 0, 0],
            [0, kyp + h * kmb, h * kmb * rp, -h * kmb, -h * kmb * rg, 0],
            [-kcp, h * kmb * rp, h * kmb * rp ** 2 + kcp, -h * kmb * rp, -h * kmb * rp * rg, 0],
            [0, -h * kmb, -h * kmb * rp, kyg + h * kmb, h * kmb * rg, 0],
            [0, -h * kmb * rg, -h * kmb * rp * rg, h * kmb * rg, h * kmb * rg ** 2 + kcg, -kcg],
            [0, 0, 0, 0, -kcg, kcg]])
        qcp, qcg, qyp, qyg, qstp, qstg = (q[k] for k in ("q_cp", "q_cg", "q_yp", "q_yg",
                                                          "q_stp", "q_stg"))
        C = np.array([
            [qcp, 0, -qcp, 0, 0, 0],
            [0, qyp + h * qmb, h * qmb * rp, -h * qmb, -h * qmb * rg, 0],
            [-qcp, h * qmb * rp, h * qmb * rp ** 2 + qcp + qstp, -h * qmb * rp,
             -h * qmb * rp * rg, 0],
            [0, -h * qmb, -h * qmb * rp, qyg + h * qmb, h * qmb * rg, 0],
            [0, -h * qmb * rg, -h * qmb * rp * rg, h * qmb * rg, h * qmb * rg ** 2 + qcg + qstg,
             -qcg],
            [0, 0, 0, 0, -qcg, qcg]])
        gg = np.outer(dyn.g, dyn.g)
        np.testing.assert_allclose(dyn.K0 + h * kmb * gg, K, rtol=1e-14, atol=1e-9)
        np.testing.assert_allclose(dyn.C0 + h * qmb * gg, C, rtol=1e-14, atol=1e-12)
    np.testing.assert_array_equal(np.diag(dyn.M), [4.3e-3, 0.7, 2.5e-3, 0.7, 2.5e-3, 4.5e-3])
    # the rigid rotation is a free mode of K0 and invisible to the mesh
    e = dyn.reference_direction
    assert np.abs(dyn.K0 @ e).max() < 1e-9 and abs(dyn.g @ e) < 1e-15


def test_asymmetric_torsional_damping_uses_q_stg():
    """Erratum 3: the gear's absolute damping enters the gear row."""
    case = short_case(**{"gear.torsional_damping": 0.02, "pinion.torsional_damping": 0.01})
    dyn = DynamicModel.from_case(case, geometric_map(case.gear_pair()))
    assert dyn.damping["q_stg"] == 0.02 and dyn.damping["q_stp"] == 0.01
    c_rigid = dyn.C0 - np.diag([0, 0, 0.01, 0, 0.02, 0])
    e = dyn.reference_direction
    assert np.abs(c_rigid @ e).max() < 1e-12


def test_damping_from_ratios(dyn, case):
    """Bearings: q = 2 zeta sqrt(k m) (about 84 N s/m, docs/verification/dynamics.md); couplings: the
    two-inertia mode has damping ratio 0.05 (complex eigenvalues); mesh: 2 zeta sqrt(k m_e)."""
    assert dyn.damping["q_yp"] == pytest.approx(2 * 0.05 * math.sqrt(1e6 * 0.7), rel=1e-14)
    assert round(dyn.damping["q_yp"]) == 84
    for (i, j), q, k in (((0, 2), dyn.damping["q_cp"], 1e5), ((4, 5), dyn.damping["q_cg"], 1e5)):
        i1, i2 = dyn.M[i, i], dyn.M[j, j]
        A = np.array([[0, 0, 1, 0], [0, 0, 0, 1],
                      [-k / i1, k / i1, -q / i1, q / i1], [k / i2, -k / i2, q / i2, -q / i2]])
        lam = [x for x in np.linalg.eigvals(A) if abs(x) > 1e-6][0]
        assert -lam.real / abs(lam) == pytest.approx(0.05, rel=1e-10)
    m_e = 2.5e-3 * 2.5e-3 / (2.5e-3 * dyn.r_b2 ** 2 + 2.5e-3 * dyn.r_b1 ** 2)
    assert dyn.m_e == pytest.approx(m_e, rel=1e-14)
    assert dyn.q_mb == pytest.approx(2 * 0.07 * math.sqrt(dyn.k_rep * m_e), rel=1e-14)
    # k_rep: mean of the geometric map (k_pair * contact ratio) at the static operating point
    eps = case.gear_pair().operating(1.0852e-3).contact_ratio
    assert dyn.k_rep == pytest.approx(8e7 * eps, rel=2e-3)
    # a given mesh damping is used as is
    case2 = case.with_overrides({"mesh.damping": 500.0})
    assert DynamicModel.from_case(case2, geometric_map(case.gear_pair())).q_mb == 500.0


def test_output_law_calibrated_to_paper_speed(dyn):
    """c_L = T_in / 114.14 = 0.8761 N m s/rad with zero absolute torsional damping."""
    assert dyn.output_law.kind == "linear" and dyn.output_calibrated
    assert dyn.output_law.coefficient == pytest.approx(100 / 114.14, rel=1e-14)
    assert round(dyn.output_law.coefficient, 4) == 0.8761
    assert dyn.speed == 114.14


@pytest.mark.parametrize("law", ["linear", "quadratic", "constant"])
def test_calibration_balances_torque_with_absolute_damping(law):
    case = short_case(**{"load.law": law, "pinion.torsional_damping": 0.012,
                         "gear.torsional_damping": 0.012})
    dyn = DynamicModel.from_case(case, geometric_map(case.gear_pair()))
    w = dyn.speed
    n = (100 - 0.012 * w) / dyn.r_b1
    assert float(dyn.output_law.torque(dyn.gear_speed)) == pytest.approx(
        n * dyn.r_b2 - 0.012 * dyn.gear_speed, rel=1e-13)


def test_given_coefficient_and_table_set_the_speed():
    """A given coefficient (or a table) wins over load.speed; the speed solves the balance."""
    case = short_case(**{"load.coefficient": 1.25})
    dyn = DynamicModel.from_case(case, geometric_map(case.gear_pair()))
    assert dyn.speed == pytest.approx(100 / 1.25, rel=1e-12) and not dyn.output_calibrated
    case = short_case(**{"load.law": "table", "load.table_speeds": [0.0, 100.0, 200.0],
                         "load.table_torques": [0.0, 50.0, 150.0]})
    dyn = DynamicModel.from_case(case, geometric_map(case.gear_pair()))
    assert dyn.speed == pytest.approx(150.0, rel=1e-12)   # 50 + (w - 100) = 100
    assert dyn.output_law.slope(150.0) == pytest.approx(1.0)
    case = short_case(**{"load.law": "quadratic", "load.coefficient": 0.01})
    dyn = DynamicModel.from_case(case, geometric_map(case.gear_pair()))
    assert dyn.speed == pytest.approx(100.0, rel=1e-12)


def test_induction_motor_law():
    """Kloss curve: T(w_s) = 0, T at breakdown slip = T_b; the load is calibrated to the speed on
    the stable branch; slopes agree with finite differences."""
    law = TorqueLaw("induction", synchronous_speed=125.0, breakdown_torque=250.0,
                    breakdown_slip=0.2)
    assert law.torque(125.0) == 0.0
    assert law.torque(125.0 * 0.8) == pytest.approx(250.0, rel=1e-14)
    for w in (60.0, 110.0, 124.0):
        fd = (law.torque(w + 1e-5) - law.torque(w - 1e-5)) / 2e-5
        assert law.slope(w) == pytest.approx(fd, rel=1e-6)
    case = short_case(**{"motor.law": "induction", "motor.synchronous_speed": 125.0,
                         "motor.breakdown_torque": 250.0, "motor.breakdown_slip": 0.2})
    dyn = DynamicModel.from_case(case, geometric_map(case.gear_pair()))
    t_in = float(dyn.input_law.torque(114.14))
    assert dyn.output_law.coefficient == pytest.approx(t_in / 114.14, rel=1e-13)
    with pytest.raises(InputError, match="load.speed"):
        DynamicModel.from_case(short_case(**{"motor.law": "induction",
                                             "motor.synchronous_speed": 110.0,
                                             "motor.breakdown_torque": 250.0,
                                             "motor.breakdown_slip": 0.2}),
                               geometric_map(case.gear_pair()))


def test_kernel_law_torque_matches_numpy_laws():
    tw, tt = np.array([0.0, 50.0, 120.0]), np.array([10.0, 40.0, 90.0])
    laws = [TorqueLaw("constant", 3.0), TorqueLaw("linear", 0.8), TorqueLaw("quadratic", 0.01),
            TorqueLaw("table", speeds=tw, torques=tt),
            TorqueLaw("induction", synchronous_speed=125.0, breakdown_torque=250.0,
                      breakdown_slip=0.2)]
    for law in laws:
        a, b = law.table()
        for w in (-5.0, 0.0, 30.0, 50.0, 100.0, 119.0, 150.0):
            assert law_torque(law.code, *law.params(), a, b, w) == pytest.approx(
                float(law.torque(w)), rel=1e-15, abs=1e-13)


def test_static_equilibrium_paper_numbers(dyn, smap):
    """docs/verification/dynamics.md: N = T/r_b = 1542.3 N, y_g - y_p = 3.085 mm, eq. 4 gives 1.0852 mm;
    the static state satisfies the equations of motion in deviation form."""
    st = static_equilibrium(dyn, smap, which="II")
    assert round(st.mesh_force, 1) == 1542.3
    assert st.mesh_force == pytest.approx(100 / (0.069 * math.cos(math.radians(20))), rel=1e-14)
    assert round((st.y_g - st.y_p) * 1e3, 3) == 3.085
    assert round(st.centre_distance_change * 1e3, 4) == 1.0852
    Q0, _, _ = dyn.forcing_at_reference()
    resid = dyn.K0 @ st.z + st.mesh_force * dyn.g - Q0
    assert np.abs(resid).max() < 1e-9 * st.mesh_force
    assert st.z[2] == 0.0                               # theta_p = 0 at t = 0
    p = dyn.g @ st.z
    assert p == pytest.approx(st.mesh_force / st.mesh_stiffness, rel=1e-12)
    # mean transmission error = (2N/k_y + N/k_mesh)/r_b: about 0.048 rad (paper Table 2: 0.05)
    assert st.transmission_error == pytest.approx(
        (2 * st.mesh_force / 1e6 + st.mesh_force / st.mesh_stiffness) / dyn.r_b1, rel=1e-12)
    assert 0.045 < st.transmission_error < 0.05
    st1 = static_equilibrium(dyn, smap, which="I")
    assert st1.mesh_stiffness == pytest.approx(float(smap(0.0, 0.0)))


def test_static_equilibrium_refuses_a_map_without_the_operating_point(dyn, case):
    narrow = geometric_map(case.gear_pair(), dd=(-0.2e-3, 0.5e-3))
    with pytest.raises(InputError, match="centre_distance_max.*1.0852"):
        static_equilibrium(dyn, narrow, which="II")
    static_equilibrium(dyn, narrow, which="I")   # model I needs dd = 0 only


def test_natural_frequencies(dyn):
    """Without the mesh the bearing modes are sqrt(k_y/m)/(2 pi) = 190.2 Hz; a rigid-body mode
    is always 0; the highest mode for the largest stiffness is 4-6.5 kHz (docs/verification/dynamics.md)."""
    f0 = natural_frequencies(dyn, 0.0)
    assert f0[0] < 1e-3 and f0[1] < 1e-3   # rigid body and the free torsional pinion/gear pair
    np.testing.assert_allclose(f0[2:4], math.sqrt(1e6 / 0.7) / (2 * math.pi), rtol=1e-12)
    f = natural_frequencies(dyn, 1.6e8)
    assert f[0] < 1e-3 and 3.7e3 < f[-1] < 6.5e3


def test_time_step_check(dyn, smap):
    dt_max, f_max, f_mesh = max_time_step(dyn, smap)
    assert dt_max == pytest.approx(1 / (10 * f_max))
    assert f_mesh == pytest.approx(114.14 * 23 / (2 * math.pi))   # 417.8 Hz
    check_time_step(dyn, smap, 1e-5)
    with pytest.raises(InputError) as ei:
        check_time_step(dyn, smap, 1.2 * dt_max)
    assert ei.value.field == "simulation.dt"
    assert f"{dt_max:.4g}" in str(ei.value)


def test_operating_arrays_match_gear_pair(case):
    pair = case.gear_pair()
    dd = np.array([-0.3e-3, 0.0, 0.5e-3, 1.0e-3, 1.07e-3, 1.0852e-3, 2e-3])
    op = operating_arrays(pair, dd)
    for i, d in enumerate(dd):
        ref = pair.operating(d, check=False)
        assert op["pressure_angle"][i] == pytest.approx(ref.pressure_angle, rel=1e-14)
        assert op["contact_ratio"][i] == pytest.approx(ref.contact_ratio, rel=1e-12)
        assert op["contact_ratio_eq8"][i] == pytest.approx(ref.contact_ratio_eq8, rel=1e-12)
    # docs/verification/dynamics.md static point at +1.07 mm
    i = 4
    assert math.degrees(op["pressure_angle"][i]) == pytest.approx(21.178, abs=5e-4)
    assert op["contact_ratio"][i] == pytest.approx(1.4198, abs=1e-4)
    assert op["contact_ratio_eq8"][i] == pytest.approx(1.4308, abs=1e-4)


def test_paper_case_loads():
    assert geardyn.paper_case().simulation.model == "II"
