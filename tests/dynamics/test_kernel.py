"""The compiled time loop against its Python twin and against closed-form single-DOF solutions."""

from __future__ import annotations

import math

import numpy as np
import pytest
from scipy.linalg import expm

from geardyn.dynamics import DynamicModel, initial_state, run_steps, static_equilibrium
from geardyn.dynamics import _kernel as K
from geardyn.dynamics.newmark import _setup_for_case

from ._support import constant_map, geometric_map, sdof_setup, short_case


def _run(setup, z0, v0, n, python=False, **kw):
    st, ist = initial_state(setup, z0, v0)
    out = np.full((n + 1, K.N_REC), np.nan)
    status, j, fail = run_steps(setup, st, ist, n, out=out, python=python, **kw)
    return status, out[:j], fail


def _case_setup(case, smap, which):
    dyn = DynamicModel.from_case(case, smap)
    static = static_equilibrium(dyn, smap, which=which)
    return _setup_for_case(case, dyn, smap, which, static), static


@pytest.mark.parametrize("which, over", [
    ("II", {}),
    ("II", {"simulation.tolerance": 1e-8}),                     # iterates at the handovers
    ("II", {"simulation.stiffness_evaluation": "start"}),       # the paper's flow chart
    ("I", {"simulation.integrator": "hht", "simulation.hht_alpha": -0.1}),
    ("II", {"load.law": "quadratic", "motor.law": "induction", "motor.synchronous_speed": 125.0,
            "motor.breakdown_torque": 140.0, "motor.breakdown_slip": 0.2}),
])
def test_kernel_matches_python_twin_on_the_paper_model(which, over):
    """Same discrete equations, two implementations (Sherman-Morrison in numba vs a full
    solve in NumPy): 400 steps (1.7 mesh periods, four handovers) agree to rounding."""
    case = short_case(**over)
    smap = geometric_map(case.gear_pair())
    setup, static = _case_setup(case, smap, which)
    s1, r1, _ = _run(setup, static.z, None, 400)
    s2, r2, _ = _run(setup, static.z, None, 400, python=True)
    assert s1 == s2 == 0 and r1.shape == r2.shape == (401, K.N_REC)
    np.testing.assert_array_equal(np.isnan(r1), np.isnan(r2))
    r1, r2 = np.nan_to_num(r1), np.nan_to_num(r2)
    scale = np.abs(r2).max(axis=0) + 1e-300
    diff = np.abs(r1 - r2) / scale
    assert diff.max() < 1e-8, (diff.max(axis=0))
    np.testing.assert_array_equal(r1[:, K.R_IT], r2[:, K.R_IT])
    np.testing.assert_array_equal(r1[:, K.R_H], r2[:, K.R_H])
    if over.get("simulation.tolerance") == 1e-8:
        assert r1[:, K.R_IT].max() >= 1     # the iteration path was exercised


def test_kernel_matches_twin_through_tooth_separation():
    """An impact problem with separation (h switching) gives the same contact history."""
    m, k, v0 = 2.0, 5e4, 0.3
    setup = sdof_setup(constant_map(short_case().gear_pair(), k), m=m, c=4.0, dt=2e-5,
                       separation=True)
    z0 = np.zeros(6)
    z0[1] = -1e-3
    v = np.zeros(6)
    v[1] = v0
    s1, r1, _ = _run(setup, z0, v, 2000)
    s2, r2, _ = _run(setup, z0, v, 2000, python=True)
    assert s1 == s2 == 0
    np.testing.assert_array_equal(r1[:, K.R_H], r2[:, K.R_H])
    assert r1[:, K.R_H].min() == 0 and r1[:, K.R_H].max() == 1
    np.testing.assert_allclose(r1[:, K.R_Z + 1], r2[:, K.R_Z + 1], rtol=0, atol=1e-15)


