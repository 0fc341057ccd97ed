"""Input torque ripple (issue 14.3): the forced response of the linear model (constant mesh
stiffness, linear load) against the closed-form frequency response, and the Python twin."""

from __future__ import annotations

import numpy as np
import pytest

from geardyn.dynamics import DynamicModel, initial_state, run_steps, simulate, static_equilibrium
from geardyn.dynamics import _kernel as K
from geardyn.dynamics.newmark import _setup_for_case
from geardyn.errors import InputError
from geardyn.stiffness import StiffnessMap

from ._support import case_with, pem_healthy_map

K_CONST = 1.1e8  # N/m


def _constant_map(pair):
    return StiffnessMap.from_function(pair, [0.0],
                                      lambda th, d: {"k_mb": np.full(th.size, K_CONST)}, n_seg=2)


@pytest.mark.slow
@pytest.mark.parametrize("order,phase", [(1.0, 0.0), (2.5, 0.7)])
def test_ripple_response_matches_the_closed_form_frf(order, phase):
    case = case_with(motor__ripple=0.1, motor__ripple_order=order, motor__ripple_phase=phase,
                     simulation__settle_time=0.25, simulation__record_time=0.2201,
                     simulation__decimation=10)
    smap = _constant_map(case.gear_pair())
    ds = simulate(case, smap, model="I")
    assert "input_torque_ripple" in ds.attrs
    dyn = DynamicModel.from_case(case, smap)
    static = static_equilibrium(dyn, smap, which="I")
    setup = _setup_for_case(case, dyn, smap, "I", static)
    w = order * dyn.speed
    amp = 0.1 * case.motor.torque
    # closed form: z = Im{Z exp(i(w t + phase))}, (K - w^2 M + i w C) Z = A e_0
    kk = setup.K0 + K_CONST * np.outer(setup.g, setup.g)
    f = np.zeros(6)
    f[0] = amp
    z = np.linalg.solve(kk - w * w * setup.M + 1j * w * setup.C, f)
    t = ds.time.values
    for i, name in ((0, "omega_m"), (2, "omega_p"), (5, "omega_out")):
        want = np.imag(1j * w * z[i] * np.exp(1j * (w * t + phase)))
        got = ds[name].values - ds[name].values.mean()
        basis = np.column_stack([np.sin(w * t), np.cos(w * t), np.ones_like(t)])
        c_got = np.linalg.lstsq(basis, got, rcond=None)[0][:2]
        c_want = np.linalg.lstsq(basis, want, rcond=None)[0][:2]
        assert np.hypot(*c_want) > 1e-4  # a visible speed ripple [rad/s]
        np.testing.assert_allclose(c_got, c_want, rtol=0, atol=2e-3 * np.hypot(*c_want)), name


@pytest.mark.slow
@pytest.mark.parametrize("integrator", ["newmark", "hht"])
def test_ripple_kernel_matches_python_twin(integrator):
    case = case_with(motor__ripple=0.2, motor__ripple_order=3.0,
                     modifications__pinion__tip_relief="10 um",
                     simulation__integrator=integrator)
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


def test_bad_ripple_is_refused():
    with pytest.raises(InputError, match="motor.ripple"):
        case_with(motor__ripple=1.5)
    with pytest.raises(InputError, match="motor.ripple_order"):
        case_with(motor__ripple_order=-1.0)
