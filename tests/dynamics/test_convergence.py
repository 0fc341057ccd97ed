"""The full 6-DOF model against scipy's DOP853 (an independent right-hand side of eqs. 9-16),
observed orders under dt halving, and the energy audit (docs/verification/dynamics.md, integration checks)."""

from __future__ import annotations

import numpy as np
import pytest
from scipy.integrate import trapezoid  # np.trapezoid needs NumPy 2; the floor is 1.26

from geardyn.dynamics import DynamicModel, simulate

from ._support import dop853_reference, short_case, triangle_map

NAMES = ("theta_m", "y_p", "theta_p", "y_g", "theta_g", "theta_out",
         "omega_m", "v_yp", "omega_p", "v_yg", "omega_g", "omega_out")
DTS = (2e-5, 1e-5, 5e-6, 2.5e-6)
T_END = 0.02
T_EVAL = np.arange(0, 1001) * 2e-5      # common grid of all step sizes, 0 .. 20 ms


def _runs(which, evaluation):
    # tight model II tolerances so the compared scheme is the converged one
    case = short_case(**{"simulation.record_time": T_END + 4e-5, "simulation.tolerance": 1e-13,
                         "simulation.rtol": 1e-13,
                         "simulation.stiffness_evaluation": evaluation})
    smap = triangle_map(case.gear_pair())
    runs = {dt: simulate(case.with_overrides({"simulation.dt": dt}), smap, model=which)
            for dt in DTS}
    return case, smap, runs


def _on_grid(ds, dt, name):
    return ds[name].values[:: int(round(2e-5 / dt))][: T_EVAL.size]


@pytest.fixture(scope="module", params=["I", "II"])
def reference(request):
    which = request.param
    case, smap, runs = _runs(which, "predictor")
    ds = runs[1e-5]
    y0 = np.array([ds[v].values[0] for v in NAMES])
    ref = dop853_reference(case, smap, which, y0, T_EVAL, rtol=1e-12)
    return which, case, smap, runs, ref


@pytest.mark.slow
def test_agrees_with_dop853_at_default_step(reference):
    """Transmission error within 1e-6 rad of DOP853 (rtol 1e-12) over 20 ms at dt = 1e-5 s."""
    which, case, smap, runs, ref = reference
    te_ref = ref[2] - ref[4]
    err = np.abs(_on_grid(runs[1e-5], 1e-5, "transmission_error") - te_ref).max()
    assert err < 1e-6, err
    # every DOF tracks the reference too (bearing displacements to 1e-8 m)
    for i in (1, 3):
        assert np.abs(_on_grid(runs[1e-5], 1e-5, NAMES[i]) - ref[i]).max() < 1e-8
    if which == "II":
        assert runs[1e-5]["iterations"].values.max() >= 1


@pytest.mark.slow
def test_observed_order_two_with_smooth_stiffness(reference):
    """Error against DOP853 falls as dt^2: observed order 2 +/- 0.1 for each halving."""
    which, case, smap, runs, ref = reference
    te_ref = ref[2] - ref[4]
    errs = [np.abs(_on_grid(runs[dt], dt, "transmission_error") - te_ref).max() for dt in DTS]
    orders = np.log2(np.array(errs[:-1]) / np.array(errs[1:]))
    assert np.all(np.abs(orders - 2.0) < 0.1), (errs, orders)


@pytest.mark.parametrize("which", ["I", "II"])
def test_start_of_step_evaluation_is_first_order(which):
    """The paper's flow chart (stiffness at the start of the step) converges at order 1; at
    dt = 1e-5 s its centre-distance error is of the order of the 0.1 um tolerance."""
    case, smap, runs = _runs(which, "start")
    ds = runs[1e-5]
    y0 = np.array([ds[v].values[0] for v in NAMES])
    ref = dop853_reference(case, smap, which, y0, T_EVAL, rtol=1e-12)
    te_ref = ref[2] - ref[4]
    errs = [np.abs(_on_grid(runs[dt], dt, "transmission_error") - te_ref).max() for dt in DTS]
    orders = np.log2(np.array(errs[:-1]) / np.array(errs[1:]))
    assert np.all(np.abs(orders - 1.0) < 0.1), (errs, orders)
    pair = case.gear_pair()
    d_ref = np.hypot(pair.base_radius_sum, pair.design_t1t2 + ref[3] - ref[1]) \
        - pair.design_centre_distance
    dd_err = np.abs(_on_grid(ds, 1e-5, "centre_distance_change") - d_ref).max()
    assert 1e-8 < dd_err < 3e-7


def _energy_residual(ds, dyn):
    """Input work - output work - dissipation - change of (kinetic + potential) energy + work of
    the stiffness change (Oh, Grosh & Barber 2005), trapezoidal in time [J]."""
    M = np.diag(dyn.M)
    q = dyn.damping
    V = np.stack([ds[v].values for v in NAMES[6:]])
    X = np.stack([ds[v].values for v in NAMES[:6]])
    kcp, kcg, kyp, kyg = -dyn.K0[0, 2], -dyn.K0[4, 5], dyn.K0[1, 1], dyn.K0[3, 3]
    kinetic = 0.5 * (M[:, None] * V ** 2).sum(0)
    elastic = (0.5 * kcp * (X[0] - X[2]) ** 2 + 0.5 * kyp * X[1] ** 2 + 0.5 * kyg * X[3] ** 2
               + 0.5 * kcg * (X[4] - X[5]) ** 2)
    p, k, h = (ds[v].values for v in ("mesh_deflection", "mesh_stiffness", "contact"))
    pd = V[1] + dyn.r_b1 * V[2] - V[3] - dyn.r_b2 * V[4]
    mesh = 0.5 * h * k * p ** 2
    p_in = dyn.input_law.torque(V[0]) * V[0]
    p_out = dyn.output_law.torque(V[5]) * V[5]
    diss = (q["q_cp"] * (V[0] - V[2]) ** 2 + q["q_yp"] * V[1] ** 2 + q["q_yg"] * V[3] ** 2
            + q["q_cg"] * (V[4] - V[5]) ** 2 + q["q_stp"] * V[2] ** 2 + q["q_stg"] * V[4] ** 2
            + h * dyn.q_mb * pd ** 2)
    t = ds.time.values
    stiffness_work = np.sum(0.25 * (p[1:] ** 2 + p[:-1] ** 2) * np.diff(h * k))
    energy = kinetic + elastic + mesh
    resid = (energy[-1] - energy[0]) - trapezoid(p_in - p_out - diss, t) - stiffness_work
    return resid, trapezoid(p_in, t)


@pytest.mark.parametrize("which", ["I", "II"])
def test_energy_audit_residual_falls_as_dt_squared(which):
    case = short_case(**{"simulation.record_time": T_END, "simulation.tolerance": 1e-13,
                         "simulation.rtol": 1e-13, "pinion.torsional_damping": 0.01})
    smap = triangle_map(case.gear_pair())
    dyn = DynamicModel.from_case(case, smap)
    res = []
    for dt in (1e-5, 5e-6, 2.5e-6):
        r, w_in = _energy_residual(simulate(case.with_overrides({"simulation.dt": dt}), smap,
                                            model=which), dyn)
        res.append(abs(r))
        assert abs(r) < 1e-7 * w_in       # the books balance to 1e-7 of the input work
    orders = np.log2(np.array(res[:-1]) / np.array(res[1:]))
    assert np.all(np.abs(orders - 2.0) < 0.1), (res, orders)