def test_undamped_sdof_period_error_and_no_decay():
    """Average acceleration: no amplitude decay; numerical frequency (2/dt) atan(w dt/2), i.e.
    period error (w dt)^2/12 to leading order (docs/verification/dynamics.md, integration checks)."""
    m, k = 1.5, 6e3
    w = math.sqrt(k / m)
    for wdt in (0.1, 0.3):
        dt = wdt / w
        setup = sdof_setup(constant_map(short_case().gear_pair(), k), m=m, dt=dt)
        z0 = np.zeros(6)
        z0[1] = 1e-3
        n = int(40 * 2 * math.pi / wdt)
        status, rec, _ = _run(setup, z0, None, n)
        assert status == 0
        y, v = rec[:, K.R_Z + 1], rec[:, K.R_V + 1]
        energy = 0.5 * k * y ** 2 + 0.5 * m * v ** 2
        assert np.ptp(energy) / energy[0] < 1e-12              # exactly conservative
        # period from the upward zero crossings (linear interpolation is plenty here: we fit
        # the phase over 40 periods)
        t = np.arange(y.size) * dt
        i = np.nonzero((y[:-1] < 0) & (y[1:] >= 0))[0]
        tc = t[i] - y[i] * dt / (y[i + 1] - y[i])
        # exact discrete solution is y_n = cos(n wbar dt): fit wbar from the phase instead
        wbar = 2 / dt * math.atan(wdt / 2)
        np.testing.assert_allclose(y, 1e-3 * np.cos(wbar * t), atol=1e-15)
        period_err = (np.polyfit(np.arange(tc.size), tc, 1)[0] - 2 * math.pi / w) \
            / (2 * math.pi / w)
        assert period_err == pytest.approx(wdt ** 2 / 12, rel=0.05)


def test_damped_sdof_against_closed_form_second_order():
    """m y'' + c y' + k y = F from rest at y = 0: closed form vs Newmark; order 2 +/- 0.1."""
    m, k, c, F = 0.7, 1e6, 83.7, 150.0
    wn = math.sqrt(k / m)
    zeta = c / (2 * math.sqrt(k * m))
    wd = wn * math.sqrt(1 - zeta ** 2)
    T = 0.02
    errs = []
    dts = (2e-5, 1e-5, 5e-6)
    for dt in dts:
        setup = sdof_setup(constant_map(short_case().gear_pair(), k), m=m, c=c, dt=dt, force=F)
        n = int(round(T / dt))
        status, rec, _ = _run(setup, np.zeros(6), None, n)
        t = np.arange(n + 1) * dt
        ys = F / k
        exact = ys * (1 - np.exp(-zeta * wn * t) * (np.cos(wd * t)
                                                     + zeta * wn / wd * np.sin(wd * t)))
        errs.append(np.abs(rec[:, K.R_Z + 1] - exact).max())
    orders = np.log2(np.array(errs[:-1]) / np.array(errs[1:]))
    assert np.all(np.abs(orders - 2) < 0.1), orders
    assert errs[1] < 2e-3 * F / k


