"""Speed profiles (issue 14.3): a speed-controlled drive following a ramp run-up or coast-down.

Oracles: the rigid-body equation ``I dW/dt = T + c (w_target - W) - c_L W`` integrated by scipy
(a second method), its closed-form steady state ``(T + c w_1)/(c + c_L)``, and the Python twin."""

from __future__ import annotations

import numpy as np
import pytest
from scipy.integrate import solve_ivp

from geardyn.dynamics import DynamicModel, initial_state, run_steps, simulate, static_equilibrium
from geardyn.dynamics import _kernel as K
from geardyn.dynamics.newmark import _setup_for_case
from geardyn.errors import InputError

from ._support import case_with, pem_healthy_map
from .test_torque_ripple import _constant_map

W0 = 114.14  # rad/s, the paper's speed (the static start)


@pytest.mark.slow
@pytest.mark.parametrize("factor", [1.2, 0.7])  # run-up and coast-down
def test_ramp_follows_the_rigid_body_equation_and_its_steady_state(factor):
    w1, gain = factor * W0, 5.0
    case = case_with(motor__profile_times=[0.05, 0.15], motor__profile_speeds=[W0, w1],
                     motor__drive_gain=gain, simulation__settle_time=0.0,
                     simulation__record_time=0.6, simulation__decimation=100)
    smap = _constant_map(case.gear_pair())
    ds = simulate(case, smap, model="I")
    assert "speed_profile" in ds.attrs
    dyn = DynamicModel.from_case(case, smap)
    inertia = float(np.trace(dyn.M) - dyn.M[1, 1] - dyn.M[3, 3])  # ratio 1, no q_st
    t0, c_l = case.motor.torque, dyn.output_law.coefficient

    def rigid(t, y):
        return [(t0 + gain * (np.interp(t, [0.05, 0.15], [W0, w1]) - y[0]) - c_l * y[0])
                / inertia]

    t = ds.time.values
    ref = solve_ivp(rigid, (0.0, t[-1]), [W0], t_eval=t, rtol=1e-11, atol=1e-11,
                    max_step=1e-3).y[0]
    w_ss = (t0 + gain * w1) / (gain + c_l)
    for name in ("omega_m", "omega_p", "omega_out"):
        w = ds[name].values
        # elastic twist during the ramp (coupling modes) stays within 2 % of the speed change
        assert np.abs(w - ref).max() < 0.02 * abs(w1 - W0), name
        assert np.abs(w - ref)[t > 0.3].max() < 1e-6, name
        assert w[-1] == pytest.approx(w_ss, rel=1e-9), name


@pytest.mark.slow
def test_profile_kernel_matches_python_twin():
    # no ripple: a ripple with a speed profile is refused since 2026-11-27 (a fixed-frequency
    # torque in a run-up); the ripple's twin equality is test_kernel_mutants'
    # test_twin_equality_with_ripple_drive_and_laws
    case = case_with(motor__profile_times=[0.0, 0.002], motor__profile_speeds=[W0, 1.3 * W0],
                     modifications__gear__runout="8 um")
    smap = pem_healthy_map()
    dyn = DynamicModel.from_case(case, smap)
    static = static_equilibrium(dyn, smap, which="II")
    setup = _setup_for_case(case, dyn, smap, "II", static)
    outs = []
    for python in (False, True):
        st, ist = initial_state(setup, static.z)
        out = np.full((301, K.N_REC), np.nan)
        status, _, _ = run_steps(setup, st, ist, 300, out=out, python=python)
        assert status == 0
        outs.append(out)
    np.testing.assert_allclose(outs[0], outs[1], rtol=1e-9, atol=1e-12)
    assert outs[0][-1, K.R_V] > 0.1  # the motor is accelerating (deviation from w_ref) [rad/s]


@pytest.mark.parametrize("times,speeds,field", [
    ([0.0], [100.0], "motor.profile_times"), ([0.1, 0.0], [100.0, 120.0], "motor.profile_times"),
    ([0.0, 0.1], [100.0, -1.0], "motor.profile_speeds")])
def test_bad_profiles_are_refused(times, speeds, field):
    case = case_with(motor__profile_times=times, motor__profile_speeds=speeds)
    with pytest.raises(InputError, match=field):
        simulate(case, _constant_map(case.gear_pair()), model="I")