@pytest.mark.parametrize("window", ["point", "step"])
@pytest.mark.parametrize("k2_over_k1, stable", [(1.6, True), (3.2, False)])
def test_square_wave_parametric_oscillator(k2_over_k1, stable, window):
    """Square-wave k(t) (k1 for 40 % of the period, k2 for 60 %) against the exact product of
    per-segment transfer matrices (docs/verification/dynamics.md, integration checks), in a stable
    and an unstable Floquet case.

    The switches sit a quarter step past a grid point, so every switch commits the same local
    error. Sampled at a point (``stiffness_window="point"``) the steps cap the scheme at first
    order, observed 1.0 +/- 0.1; averaged over each step's rotation (``"step"``, the default,
    :func:`geardyn.stiffness.map.lookup_box`) a switch inside a step enters with the right
    fraction of the step and the scheme keeps its second order, observed 2.0 +/- 0.1. The
    unstable case grows per period by the exact Floquet multiplier."""
    from geardyn.stiffness.map import MapArrays

    m, speed, tm = 1.0, 100.0, 0.25
    T = tm / speed
    # near the principal parametric resonance (2 w = mesh frequency) when unstable
    k1 = 0.55 * (math.pi / T * (1.0 if stable else 0.93)) ** 2 * m
    k2 = k2_over_k1 * k1
    arr = MapArrays(0.0, 0.0, np.array([0.0]), np.array([0.4 * tm]), tm, 1, 2,
                    np.array([[k1, k1, k2, k2]]))
    delta = 0.25
    n_per = 30
    errs, spps = [], np.array([400, 800, 1600, 3200])
    for spp in spps:
        dt = T / spp
        ta, tb = 0.4 * T - delta * dt, 0.6 * T
        A1 = expm(np.array([[0.0, 1.0], [-k1 / m, 0.0]]) * ta)
        A2 = expm(np.array([[0.0, 1.0], [-k1 / m, 0.0]]) * delta * dt)
        B = expm(np.array([[0.0, 1.0], [-k2 / m, 0.0]]) * tb)
        mono = A2 @ B @ A1            # one period from theta = delta * speed * dt (zone A)
        mult = np.abs(np.linalg.eigvals(mono)).max()
        assert (mult < 1 + 1e-9) == stable
        exact = [np.array([1e-3, 0.0])]
        for _ in range(n_per):
            exact.append(mono @ exact[-1])
        exact = np.array(exact)
        setup = sdof_setup(arr, m=m, dt=dt, speed=speed, stiffness_window=window)
        z0 = np.zeros(6)
        z0[1] = 1e-3
        z0[2] = delta * speed * dt
        status, rec, _ = _run(setup, z0, None, n_per * spp)
        assert status == 0
        x_num = rec[::spp, K.R_Z + 1][: n_per + 1]
        v_num = rec[::spp, K.R_V + 1][: n_per + 1]
        errs.append(np.abs(x_num - exact[:, 0]).max() / np.abs(exact[:, 0]).max())
        if not stable and spp == spps[-1]:
            amp = np.hypot(x_num, v_num / math.sqrt(k1 / m))
            rate = np.exp(np.polyfit(np.arange(n_per // 2, n_per + 1),
                                     np.log(amp[n_per // 2:]), 1)[0])
            assert rate == pytest.approx(mult, rel=1e-3)
    orders = np.log2(np.array(errs[:-1]) / np.array(errs[1:]))
    order = 1.0 if window == "point" else 2.0
    assert np.all(np.abs(orders - order) < 0.1), (errs, orders)
    assert errs[-1] < (5e-3 if window == "point" else 2e-5)


def test_tooth_separation_impact_closed_form():
    """A mass meets the mesh spring at speed v0 (separation on, eq. 15): it stays in contact
    for half a period pi sqrt(m/k) and leaves with -v0 (undamped)."""
    m, k, v0 = 2.0, 5e4, 0.3
    w = math.sqrt(k / m)
    dt = 1e-6
    setup = sdof_setup(constant_map(short_case().gear_pair(), k), m=m, dt=dt, separation=True)
    z0 = np.zeros(6)
    z0[1] = -1e-3
    v = np.zeros(6)
    v[1] = v0
    t_hit = 1e-3 / v0
    n = int((t_hit + math.pi / w + 2e-3) / dt)
    status, rec, _ = _run(setup, z0, v, n)
    h = rec[:, K.R_H]
    on = np.nonzero(h)[0]
    assert on[0] * dt == pytest.approx(t_hit, abs=2 * dt)
    assert (on[-1] - on[0]) * dt == pytest.approx(math.pi / w, abs=3 * dt)
    assert np.all(np.diff(on) == 1)                 # one contact, no chatter
    assert rec[-1, K.R_V + 1] == pytest.approx(-v0, rel=1e-4)
    assert rec[-1, K.R_N] == 0.0


def test_hht_spectral_radius():
    """HHT-alpha damps a mode by the spectral radius of its amplification matrix (Hilber,
    Hughes & Taylor 1977), computed here independently from the three defining equations."""
    m, k, al = 1.0, 1.0e4, -0.2
    w = math.sqrt(k / m)
    beta, gam = (1 - al) ** 2 / 4, 0.5 - al
    for wdt in (0.5, 3.0):
        dt = wdt / w
        # unknowns (x1, v1, a1) from (x0, v0, a0): m a1 + (1+al) k x1 - al k x0 = 0 and Newmark
        L = np.array([[1, 0, -beta * dt ** 2], [0, 1, -gam * dt], [(1 + al) * k, 0, m]])
        R = np.array([[1, dt, (0.5 - beta) * dt ** 2], [0, 1, (1 - gam) * dt], [al * k, 0, 0]])
        rho = np.abs(np.linalg.eigvals(np.linalg.solve(L, R))).max()
        setup = sdof_setup(constant_map(short_case().gear_pair(), k), m=m, dt=dt,
                           integrator="hht", hht_alpha=al)
        z0 = np.zeros(6)
        z0[1] = 1.0
        status, rec, _ = _run(setup, z0, None, 200)
        y, v = rec[:, K.R_Z + 1], rec[:, K.R_V + 1]
        amp = np.hypot(y, v / w)
        rate = np.exp(np.polyfit(np.arange(100, 201), np.log(amp[100:]), 1)[0])
        assert rate == pytest.approx(rho, rel=1e-3)
        assert rho < 1


def test_failure_codes_and_state():
    """A negative stiffness diverges: the kernel stops with a runaway code, the failing state
    and its time; NaN input is caught as non-finite."""
    pair = short_case().gear_pair()
    setup = sdof_setup(constant_map(pair, 1e4), m=1.0, dt=1e-3, p_lim=1.0)
    setup.K0[1, 1] = -5e4            # net negative stiffness: exponential growth
    setup.SK[:] = setup.Sinv @ setup.K0
    z0 = np.zeros(6)
    z0[1] = 1e-6
    st, ist = initial_state(setup, z0)
    status, j, fail = run_steps(setup, st, ist, 10_000)
    assert status == K.MESH_RUNAWAY
    assert abs(fail[2]) > 1.0 and fail[0] == pytest.approx(ist[0] * 1e-3)
    assert abs(st[K.S_Z + 1]) > 1.0 and np.isfinite(st[:K.S_N + 1]).all()
    setup2 = sdof_setup(constant_map(pair, 1e4), m=1.0, dt=1e-3)
    st, ist = initial_state(setup2, z0)
    st[K.S_V + 3] = np.nan
    status, j, fail = run_steps(setup2, st, ist, 10)
    assert status == K.NONFINITE and fail[0] == pytest.approx(1e-3)


def test_no_precision_decay_after_a_long_run():
    """The kernel integrates deviations from the rigid rotation, so a step taken after 100 s of
    simulated time (theta_p ~ 1.1e4 rad) is as precise as one at t = 0: the same motion started
    at step 1e7 (pinion phase given by the step count) and at step 0 (the same phase added to the
    deviations as a rigid rotation) agree to rounding."""
    case = short_case()
    smap = geometric_map(case.gear_pair())
    setup, static = _case_setup(case, smap, "II")
    n0 = 10_000_000
    period = smap.period
    phase = float(np.fmod(n0 * setup.fp[K.FP_HSTEP], period))
    z_late = static.z.copy()
    dyn = DynamicModel.from_case(case, smap)
    z_early = static.z + phase * dyn.reference_direction      # the same rigid rotation
    out_a = np.full((601, K.N_REC), np.nan)
    out_b = np.full((601, K.N_REC), np.nan)
    st, ist = initial_state(setup, z_late, step=n0)
    assert run_steps(setup, st, ist, 600, rec_start=n0, out=out_a)[0] == 0
    st, ist = initial_state(setup, z_early, step=0)
    assert run_steps(setup, st, ist, 600, out=out_b)[0] == 0
    for col in (K.R_Z + 1, K.R_Z + 3, K.R_N, K.R_K, K.R_DD):
        a, b = out_a[:, col], out_b[:, col]
        assert np.abs(a - b).max() <= 1e-9 * np.abs(b).max(), col
    p_a = out_a[:, K.R_Z:K.R_Z + 6] @ setup.g
    p_b = out_b[:, K.R_Z:K.R_Z + 6] @ setup.g
    assert np.abs(p_a - p_b).max() < 1e-9 * np.abs(p_b).max()
