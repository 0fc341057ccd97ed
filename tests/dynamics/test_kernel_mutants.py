"""The time-step kernel *and* its Python twin, each against independent oracles (issue 20,
docs/mutation.md "Dynamics kernel").

``tests/dynamics/test_kernel.py`` compares the compiled kernel with the twin step by step, which
checks the kernel but not the twin: a bug in the twin would only show as a disagreement with no
way of telling which side is wrong. Every oracle test here is therefore parametrised over both
engines (``kernel`` = :func:`geardyn.dynamics._kernel.advance`, ``twin`` =
:func:`~geardyn.dynamics._kernel.advance_python`) and compares with something computed without
either of them:

* closed forms: the exact discrete solution of the average-acceleration rule for a linear
  oscillator (a rotation by ``2 atan(w dt / 2)`` in the ``(p, v/w)`` plane, energy conserved
  exactly), damped step responses, a free rotor under a torque ripple, the rebound of an impact;
* observed orders of convergence under step halving (2 for Newmark/HHT with the predictor
  evaluation, 1 with the paper's start-of-step evaluation) against those closed forms, against
  scipy's ``solve_ivp`` of the scalar law equations and against DOP853 on the full 6-DOF model
  (the independent right-hand side of ``_support.dop853_reference``);
* the HHT-alpha spectral radius computed from the three defining equations;
* the tooth-error pair search of the kernel and the twin against the vectorised
  :meth:`geardyn.modifications.ToothModifications.pair_errors` and ``shares``;
* step-by-step audits of the stated discrete equations: eq. 4, eq. 14 with the map read at the
  predictor angle (or averaged over the step's rotation, by quadrature), eq. 15 per pair with
  the free deflection measured by the same step without mesh, the equations of motion, and the
  step as the implicit trapezoidal rule on a load law;
* bookkeeping that follows from the definition of a time-stepping scheme (a run in chunks equals
  one run; records at ``rec_start + i decim``; failure codes with the failing state).

Tests whose name contains ``twin_equality`` compare the two engines directly (legitimate for the
kernel, and they exercise branches cheaply); the mutation run of the twin deselects them.
"""

from __future__ import annotations

import math

import numpy as np
import pytest
from scipy.integrate import solve_ivp

from geardyn.dynamics import DynamicModel, initial_state, make_setup, run_steps
from geardyn.dynamics import _kernel as K
from geardyn.dynamics.model import TorqueLaw
from geardyn.stiffness.map import MapArrays, lookup_reference

from ._support import constant_map, dop853_reference, sdof_setup, short_case, triangle_map

ENGINES = ["kernel", "twin"]


@pytest.fixture(scope="module")
def pair():
    return short_case().gear_pair()


def _run(setup, z0, v0, n, engine, **kw):
    st, ist = initial_state(setup, z0, v0)
    out = np.full((n + 1, K.N_REC), np.nan)
    status, j, fail = run_steps(setup, st, ist, n, out=out, python=engine == "twin", **kw)
    return status, out[:j], fail, st, ist


def _order(errs):
    return np.log2(np.array(errs[:-1]) / np.array(errs[1:]))


# --------------------------------------------------------------------------- linear closed forms
@pytest.mark.parametrize("engine", ENGINES)
def test_two_mass_mesh_oscillator_is_the_exact_discrete_rotation(engine, pair):
    """Two masses on DOFs 1 and 3 joined by the mesh spring (``g = e1 - e3``), plus a spring
    ``K0`` to ground on DOF 1 that is *zero* here so the relative motion is a free oscillator of
    the reduced mass: average acceleration maps ``(p, p'/w)`` by an exact rotation through
    ``phi = 2 atan(w dt/2)``; the centre of mass drifts at its initial speed exactly."""
    m1, m3, k = 1.5, 0.6, 4.0e4
    mu = m1 * m3 / (m1 + m3)
    w = math.sqrt(k / mu)
    dt = 0.25 / w
    M = np.diag([1.0, m1, 1.0, m3, 1.0, 1.0])
    Z = np.zeros((6, 6))
    g = np.array([0.0, 1.0, 0.0, -1.0, 0.0, 0.0])
    setup = make_setup(M, Z, Z, g, np.zeros(6), constant_map(pair, k), dt=dt, separation=False)
    z0 = np.zeros(6)
    z0[1], z0[3] = 2e-4, -1e-4
    v0 = np.zeros(6)
    v0[1], v0[3] = 0.05, 0.02
    n = 300
    status, rec, _, _, _ = _run(setup, z0, v0, n, engine)
    assert status == 0 and rec.shape[0] == n + 1
    phi = 2 * math.atan(w * dt / 2)
    p0, pd0 = z0[1] - z0[3], v0[1] - v0[3]
    nn = np.arange(n + 1)
    p_exact = p0 * np.cos(nn * phi) + pd0 / w * np.sin(nn * phi)
    pd_exact = -p0 * w * np.sin(nn * phi) + pd0 * np.cos(nn * phi)
    p = rec[:, K.R_Z + 1] - rec[:, K.R_Z + 3]
    pd = rec[:, K.R_V + 1] - rec[:, K.R_V + 3]
    np.testing.assert_allclose(p, p_exact, rtol=0, atol=1e-13 * abs(p0) + 1e-16)
    np.testing.assert_allclose(pd, pd_exact, rtol=0, atol=1e-12 * abs(pd0))
    vcm = (m1 * v0[1] + m3 * v0[3]) / (m1 + m3)
    ycm = (m1 * rec[:, K.R_Z + 1] + m3 * rec[:, K.R_Z + 3]) / (m1 + m3)
    ycm0 = (m1 * z0[1] + m3 * z0[3]) / (m1 + m3)
    np.testing.assert_allclose(ycm, ycm0 + vcm * nn * dt, rtol=0, atol=1e-15)
    # eq. 14: the recorded mesh force is k p, the recorded stiffness k, contact kept
    np.testing.assert_allclose(rec[:, K.R_N], k * p, rtol=1e-12, atol=0)
    assert np.all(rec[:, K.R_K] == k) and np.all(rec[:, K.R_H] == 1.0)
    # the untouched DOFs stay at rest
    for i in (0, 2, 4, 5):
        assert np.all(rec[:, K.R_Z + i] == 0.0) and np.all(rec[:, K.R_V + i] == 0.0)


def _step_response(engine, pair, dt, T, *, split, integrator="newmark", alpha=0.0):
    """``m y'' + c y' + k y = F`` from rest, with ``k`` and ``c`` either all in the mesh
    (``split=False``) or 30 % / 40 % of them in ``K0`` / ``C`` (``split=True``)."""
    m, k, c, F = 0.7, 1e6, 83.7, 150.0
    fk, fc = (0.3, 0.4) if split else (0.0, 0.0)
    M = np.diag([1.0, m, 1.0, 1.0, 1.0, 1.0])
    K0 = np.zeros((6, 6))
    C = np.zeros((6, 6))
    K0[1, 1], C[1, 1] = fk * k, fc * c
    g = np.array([0.0, 1.0, 0.0, 0.0, 0.0, 0.0])
    Q0 = np.zeros(6)
    Q0[1] = F
    setup = make_setup(M, K0, C, g, Q0, constant_map(pair, (1 - fk) * k), dt=dt,
                       q_mb=(1 - fc) * c, separation=False, integrator=integrator,
                       hht_alpha=alpha)
    n = int(round(T / dt))
    status, rec, _, _, _ = _run(setup, np.zeros(6), None, n, engine)
    assert status == 0
    t = np.arange(n + 1) * dt
    wn = math.sqrt(k / m)
    zeta = c / (2 * math.sqrt(k * m))
    wd = wn * math.sqrt(1 - zeta ** 2)
    exact = F / k * (1 - np.exp(-zeta * wn * t) * (np.cos(wd * t) + zeta * wn / wd
                                                    * np.sin(wd * t)))
    return np.abs(rec[:, K.R_Z + 1] - exact).max(), F / k, rec


@pytest.mark.parametrize("engine", ENGINES)
@pytest.mark.parametrize("integrator, alpha", [("newmark", 0.0), ("hht", -0.1)])
def test_damped_step_response_with_split_stiffness_and_damping_is_second_order(
        engine, integrator, alpha, pair):
    """Closed-form step response of a damped oscillator whose stiffness and damping are shared
    between ``K0``/``C`` and the mesh (``k_mb``, ``q_mb``): observed order 2 +/- 0.1 for
    Newmark and HHT-alpha, and the error at the finest step below 1e-3 of the static
    deflection."""
    errs = []
    for dt in (4e-5, 2e-5, 1e-5):
        err, ystat, _ = _step_response(engine, pair, dt, 0.004, split=True,
                                       integrator=integrator, alpha=alpha)
        errs.append(err)
    assert np.all(np.abs(_order(errs) - 2) < 0.1), (errs, _order(errs))
    assert errs[-1] < 1e-3 * ystat


@pytest.mark.parametrize("engine", ENGINES)
def test_hht_decay_about_the_static_deflection(engine, pair):
    """HHT-alpha with a constant force: the motion decays towards ``F/k`` (so the constant
    forcing enters the alpha-weighted old residual correctly) at the spectral radius of the
    amplification matrix computed from the three defining equations; ``k`` is shared between
    ``K0`` and the mesh."""
    m, k, F, al = 1.0, 1.0e4, 30.0, -0.25
    w = math.sqrt(k / m)
    beta, gam = (1 - al) ** 2 / 4, 0.5 - al
    dt = 1.5 / w
    M = np.diag([1.0, m, 1.0, 1.0, 1.0, 1.0])
    K0 = np.zeros((6, 6))
    K0[1, 1] = 0.35 * k
    C = np.zeros((6, 6))
    g = np.array([0.0, 1.0, 0.0, 0.0, 0.0, 0.0])
    Q0 = np.zeros(6)
    Q0[1] = F
    setup = make_setup(M, K0, C, g, Q0, constant_map(pair, 0.65 * k), dt=dt, separation=False,
                       integrator="hht", hht_alpha=al)
    L = np.array([[1, 0, -beta * dt ** 2], [0, 1, -gam * dt], [(1 + al) * k, 0, m]])
    R = np.array([[1, dt, (0.5 - beta) * dt ** 2], [0, 1, (1 - gam) * dt], [al * k, 0, 0]])
    rho = np.abs(np.linalg.eigvals(np.linalg.solve(L, R))).max()
    status, rec, _, _, _ = _run(setup, np.zeros(6), None, 60, engine)
    assert status == 0
    y, v = rec[:, K.R_Z + 1] - F / k, rec[:, K.R_V + 1]
    amp = np.hypot(y, v / w)
    rate = np.exp(np.polyfit(np.arange(20, 61), np.log(amp[20:]), 1)[0])
    assert rate == pytest.approx(rho, rel=1e-3)
    assert rho ** 40 < 0.5         # a visible decay over the fitted steps


@pytest.mark.parametrize("engine", ENGINES)
def test_impact_with_separation_closed_form(engine, pair):
    """A mass meets the mesh spring at ``v0`` (eq. 15): contact for ``pi sqrt(m/k)``, rebound
    at ``-v0`` (average acceleration conserves the energy of the linear contact; the entry and
    exit at step boundaries cost O((w dt)^2)), no force while separated."""
    m, k, v0 = 2.0, 5e4, 0.3
    w = math.sqrt(k / m)
    dt = 2e-6
    setup = sdof_setup(constant_map(pair, k), m=m, dt=dt, separation=True)
    z0 = np.zeros(6)
    z0[1] = -2e-4
    v = np.zeros(6)
    v[1] = v0
    t_hit = 2e-4 / v0
    n = int((t_hit + math.pi / w + 5e-4) / dt)
    status, rec, _, _, _ = _run(setup, z0, v, n, engine)
    assert status == 0
    h = rec[:, K.R_H]
    on = np.nonzero(h)[0]
    assert on[0] * dt == pytest.approx(t_hit, abs=2 * dt)
    assert (on[-1] - on[0]) * dt == pytest.approx(math.pi / w, abs=3 * dt)
    assert np.all(np.diff(on) == 1)
    assert rec[-1, K.R_V + 1] == pytest.approx(-v0, rel=1e-4)
    off = h == 0
    assert np.all(rec[off, K.R_N] == 0.0) and np.all(rec[on, K.R_N] > 0.0)
    # while separated the mass flies freely: y grows linearly at its speed
    before = np.arange(on[0])
    np.testing.assert_allclose(rec[before, K.R_Z + 1], z0[1] + v0 * before * dt, rtol=0,
                               atol=1e-15)


@pytest.mark.parametrize("engine", ENGINES)
@pytest.mark.parametrize("integrator, alpha", [("newmark", 0.0), ("hht", -0.1)])
def test_contact_flag_is_eq_15_at_the_end_of_each_step(engine, integrator, alpha, pair):
    """Eq. 15 at ``t_{n+1}``: with an undamped mesh the contact solution has the sign of the
    free deflection (``p = p_free / (1 + (1+alpha) beta dt^2 k g^T S^-1 g)``), so every record
    must have ``h = 1`` exactly when ``p >= 0``, and no force when ``h = 0``. A mass on a stiff
    damped support (``K0``, ``C``; ``w dt`` about 1, so that the free solve really depends on
    them) pushed in and out of contact by a force and its initial speed."""
    m, ks, cs, km, F = 0.5, 2.0e5, 30.0, 3.0e5, 40.0
    dt = 1.0 / math.sqrt((ks + km) / m)
    M = np.diag([1.0, m, 1.0, 1.0, 1.0, 1.0])
    K0 = np.zeros((6, 6))
    C = np.zeros((6, 6))
    K0[1, 1], C[1, 1] = ks, cs
    g = np.array([0.0, 1.0, 0.0, 0.0, 0.0, 0.0])
    Q0 = np.zeros(6)
    Q0[1] = F           # equilibrium without contact at F/ks = 2e-4 m > 0: inside contact
    setup = make_setup(M, K0, C, g, Q0, constant_map(pair, km), dt=dt, separation=True,
                       integrator=integrator, hht_alpha=alpha)
    z0 = np.zeros(6)
    z0[1] = -1.5e-3
    v0 = np.zeros(6)
    v0[1] = -0.5
    status, rec, _, _, _ = _run(setup, z0, v0, 400, engine)
    assert status == 0
    p, h, N = rec[1:, K.R_Z + 1], rec[1:, K.R_H], rec[1:, K.R_N]
    np.testing.assert_array_equal(h == 1.0, p >= 0.0)
    assert np.all(N[h == 0] == 0.0)
    np.testing.assert_allclose(N[h == 1], km * p[h == 1], rtol=1e-12)
    switches = np.count_nonzero(np.diff(h))
    assert switches >= 6, switches      # several entries and exits were decided


# --------------------------------------------------------------------------- load laws
def _law_setup(pair, dt, in_law, out_law, w_in, w_out, integrator="newmark", alpha=0.0):
    """DOF 0 driven by ``in_law`` (inertia 0.02 kg m^2) and DOF 5 braked by ``out_law``
    (0.05 kg m^2), uncoupled; linearised at ``w_in``, ``w_out`` as the model does."""
    I0, I5 = 0.02, 0.05
    M = np.diag([I0, 1.0, 1.0, 1.0, 1.0, I5])
    C = np.zeros((6, 6))
    C[0, 0] = -in_law.slope(w_in)
    C[5, 5] = out_law.slope(w_out)
    Q0 = np.zeros(6)
    Q0[0] = float(in_law.torque(w_in))
    Q0[5] = -float(out_law.torque(w_out))
    g = np.array([0.0, 1.0, 0.0, 0.0, 0.0, 0.0])
    setup = make_setup(M, np.zeros((6, 6)), C, g, Q0, constant_map(pair, 1e5), dt=dt,
                       separation=False, input_law=in_law, output_law=out_law,
                       input_speed=w_in, output_speed=w_out, rtol=1e-12,
                       integrator=integrator, hht_alpha=alpha)
    return setup, I0, I5


LAWS = {
    "induction-linear": (TorqueLaw("induction", synchronous_speed=130.0, breakdown_torque=40.0,
                                   breakdown_slip=0.2),
                         TorqueLaw("linear", coefficient=0.2), 115.0, 90.0),
    "constant-quadratic": (TorqueLaw("constant", coefficient=12.0),
                           TorqueLaw("quadratic", coefficient=2.0e-3), 115.0, 90.0),
    "table-induction": (TorqueLaw("table", speeds=np.array([80.0, 100.0, 120.0, 140.0]),
                                  torques=np.array([30.0, 22.0, 9.0, 1.0])),
                        TorqueLaw("induction", synchronous_speed=150.0, breakdown_torque=25.0,
                                  breakdown_slip=0.3), 110.0, 90.0),
    "induction-quadratic": (TorqueLaw("induction", synchronous_speed=130.0,
                                      breakdown_torque=40.0, breakdown_slip=0.2),
                            TorqueLaw("quadratic", coefficient=2.0e-3), 115.0, 90.0),
    "table-table": (TorqueLaw("table", speeds=np.array([80.0, 100.0, 120.0, 140.0]),
                              torques=np.array([30.0, 22.0, 9.0, 1.0])),
                    TorqueLaw("table", speeds=np.array([60.0, 85.0, 95.0, 130.0]),
                              torques=np.array([4.0, 9.0, 19.0, 25.0])), 110.0, 90.0),
}


@pytest.mark.parametrize("engine", ENGINES)
@pytest.mark.parametrize("laws", sorted(LAWS))
@pytest.mark.parametrize("integrator, alpha", [("newmark", 0.0), ("hht", -0.15)])
def test_nonlinear_laws_against_solve_ivp(engine, laws, integrator, alpha, pair):
    """Spin-up of a rotor on a nonlinear input law and spin-down of one on a nonlinear output
    law, started 8 rad/s and -6 rad/s off the linearisation speeds: the speeds against scipy's
    ``solve_ivp`` of ``I w' = T_in(w)`` and ``I w' = -T_out(w)`` (rtol 1e-11), error at least
    3x smaller for each halving of the step (order 2 +/- 0.15 for the smooth laws, where no
    table kink is crossed), and below 2e-5 rad/s at the finest step; the other DOFs stay at
    rest."""
    in_law, out_law, w_in, w_out = LAWS[laws]
    T = 0.02
    errs = []
    for dt in (2e-4, 1e-4, 5e-5):
        setup, I0, I5 = _law_setup(pair, dt, in_law, out_law, w_in, w_out, integrator, alpha)
        v0 = np.zeros(6)
        v0[0], v0[5] = 8.0, -6.0
        n = int(round(T / dt))
        status, rec, _, _, _ = _run(setup, np.zeros(6), v0, n, engine)
        assert status == 0
        t = np.arange(n + 1) * dt
        ref_in = solve_ivp(lambda _t, y, i0=I0: [float(in_law.torque(y[0])) / i0], (0, T),
                           [w_in + 8.0], t_eval=t, rtol=1e-11, atol=1e-12, method="DOP853").y[0]
        ref_out = solve_ivp(lambda _t, y, i5=I5: [-float(out_law.torque(y[0])) / i5], (0, T),
                            [w_out - 6.0], t_eval=t, rtol=1e-11, atol=1e-12,
                            method="DOP853").y[0]
        for i in (1, 2, 3, 4):          # the law torques act on DOFs 0 and 5 only
            assert np.all(rec[:, K.R_Z + i] == 0.0), i
        e0 = np.abs(rec[:, K.R_V] + w_in - ref_in).max()
        e5 = np.abs(rec[:, K.R_V + 5] + w_out - ref_out).max()
        errs.append((e0, e5))
        assert abs(ref_in[-1] - ref_in[0]) > 1.0 and abs(ref_out[-1] - ref_out[0]) > 1.0
    errs = np.array(errs)
    for col in range(2):
        ratios = errs[:-1, col] / errs[1:, col]
        kind = (in_law, out_law)[col].kind
        if kind == "constant":      # constant torque: uniform acceleration, exact
            assert errs[:, col].max() < 1e-9, errs
            continue
        assert np.all(ratios > 3.0), errs
        if kind != "table":         # smooth law: order 2
            assert np.all(np.abs(np.log2(ratios) - 2) < 0.15), errs
    assert errs[-1].max() < 2e-5, errs


@pytest.mark.parametrize("engine", ENGINES)
@pytest.mark.parametrize("ripple", [0.0, 1.5])
def test_law_steps_are_the_trapezoidal_rule(engine, ripple, pair):
    """Average acceleration on ``I w' = T(w) + A sin(n w_ref t)`` is the implicit trapezoidal
    rule ``w1 = w0 + dt/2 (f(w0, t0) + f(w1, t1))``, solved here step by step independently: in
    closed form for the quadratic output law (a quadratic equation in ``w1``) and by
    ``brentq`` for the Kloss input law with a torque ripple; the kernel's iterated law remainder
    must reproduce it to 1e-10 of the speed change (rtol 1e-13), however it predicts it."""
    from scipy.optimize import brentq

    in_law = TorqueLaw("induction", synchronous_speed=130.0, breakdown_torque=40.0,
                       breakdown_slip=0.2)
    out_law = TorqueLaw("quadratic", coefficient=2.0e-3)
    w_in, w_out, dt, n, order = 115.0, 90.0, 5e-4, 60, 2.0
    setup, I0, I5 = _law_setup(pair, dt, in_law, out_law, w_in, w_out)
    setup.fp[K.FP_RTOL] = 1e-13
    setup.fp[K.FP_HSTEP] = w_in * dt
    setup.fp[K.FP_RIP_AMP], setup.fp[K.FP_RIP_ORDER] = ripple, order
    v0 = np.zeros(6)
    v0[0], v0[5] = 8.0, -6.0
    status, rec, _, _, _ = _run(setup, np.zeros(6), v0, n, engine)
    assert status == 0

    def f_in(w, t):
        return (float(in_law.torque(w)) + ripple * math.sin(order * w_in * t)) / I0

    w = [w_in + 8.0]
    for i in range(n):
        t0, t1, w0 = i * dt, (i + 1) * dt, w[-1]
        g0 = w0 + 0.5 * dt * f_in(w0, t0)
        w.append(brentq(lambda x, g0=g0, t1=t1: x - g0 - 0.5 * dt * f_in(x, t1), w0 - 50.0,
                        w0 + 50.0, xtol=1e-14, rtol=1e-15))
    a = out_law.coefficient * dt / (2 * I5)
    u = [w_out - 6.0]
    for _ in range(n):          # a u1^2 + u1 - (u0 - a u0^2) = 0, u > 0
        b = u[-1] - a * u[-1] ** 2
        u.append((-1.0 + math.sqrt(1.0 + 4.0 * a * b)) / (2.0 * a))
    np.testing.assert_allclose(rec[:, K.R_V] + w_in, w, rtol=0,
                               atol=1e-10 * abs(w[-1] - w[0]))
    np.testing.assert_allclose(rec[:, K.R_V + 5] + w_out, u, rtol=0,
                               atol=1e-10 * abs(u[-1] - u[0]))


# --------------------------------------------------------------------------- ripple and drive
@pytest.mark.parametrize("engine", ENGINES)
@pytest.mark.parametrize("integrator, alpha", [("newmark", 0.0), ("hht", -0.2)])
def test_torque_ripple_on_a_free_rotor_closed_form(engine, integrator, alpha, pair):
    """A free rotor (inertia I) under ``A sin(n w t + phi)`` from rest:
    ``z = A/(I W^2) [sin phi - sin(W t + phi) + W t cos phi]``, ``W = n w``; order 2."""
    I0, A, order, phase, speed = 0.03, 1.0, 3.0, 0.7, 40.0   # A = 1 N m exactly
    W = order * speed
    errs = []
    T = 0.06
    for dt in (4e-4, 2e-4, 1e-4):
        M = np.diag([I0, 1.0, 1.0, 1.0, 1.0, 1.0])
        Z = np.zeros((6, 6))
        g = np.array([0.0, 1.0, 0.0, 0.0, 0.0, 0.0])
        setup = make_setup(M, Z, Z, g, np.zeros(6), constant_map(pair, 1e5), dt=dt,
                           speed=speed, separation=False, ripple=(A, order, phase),
                           integrator=integrator, hht_alpha=alpha)
        n = int(round(T / dt))
        status, rec, _, _, _ = _run(setup, np.zeros(6), None, n, engine)
        assert status == 0
        t = np.arange(n + 1) * dt
        exact = A / (I0 * W ** 2) * (math.sin(phase) - np.sin(W * t + phase)
                                    + W * t * math.cos(phase))
        vex = A / (I0 * W) * (math.cos(phase) - np.cos(W * t + phase))
        errs.append(max(np.abs(rec[:, K.R_Z] - exact).max() / np.abs(exact).max(),
                        np.abs(rec[:, K.R_V] - vex).max() / np.abs(vex).max()))
        _, _, _, st, ist = _run(setup, np.zeros(6), None, 7, engine)
        # the state carries the ripple torque of its step, A sin(n w (7 dt) + phi)
        assert st[K.S_RIP] == pytest.approx(A * math.sin(W * 7 * dt + phase), rel=1e-12)
    assert np.all(np.abs(_order(errs) - 2) < 0.15), (errs, _order(errs))
    assert errs[-1] < 2e-3


@pytest.mark.parametrize("engine", ENGINES)
@pytest.mark.parametrize("ripple", [0.0, 0.4])
def test_speed_controlled_drive_follows_its_ramp(engine, ripple, pair):
    """A drive ``c (w_target(t) - w_ref)`` on a free rotor whose speed deviation feeds back
    (``c`` in ``C``), alone and with a torque ripple on top:
    ``I v' = c (w_target(t) - w_ref - v) + A sin(n w t)``, a first-order lag of the piecewise
    linear profile; against ``solve_ivp`` piece by piece (the profile's kinks on the grid),
    order 2 (> 1.8 for each halving). The gain is 1 N m s/rad exactly."""
    I0, c, w_ref, speed, order = 0.02, 1.0, 100.0, 30.0, 2.0
    times, speeds = np.array([0.0, 0.01, 0.03, 0.05]), np.array([100.0, 100.0, 112.0, 106.0])
    T = 0.06
    ts = np.concatenate([times, [T]])

    def rhs(t, y):
        return [(c * (np.interp(t, times, speeds) - w_ref - y[0])
                 + ripple * math.sin(order * speed * t)) / I0]

    errs = []
    for dt in (4e-4, 2e-4, 1e-4):
        M = np.diag([I0, 1.0, 1.0, 1.0, 1.0, 1.0])
        C = np.zeros((6, 6))
        C[0, 0] = c
        Z = np.zeros((6, 6))
        g = np.array([0.0, 1.0, 0.0, 0.0, 0.0, 0.0])
        setup = make_setup(M, Z, C, g, np.zeros(6), constant_map(pair, 1e5), dt=dt,
                           separation=False, drive=(c, w_ref, times, speeds), speed=speed,
                           ripple=(ripple, order, 0.0))
        n = int(round(T / dt))
        status, rec, _, _, _ = _run(setup, np.zeros(6), None, n, engine)
        assert status == 0
        t = np.arange(n + 1) * dt
        ref = np.empty(n + 1)
        y = [0.0]
        for a, b in zip(ts[:-1], ts[1:], strict=True):
            sel = (t >= a - 1e-12) & (t <= b + 1e-12)
            sol = solve_ivp(rhs, (a, b), y, t_eval=np.clip(t[sel], a, b), rtol=1e-11,
                            atol=1e-13, method="DOP853")
            ref[sel] = sol.y[0]
            y = [solve_ivp(rhs, (a, b), y, rtol=1e-11, atol=1e-13, method="DOP853").y[0][-1]]
        errs.append(np.abs(rec[:, K.R_V] - ref).max())
        assert np.abs(ref).max() > 5.0
    assert np.all(_order(errs) > 1.8), (errs, _order(errs))


# --------------------------------------------------------------------------- full 6-DOF model
DOP_DTS = (2e-5, 1e-5, 5e-6)


@pytest.mark.parametrize("engine", ENGINES)
@pytest.mark.parametrize("which, evaluation, integrator, want", [
    ("II", "predictor", "newmark", 2.0),
    ("II", "start", "newmark", 1.0),
    ("I", "predictor", "hht", 2.0),
])
def test_six_dof_model_against_dop853(engine, which, evaluation, integrator, want):
    """The paper's 6-DOF model on a smooth map with kinks at the handovers (``triangle_map``),
    started off equilibrium, over 6 ms (about two and a half mesh periods): mesh deflection and
    bearing displacements against DOP853 (rtol 1e-12) with observed order 2 (predictor), resp. 1
    (start-of-step evaluation), +/- 0.15."""
    case = short_case(**{"simulation.tolerance": 1e-13, "simulation.rtol": 1e-13,
                         "simulation.stiffness_evaluation": evaluation,
                         "simulation.integrator": integrator, "simulation.hht_alpha": -0.05})
    smap = triangle_map(case.gear_pair())
    from geardyn.dynamics import static_equilibrium
    from geardyn.dynamics.newmark import _setup_for_case

    dyn = DynamicModel.from_case(case, smap)
    static = static_equilibrium(dyn, smap, which=which)
    T = 0.006
    # off equilibrium (a visible bearing and mesh transient) and a fifth of a mesh cycle
    # further on (a rigid rotation: the map is read at the phase the DOFs carry)
    z0 = static.z + 0.2 * (2 * math.pi / 23) * dyn.reference_direction
    z0[1] += 2e-6
    v0 = np.zeros(6)
    v0[2] = 0.05
    errs = []
    t_eval = np.arange(int(round(T / DOP_DTS[0])) + 1) * DOP_DTS[0]
    y0 = np.concatenate([z0, v0 + dyn.speed * dyn.reference_direction])
    ref = dop853_reference(case, smap, which, y0, t_eval, rtol=1e-12)
    g = dyn.g
    p_ref = g @ ref[:6]
    for dt in DOP_DTS:
        setup = _setup_for_case(case.with_overrides({"simulation.dt": dt}), dyn, smap, which,
                                static)
        n = int(round(T / dt))
        status, rec, _, _, _ = _run(setup, z0, v0, n, engine)
        assert status == 0
        step = int(round(DOP_DTS[0] / dt))
        z = rec[::step, K.R_Z:K.R_Z + 6]
        e_p = np.abs(z @ g - p_ref).max() / np.abs(p_ref).max()
        e_y = np.abs(z[:, [1, 3]] - ref[[1, 3]].T).max() / np.abs(ref[[1, 3]]).max()
        errs.append(max(e_p, e_y))
        if which == "II":   # eq. 4 on the recorded state
            dd = np.hypot(dyn.pair.base_radius_sum, dyn.pair.design_t1t2 + rec[:, K.R_Z + 3]
                          - rec[:, K.R_Z + 1]) - dyn.pair.design_centre_distance
            np.testing.assert_allclose(rec[1:, K.R_DD], dd[1:], rtol=0, atol=1e-12)
    assert np.all(np.abs(_order(errs) - want) < 0.15), (errs, _order(errs))


# --------------------------------------------------------------------------- recorded quantities
def _eom_residual(setup, prev, st):
    """Relative residual of ``M a1 + (1+alpha) R1 - alpha R0 = 0``, ``R = C v + K0 z + N g - Q0``
    (affine laws and no ripple: the whole forcing is ``Q0``, the laws' slopes are in ``C``), for
    the states before and after a step."""
    al = setup.fp[K.FP_ALPHA]

    def res(s):
        z, v = s[K.S_Z:K.S_Z + 6], s[K.S_V:K.S_V + 6]
        return setup.C @ v + setup.K0 @ z + s[K.S_N] * setup.g - setup.Q0

    r = setup.M @ st[K.S_A:K.S_A + 6] + (1 + al) * res(st) - al * res(prev)
    scale = np.abs(setup.Q0).max() + abs(st[K.S_N]) * np.abs(setup.g).max()
    return np.abs(r).max() / scale


def _window_average(smap, th, h, dd, variable="k_mb"):
    """``1/(2h) int_{th-h}^{th+h} K(x, dd) dx`` by adaptive quadrature of the point map (the
    stiffness a step uses with ``simulation.stiffness_window = 'step'``); ``h = 0``: the point
    value."""
    from scipy.integrate import quad

    if h == 0.0:
        return float(smap(th, dd))

    def f(x):
        return float(smap(x, dd))

    lo, hi = th - h, th + h
    pieces = [lo, hi]
    # a handover (a jump of K) inside the window: located by bisection, each side integrated
    # on its own (the window is far narrower than a contact zone: at most one jump)
    a, b = lo, hi
    jump = abs(f(b) - f(a)) > 1e-3 * abs(f(th)) and abs(f(b) - f(a)) > 0.2 * abs(
        f(0.5 * (a + b)) - 0.5 * (f(a) + f(b))) + 1e-3 * abs(f(th))
    if jump:
        fa = f(a)
        for _ in range(200):
            m = 0.5 * (a + b)
            if m in (a, b):
                break
            # the side whose ends differ by more than a linear piece would holds the jump
            if abs(f(m) - fa) > abs(f(b) - f(m)):
                b = m
            else:
                a, fa = m, f(m)
        pieces = [lo, a, b, hi]
    val = sum(quad(f, x0, x1, limit=200, epsabs=1e-13 * abs(f(th)) * (x1 - x0),
                   epsrel=1e-13)[0] for x0, x1 in zip(pieces[:-1], pieces[1:], strict=True)
              if x1 > x0)
    return val / (2 * h)


@pytest.mark.parametrize("engine", ENGINES)
@pytest.mark.parametrize("window", ["step", "point"])
def test_recorded_force_stiffness_and_centre_distance_obey_eqs_4_and_14(engine, window):
    """On the paper's model II with the square-wave map (``k_pair`` times the geometric number
    of pairs, handovers moving with the centre distance), step by step over a mesh cycle and
    a half: each record satisfies eq. 4 (``dd`` from the bearing displacements), the converged
    ``|b1 - b2| < tol``, eq. 14 ``N = h (k p + q p')``, and ``k`` is the map at the recorded
    ``dd`` at the predictor angle (``window = 'point'``) or its average over the step's
    rotation ``[theta - h, theta + h]``, ``h = |w dt + dt z_p'| / 2`` (``'step'``, by
    quadrature of the point map)."""
    from geardyn.dynamics import static_equilibrium
    from geardyn.dynamics.newmark import _setup_for_case

    from ._support import geometric_map

    case = short_case(**{"simulation.tolerance": 1e-12, "simulation.rtol": 1e-12,
                         "simulation.stiffness_window": window, "simulation.dt": 2e-5})
    smap = geometric_map(case.gear_pair())
    dyn = DynamicModel.from_case(case, smap)
    static = static_equilibrium(dyn, smap, which="II")
    setup = _setup_for_case(case, dyn, smap, "II", static)
    z0 = static.z.copy()
    z0[1] += 3e-6
    st, ist = initial_state(setup, z0)
    dt, hstep = setup.fp[K.FP_DT], setup.fp[K.FP_HSTEP]
    pair = dyn.pair
    rows, n_split = [], 0
    for n in range(180):
        prev = st.copy()
        out = np.full((2, K.N_REC), np.nan)
        status, j, _ = run_steps(setup, st, ist, 1, out=out, j=0, python=engine == "twin")
        assert status == 0 and ist[0] == n + 1
        rec = out[j - 1]
        rows.append(rec)
        z, v = rec[K.R_Z:K.R_Z + 6], rec[K.R_V:K.R_V + 6]
        dd = math.hypot(pair.base_radius_sum, pair.design_t1t2 + z[3] - z[1]) \
            - pair.design_centre_distance
        assert rec[K.R_DD] == pytest.approx(dd, abs=1e-13)
        assert rec[K.R_RA] < 1e-12
        th = math.fmod((n + 1) * hstep, smap.period) + prev[K.S_Z + 2] + dt * prev[K.S_V + 2] \
            + 0.5 * dt * dt * prev[K.S_A + 2]
        h = 0.5 * abs(hstep + dt * prev[K.S_V + 2]) if window == "step" else 0.0
        k_ref = _window_average(smap, th, h, dd)
        # the converged centre distance is known to tol = 1e-12 m; the handovers move with it
        k_lo = _window_average(smap, th, h, dd - 1e-12)
        k_hi = _window_average(smap, th, h, dd + 1e-12)
        lo, hi = min(k_ref, k_lo, k_hi), max(k_ref, k_lo, k_hi)
        assert lo * (1 - 1e-9) <= rec[K.R_K] <= hi * (1 + 1e-9), (n, rec[K.R_K], k_ref)
        n_split += not (float(smap(th - h, dd)) == float(smap(th + h, dd)) == k_ref)
        p, pd = dyn.g @ z, dyn.g @ v
        assert rec[K.R_N] == pytest.approx(rec[K.R_K] * p + dyn.q_mb * pd, rel=1e-10)
        assert rec[K.R_H] == 1.0
        assert _eom_residual(setup, prev, st) < 1e-9
    rows = np.array(rows)
    assert np.ptp(rows[:, K.R_DD]) > 1e-7     # the centre distance really moved
    if window == "step":
        assert n_split >= 2                     # windows holding a handover were checked


# --------------------------------------------------------------------------- tooth errors
ALL_ERRORS = {"modifications.pinion.grade": 6, "modifications.gear.grade": 7,
              "modifications.gear.seed": 3, "modifications.pinion.tip_relief": "20 um",
              "modifications.gear.tip_relief": "15 um",
              "modifications.gear.relief_shape": "parabolic",
              "modifications.pinion.runout": "10 um", "modifications.gear.runout": "6 um",
              "modifications.gear.runout_phase": 1.0}
UNEQUAL = {"gear.teeth": 31, "modifications.pinion.grade": 5, "modifications.gear.grade": 8,
           "modifications.pinion.seed": 4, "modifications.pinion.tip_relief": "12 um",
           "modifications.pinion.relief_shape": "parabolic",
           "modifications.gear.tip_relief": "18 um", "modifications.pinion.runout": "7 um",
           "modifications.pinion.runout_phase": 0.4, "modifications.gear.runout": "11 um"}
RELIEF_ONLY = {"gear.teeth": 31, "modifications.pinion.tip_relief": "20 um",
               "modifications.gear.tip_relief": "9 um",
               "modifications.gear.relief_shape": "parabolic"}


def _mods_case(over):
    from tests.modifications._support import case_with

    return case_with(**{k.replace(".", "__"): v for k, v in over.items()})


@pytest.fixture(scope="module")
def errors_setup():
    """The paper pair with every error and the PEM map's load shares."""
    from geardyn.modifications import ToothModifications
    from tests.modifications._support import pem_healthy_map

    case = _mods_case(ALL_ERRORS)
    smap = pem_healthy_map()
    mods = ToothModifications.from_case(case)
    return case, smap, mods, mods.kernel_arrays(smap)


def _error_config(name, errors_setup):
    """``(smap, mods, kernel arrays)`` of the named configuration: ``all`` (23/23, tables,
    relief, runout, PEM load shares), ``zero-shares`` (the same with every share 0: the
    handover-node branch), ``unequal`` (23/31, tables, relief, runout, a map without shares)
    and ``relief-only`` (23/31, no table, no runout, no shares)."""
    import dataclasses

    from geardyn.modifications import ToothModifications

    case, smap, mods, arrays = errors_setup
    if name == "all":
        return smap, mods, arrays
    if name == "zero-shares":
        extra = dict(smap.extra)
        extra["load_share"] = np.zeros_like(extra["load_share"])
        zmap = dataclasses.replace(smap, extra=extra)
        return zmap, mods, mods.kernel_arrays(zmap)
    c = _mods_case(UNEQUAL if name == "unequal" else RELIEF_ONLY)
    m = ToothModifications.from_case(c)
    cmap = constant_map(c.gear_pair(), 1.3e8)
    return cmap, m, m.kernel_arrays(cmap)


def _expected_excitation(mods, smap, th, tha, dd, pfree, sep):
    """What the step must use, from :meth:`ToothModifications.pair_errors` and ``shares``."""
    pe = mods.pair_errors(np.array([tha]), dd)
    run = pe["runout"][0]
    th_k = th - run / mods.pair.pinion.base_radius
    inc = pe["in_contact"][0]
    e = pe["e"][0]
    # the shares by the map's NumPy twin, not by its compiled look-up (the kernel's)
    if "load_share" in smap.extra:
        sh = np.array([float(lookup_reference(np.array(th_k), np.array(dd),
                                              smap.arrays("load_share", slot=k)))
                       for k in range(3)])
    else:
        sh = mods.shares(smap, np.array([th_k]), dd, pe["in_contact"])[0]
    k_mb = float(smap(th_k, dd)) if "load_share" in smap.extra else math.nan
    if not inc.any():
        return th_k, run, 1.0, 1.0, k_mb
    loaded = inc & ((not sep) | (pfree - e >= 0.0))
    if not loaded.any():
        return th_k, 0.0, 1.0, 0.0, k_mb
    sa = sh[loaded].sum()
    if sa <= 0.0:
        return th_k, run, 1.0, 1.0, k_mb
    frac = 1.0 if loaded.sum() == inc.sum() else sa / sh[inc].sum()
    return th_k, (sh[loaded] * e[loaded]).sum() / sa, frac, 1.0, k_mb


@pytest.mark.parametrize("engine", ENGINES)
@pytest.mark.parametrize("config", ["all", "zero-shares", "unequal", "relief-only"])
def test_tooth_error_pairs_against_pair_errors(engine, config, errors_setup):
    """The per-step pair search (``_excite`` of the kernel, ``_excite_py`` of the twin): the
    contact pattern's angle, the share-weighted error of the loaded pairs, their share of
    ``k_mb``, the contact flag (and the kernel's ``k_mb``) against the vectorised
    :meth:`ToothModifications.pair_errors` and :meth:`~ToothModifications.shares`, over a
    hunting period, three centre distances (and, on the maps without load shares, a fourth
    with a contact ratio below 1, so that some angles have no pair in contact) and free
    deflections that load all, some or none of
    the pairs."""
    smap, mods, (eip, efp, etp, etg, els) = _error_config(config, errors_setup)
    pair = mods.pair
    arr = smap.arrays()
    rng = np.random.default_rng(7)
    tha_all = rng.uniform(0.0, mods.hunting_period, 40)
    d0 = pair.design_centre_distance
    rsum = pair.base_radius_sum
    assert pair.operating(5e-3, check=False).contact_ratio < 1.0
    seen = {"partial": 0, "none": 0, "no pair": 0}
    shares = "load_share" in smap.extra
    # beyond the PEM map's range a step stops (MAP_RANGE) before the errors matter
    for dd in (-2e-5, 0.0, 1.3e-4) + (() if shares else (5e-3,)):
        b1 = d0 + dd
        for tha in tha_all:
            th = math.fmod(tha, smap.period)
            pe = mods.pair_errors(np.array([tha]), dd)
            e_in = np.sort(pe["e"][0][pe["in_contact"][0]])
            # between the two smallest errors of the pairs in contact: only some are loaded
            p_mid = 0.5 * (e_in[0] + e_in[1]) if e_in.size > 1 else 1e-3
            for pfree, sep in ((1e-3, True), (p_mid, True), (-1e-3, True), (-1e-3, False)):
                want = _expected_excitation(mods, smap, th, tha, dd, pfree, sep)
                if engine == "twin":
                    got = K._excite_py(th, tha, b1, rsum, dd, pfree, sep, eip, efp, etp, etg,
                                       els, arr)
                else:
                    got = K._excite(th, tha, b1, rsum, dd, pfree, sep, eip, efp, etp, etg, els,
                                    arr.dd0, arr.ddd, arr.phase_a, arr.length_a, arr.mesh_angle,
                                    arr.n_cycles, arr.n_seg, arr.values)
                    if math.isnan(want[4]):
                        assert math.isnan(got[4])
                    else:
                        assert got[4] == pytest.approx(want[4], rel=1e-12)
                assert got[0] == pytest.approx(want[0], abs=1e-13)
                assert got[1] == pytest.approx(want[1], rel=1e-9, abs=1e-15)
                assert got[2] == pytest.approx(want[2], rel=1e-12)
                assert got[3] == want[3]
                seen["partial"] += 0.0 < want[2] < 1.0
                seen["none"] += want[3] == 0.0
                seen["no pair"] += not pe["in_contact"][0].any()
    if shares:
        del seen["no pair"]
    if config == "zero-shares":     # no loaded share: always the unweighted branch
        del seen["partial"]
    assert min(seen.values()) > 3, seen     # every branch was exercised


@pytest.mark.parametrize("engine", ENGINES)
@pytest.mark.parametrize("evaluation, integrator", [("predictor", "newmark"),
                                                    ("start", "hht")])
def test_steps_with_tooth_errors_obey_eq_15_per_pair(engine, evaluation, integrator,
                                                     errors_setup):
    """Model I on the paper's model with every tooth error, step by step: the recorded
    share-weighted error, contact flag and effective stiffness are those of
    :meth:`ToothModifications.pair_errors` and the map's load shares at the step's evaluation
    angle (predictor or start of step, in the map period and in the hunting period), with the
    pairs loaded by eq. 15 applied to the free deflection, and the recorded force is
    ``h (k f (p - e_bar) + q p')``. The free deflection is measured, not recomputed: it is the
    deflection after the same step with the mesh removed (zero map, no mesh damping)."""
    import dataclasses

    from geardyn.dynamics import static_equilibrium
    from geardyn.dynamics.newmark import _setup_for_case, _start_with_errors

    case, smap, mods, _ = errors_setup
    c = case.with_overrides({"simulation.stiffness_evaluation": evaluation,
                             "simulation.integrator": integrator,
                             "simulation.hht_alpha": -0.1, "simulation.dt": 2e-5})
    dyn = DynamicModel.from_case(c, smap)
    static = static_equilibrium(dyn, smap, which="I")
    setup = _setup_for_case(c, dyn, smap, "I", static)
    arr = setup.map_arrays
    fp_free = setup.fp.copy()
    fp_free[K.FP_QMB] = 0.0
    free = dataclasses.replace(setup, map_arrays=arr._replace(values=np.zeros_like(arr.values)),
                               fp=fp_free)
    py = engine == "twin"
    z0 = _start_with_errors(setup, dyn, static)
    z0[1] += 2e-6          # a transient: pairs leave and regain contact
    st, ist = initial_state(setup, z0, step=500)
    dt, hstep, hper = setup.fp[K.FP_DT], setup.fp[K.FP_HSTEP], mods.hunting_period
    g, q = setup.g, setup.fp[K.FP_QMB]
    seen = {"partial": 0, "separated": 0}
    for _ in range(70):
        n = int(ist[0])
        prev = st.copy()
        st_f, ist_f = prev.copy(), ist.copy()
        assert run_steps(free, st_f, ist_f, 1, python=py)[0] == 0
        p_free = g @ st_f[K.S_Z:K.S_Z + 6]
        out = np.full((2, K.N_REC), np.nan)
        status, j, _ = run_steps(setup, st, ist, 1, out=out, python=py)
        assert status == 0 and j >= 1
        rec = out[j - 1]            # the row of the new step (the first call also records
        assert ist[1] == 1          # the start state)
        nn = n if evaluation == "start" else n + 1
        th, tha = math.fmod(nn * hstep, smap.period), math.fmod(nn * hstep, hper)
        for var, coef in ((K.S_Z, 1.0), (K.S_V, dt), (K.S_A, 0.5 * dt * dt)):
            if evaluation == "predictor" or var == K.S_Z:
                th += coef * prev[var + 2]
                tha += coef * prev[var + 2]
        th_k, ebar, frac, h, _k = _expected_excitation(mods, smap, th, tha, 0.0, p_free, True)
        assert rec[K.R_H] == h
        assert rec[K.R_E] == pytest.approx(ebar, rel=1e-9, abs=1e-16)
        # the map averaged over the step's rotation (the case's default window), times f; a
        # node of the map inside the window is not split (lookup_box: an O(h^2) difference,
        # at most half the second difference over the window)
        hw = 0.5 * abs(hstep + dt * prev[K.S_V + 2])
        k = _window_average(smap, th_k, hw, 0.0) * frac
        k3 = [float(smap(th_k + d, 0.0)) * frac for d in (-hw, 0.0, hw)]
        slack = 0.5 * abs(k3[0] + k3[2] - 2 * k3[1]) + 1e-9 * k
        assert abs(rec[K.R_K] - k) <= slack, (n, rec[K.R_K], k, slack)
        k = rec[K.R_K]
        p, pd = g @ rec[K.R_Z:K.R_Z + 6], g @ rec[K.R_V:K.R_V + 6]
        assert rec[K.R_N] == pytest.approx(h * (k * (p - ebar) + q * pd), rel=1e-9,
                                           abs=1e-9 * abs(static.mesh_force))
        # the equations of motion (eqs. 9-13 with the mesh force of eq. 14), HHT-weighted
        assert _eom_residual(setup, prev, st) < 1e-9
        seen["partial"] += 0.0 < frac < 1.0
        seen["separated"] += h == 0.0
    assert seen["partial"] > 0, seen


def test_tooth_error_relief_and_table_shapes(errors_setup):
    """``_relief`` (none, linear and parabolic) and ``_table_value`` against the gear's own
    :meth:`GearDeviations.relief_at` and a NumPy interpolation of its table, including both
    ends, the first and last cells and beyond."""
    case, smap, mods, (eip, efp, etp, etg, els) = errors_setup
    from geardyn.modifications import ToothModifications

    bare = ToothModifications.from_case(_mods_case({"modifications.pinion.grade": 6}))
    eip_b, efp_b, _, _, _ = bare.kernel_arrays(smap)
    assert not bare.gear.has_relief
    u = np.linspace(bare.gear.u_lo, bare.gear.u_tip, 11)
    assert all(K._relief(efp_b, K.EF_GEAR0 + K.EF_PER_GEAR, x) == 0.0 for x in u)
    for gi, (gear, tab) in enumerate(((mods.pinion, etp), (mods.gear, etg))):
        base = K.EF_GEAR0 + gi * K.EF_PER_GEAR
        nr = eip[K.EI_NR]
        u = np.concatenate([np.linspace(gear.u_lo - 2e-4, gear.u_tip + 2e-4, 97),
                            gear.u_lo + gear.du * np.array([0.25, 0.5, 1.0, 1.5, nr - 2.5,
                                                            nr - 1.5, nr - 1.0, nr - 0.5])])
        got = np.array([K._relief(efp, base, x) for x in u])
        np.testing.assert_allclose(got, gear.relief_at(u), rtol=1e-12, atol=1e-18)
        grid = gear.u_lo + gear.du * np.arange(eip[K.EI_NR])
        for row in (0, tab.shape[0] - 1, tab.shape[0] // 2):
            want = np.interp(u, grid, tab[row])
            got = np.array([K._table_value(tab, row, x, gear.u_lo, gear.du, eip[K.EI_NR])
                            for x in u])
            np.testing.assert_allclose(got, want, rtol=1e-12, atol=1e-18)
            # the grid nodes themselves
            got = np.array([K._table_value(tab, row, x, gear.u_lo, gear.du, eip[K.EI_NR])
                            for x in grid])
            np.testing.assert_allclose(got, tab[row], rtol=1e-12, atol=1e-18)


def test_lookup4_against_the_reference_lookup(errors_setup):
    """``_lookup4`` (stiffness and the three load shares with the cell found once) against
    :func:`lookup_reference` of each array, inside and beyond the centre-distance range."""
    case, smap, mods, (eip, efp, etp, etg, els) = errors_setup
    arr = smap.arrays()
    rng = np.random.default_rng(3)
    th = rng.uniform(-1.0, 2 * smap.period, 300)
    lo, hi = arr.dd0, arr.dd0 + arr.ddd * (arr.values.shape[0] - 1)
    dd = rng.uniform(lo, hi, 300)
    dd[:4] = [lo, hi, lo + arr.ddd, hi - 0.5 * arr.ddd]
    for t, d in zip(th, dd, strict=True):
        got = K._lookup4(t, d, arr.dd0, arr.ddd, arr.phase_a, arr.length_a, arr.mesh_angle,
                         arr.n_cycles, arr.n_seg, arr.values, els)
        want = [float(lookup_reference(np.array(t), np.array(d), arr))]
        want += [float(lookup_reference(np.array(t), np.array(d), arr._replace(values=els[k])))
                 for k in range(3)]
        np.testing.assert_allclose(got, want, rtol=1e-12, atol=1e-14)
    for d in (lo - 1e-6, hi + 1e-6):
        got = K._lookup4(0.1, d, arr.dd0, arr.ddd, arr.phase_a, arr.length_a, arr.mesh_angle,
                         arr.n_cycles, arr.n_seg, arr.values, els)
        assert math.isnan(got[0]) and got[1:] == (0.0, 0.0, 0.0)
    # one grid line: no interpolation in dd, any dd accepted
    one = MapArrays(0.0, 0.0, arr.phase_a[:1], arr.length_a[:1], arr.mesh_angle, arr.n_cycles,
                    arr.n_seg, arr.values[:1])
    got = K._lookup4(0.3, 5e-4, *one, np.ascontiguousarray(els[:, :1]))
    assert got[0] == pytest.approx(float(lookup_reference(np.array(0.3), np.array(0.0), one)),
                                   rel=1e-12)


def _edge_arrays(length_a, n_d=3, n_cycles=2, n_seg=3, tm=0.3, seed=0):
    rng = np.random.default_rng(seed)
    nodes = n_cycles * 2 * n_seg
    arr = MapArrays(-1e-4, 2e-4 if n_d > 1 else 0.0, np.linspace(0.05, 0.07, n_d),
                    np.asarray(length_a, float), tm, n_cycles, n_seg,
                    rng.uniform(5e7, 2e8, (n_d, nodes)))
    return arr, rng.uniform(0.0, 1.0, (3, n_d, nodes))


@pytest.mark.parametrize("zones", ["both", "two lines", "no zone A", "one line"])
def test_lookup4_at_the_edges(zones):
    """``_lookup4`` where its clamps act, against the compiled map :func:`lookup` (same
    arithmetic, another module) bit for bit and :func:`lookup_reference` to 1e-12: centre
    distances at the first and last grid lines and within 1e-9 of the spacing beyond them,
    angles at the zone boundaries, one ulp either side, at the period wrap and at nodes; a map
    whose zone A is empty (an integer contact ratio: ``L_A = (ceil(eps) - eps) Theta_m``),
    two grid lines and a single one."""
    from geardyn.stiffness.map import lookup

    length_a = {"both": [0.1, 0.12, 0.14], "two lines": [0.1, 0.13],
                "no zone A": [0.0, 0.0, 0.0], "one line": [0.11]}[zones]
    arr, els = _edge_arrays(length_a, n_d=len(length_a))
    tm, per = arr.mesh_angle, arr.mesh_angle * arr.n_cycles
    n_d = arr.values.shape[0]
    lo = arr.dd0
    hi = arr.dd0 + arr.ddd * (n_d - 1)
    dds = [lo, hi, lo + arr.ddd, 0.37 * lo + 0.63 * hi, lo - 0.5e-9 * arr.ddd,
           hi + 0.5e-9 * arr.ddd] if n_d > 1 else [0.0, 3e-4, -7e-4]
    ths = []
    for i in range(n_d):
        a, la = arr.phase_a[i], arr.length_a[i]
        for c in range(-1, arr.n_cycles + 1):
            for b in (a + c * tm, a + la + c * tm):
                ths += [b, np.nextafter(b, -np.inf), np.nextafter(b, np.inf)]
            ths += [a + c * tm + la * f for f in (0.25, 0.5, 1.0 - 1e-15)]
    ths += [per - 1e-17, -1e-17, 0.0, per, 7 * per + 0.123, -3 * per + 0.2]
    for d in dds:
        for t in ths:
            got = K._lookup4(t, d, *arr, els)
            k_fast = lookup(t, d, *arr)
            assert got[0] == k_fast, (t, d)
            want = [float(lookup_reference(np.array(t), np.array(d), arr))]
            want += [float(lookup_reference(np.array(t), np.array(d),
                                            arr._replace(values=els[k]))) for k in range(3)]
            np.testing.assert_allclose(got, want, rtol=1e-12, atol=1e-13, err_msg=f"{t} {d}")


def test_twin_equality_with_all_tooth_errors(errors_setup):
    """Kernel against twin with every error active (tables, relief, runout, shares) for models
    I and II, predictor and start-of-step, Newmark and HHT, step and point windows: 40 steps
    each."""
    from geardyn.dynamics import static_equilibrium
    from geardyn.dynamics.newmark import _setup_for_case, _start_with_errors

    case, smap, mods, _ = errors_setup
    for which, over in (("II", {}), ("II", {"simulation.stiffness_window": "point"}),
                        ("I", {"simulation.stiffness_evaluation": "start"}),
                        ("II", {"simulation.integrator": "hht",
                                "simulation.stiffness_evaluation": "start"})):
        c = case.with_overrides(over)
        dyn = DynamicModel.from_case(c, smap)
        static = static_equilibrium(dyn, smap, which=which)
        setup = _setup_for_case(c, dyn, smap, which, static)
        z0 = _start_with_errors(setup, dyn, static)
        outs = []
        for python in (False, True):
            st, ist = initial_state(setup, z0, step=1234)
            out = np.full((41, K.N_REC), np.nan)
            status, j, _ = run_steps(setup, st, ist, 40, rec_start=1234, out=out,
                                     python=python)
            assert status == 0 and j == 41
            outs.append(out)
        np.testing.assert_allclose(outs[0], outs[1], rtol=1e-9, atol=1e-13)
        assert np.ptp(outs[0][:, K.R_E]) > 1e-7


def test_twin_equality_with_ripple_drive_and_laws():
    """Kernel against twin with a torque ripple, a speed-controlled drive and nonlinear laws
    at both ends, HHT, model II: 60 steps."""
    from geardyn.dynamics import static_equilibrium
    from geardyn.dynamics.newmark import _setup_for_case

    case = short_case(**{"load.law": "quadratic", "motor.law": "induction",
                         "motor.synchronous_speed": 125.0, "motor.breakdown_torque": 140.0,
                         "motor.breakdown_slip": 0.2, "motor.ripple": 0.2,
                         "motor.ripple_order": 2.0, "motor.ripple_phase": 0.3,
                         "simulation.integrator": "hht", "simulation.hht_alpha": -0.1})
    smap = triangle_map(case.gear_pair())
    dyn = DynamicModel.from_case(case, smap)
    static = static_equilibrium(dyn, smap, which="II")
    setup = _setup_for_case(case, dyn, smap, "II", static)
    z0 = static.z.copy()
    z0[1] += 1e-6
    v0 = np.zeros(6)
    v0[0], v0[5] = 0.7, -0.4
    outs = []
    for python in (False, True):
        st, ist = initial_state(setup, z0, v0)
        out = np.full((61, K.N_REC), np.nan)
        status, j, _ = run_steps(setup, st, ist, 60, out=out, python=python)
        assert status == 0 and j == 61
        outs.append(out)
    np.testing.assert_allclose(outs[0], outs[1], rtol=1e-9, atol=1e-13)


# --------------------------------------------------------------------------- bookkeeping
@pytest.mark.parametrize("engine", ENGINES)
def test_chunks_records_and_decimation(engine, pair):
    """A time-stepping scheme is Markov in its state: 100 steps in chunks of 37/1/62 equal one
    run of 100 bit for bit; records land at ``n = rec_start + i decim`` (the state at the
    chunk start recorded once, not twice), and a full record array is not overrun."""
    m, k = 1.2, 3e4
    setup = sdof_setup(constant_map(pair, k), m=m, c=2.0, dt=1e-3, separation=False,
                       speed=12.0)
    z0 = np.zeros(6)
    z0[1] = 1e-3
    py = engine == "twin"
    st, ist = initial_state(setup, z0)
    ref = np.full((101, K.N_REC), np.nan)
    assert run_steps(setup, st, ist, 100, out=ref, python=py)[:2] == (0, 101)
    st_ref = st.copy()
    # chunks, records from step 10 every 3rd step
    st, ist = initial_state(setup, z0)
    out = np.full((40, K.N_REC), np.nan)
    j = 0
    for n in (37, 1, 62):
        status, j, _ = run_steps(setup, st, ist, n, rec_start=10, decim=3, out=out, j=j,
                                 python=py)
        assert status == 0
    np.testing.assert_array_equal(st, st_ref)
    assert ist[0] == 100 and st[K.S_RIP] == 0.0      # no ripple, no drive
    want = np.arange(10, 101, 3)
    assert j == want.size
    np.testing.assert_array_equal(out[:j], ref[want])
    assert np.isnan(out[j:]).all()
    # a record array with room for 5 rows only
    st, ist = initial_state(setup, z0)
    small = np.full((5, K.N_REC), np.nan)
    status, j, _ = run_steps(setup, st, ist, 100, out=small, decim=7, python=py)
    assert (status, j) == (0, 5)
    np.testing.assert_array_equal(small, ref[[0, 7, 14, 21, 28]])
    # the recorded state after an exact record step: ist[1] = 1 (no duplicate next call)
    st, ist = initial_state(setup, z0)
    out = np.full((3, K.N_REC), np.nan)
    status, j, _ = run_steps(setup, st, ist, 4, decim=4, out=out, python=py)
    assert (j, ist[0], ist[1]) == (2, 4, 1)
    status, j, _ = run_steps(setup, st, ist, 0, decim=4, out=out, j=j, python=py)
    assert j == 2
    st, ist = initial_state(setup, z0)
    status, j, _ = run_steps(setup, st, ist, 5, decim=4, out=out, j=0, python=py)
    assert (j, ist[0], ist[1]) == (2, 5, 0)
    # a state not yet recorded at a record step of a later start (10 = 4 + 2 * 3) is recorded
    # first, into the row given
    st, ist = initial_state(setup, z0, step=10)
    start = st.copy()
    out = np.full((6, K.N_REC), np.nan)
    status, j, _ = run_steps(setup, st, ist, 3, rec_start=4, decim=3, out=out, j=2,
                             python=py)
    assert (status, j, ist[0], ist[1]) == (0, 4, 13, 1)
    assert np.isnan(out[:2]).all() and np.isnan(out[4:]).all()
    np.testing.assert_array_equal(out[2, K.R_Z:K.R_Z + 6], start[K.S_Z:K.S_Z + 6])
    np.testing.assert_array_equal(out[3, K.R_Z:K.R_Z + 6], st[K.S_Z:K.S_Z + 6])
    # a record step reached without steps is marked recorded (ist[1] = 1)
    st, ist = initial_state(setup, z0, step=7)
    status, j, _ = run_steps(setup, st, ist, 0, rec_start=4, decim=3, out=out, j=0,
                             python=py)
    assert (j, ist[1]) == (1, 1)


@pytest.mark.parametrize("engine", ENGINES)
def test_a_late_step_equals_an_early_one(engine):
    """The map angle is ``fmod((n+1) w dt, period) + z_p``: the same motion started at step
    10^7 (phase from the step count, many periods wrapped) and at step 0 (the same phase as a
    rigid rotation in the deviations) agree to rounding over 150 steps."""
    from geardyn.dynamics import static_equilibrium
    from geardyn.dynamics.newmark import _setup_for_case

    case = short_case()
    smap = triangle_map(case.gear_pair())
    dyn = DynamicModel.from_case(case, smap)
    static = static_equilibrium(dyn, smap, which="II")
    setup = _setup_for_case(case, dyn, smap, "II", static)
    n0 = 10_000_000
    assert n0 * setup.fp[K.FP_HSTEP] > 1000 * smap.period
    phase = float(np.fmod(n0 * setup.fp[K.FP_HSTEP], smap.period))
    py = engine == "twin"
    outs = []
    for step, z in ((n0, static.z), (0, static.z + phase * dyn.reference_direction)):
        out = np.full((151, K.N_REC), np.nan)
        st, ist = initial_state(setup, z, step=step)
        assert run_steps(setup, st, ist, 150, rec_start=step, out=out, python=py)[:2] == (0, 151)
        outs.append(out)
    for col in (K.R_Z + 1, K.R_Z + 3, K.R_N, K.R_K, K.R_DD):
        a, b = outs[0][:, col], outs[1][:, col]
        assert np.abs(a - b).max() <= 1e-9 * np.abs(b).max(), col
    assert np.ptp(outs[0][:, K.R_K]) > 0.1 * outs[0][:, K.R_K].max()   # the map was crossed


@pytest.mark.parametrize("engine", ENGINES)
def test_failure_codes_with_the_failing_state(engine, pair):
    """Each failure code with its record: runaway mesh deflection (negative net stiffness),
    runaway bearing, non-finite state, a centre distance leaving the map (model II), no
    convergence; the failure time, angle, deflection, bearing displacements and force are
    those of the failing state."""
    py = engine == "twin"
    # runaway mesh deflection: p beyond p_lim
    setup = sdof_setup(constant_map(pair, 1e4), m=1.0, dt=1e-3, p_lim=1.0, speed=3.0,
                       separation=False)
    setup.K0[1, 1] = -5e4
    setup.SK[:] = setup.Sinv @ setup.K0
    z0 = np.zeros(6)
    z0[1] = 1e-6
    v0 = np.zeros(6)
    v0[2], v0[3] = 0.7, -2e-4          # a free pinion rotation and gear bearing drift
    st, ist = initial_state(setup, z0, v0)
    status, j, fail = run_steps(setup, st, ist, 10_000, python=py)
    n = ist[0]
    assert status == K.MESH_RUNAWAY and 1.0 < abs(st[K.S_Z + 1]) < 10.0
    assert fail[0] == pytest.approx(n * 1e-3, rel=1e-14)
    assert fail[1] == pytest.approx(math.fmod(n * 3e-3, constant_map(pair, 1e4).period)
                                    + st[K.S_Z + 2], rel=1e-12)
    assert st[K.S_Z + 2] > 0.01 and st[K.S_Z + 3] < -1e-6
    assert fail[2] == st[K.S_Z + 1] and fail[3] == st[K.S_Z + 1] and fail[4] == st[K.S_Z + 3]
    assert fail[5] == st[K.S_DD] == pytest.approx(
        math.hypot(setup.fp[K.FP_RSUM], setup.fp[K.FP_T1T2] + st[K.S_Z + 3] - st[K.S_Z + 1])
        - setup.fp[K.FP_D0], abs=1e-15)
    assert fail[6] == pytest.approx(1e4 * st[K.S_Z + 1], rel=1e-12) and fail[7] == 1e4
    assert fail[8] == st[K.S_IT] == 0 and math.isnan(fail[9]) and math.isnan(st[K.S_RA])
    # runaway bearing: the same on DOF 3 with g = 0 (no mesh deflection)
    M = np.eye(6)
    K0 = np.zeros((6, 6))
    K0[3, 3] = -4e4
    g = np.array([1.0, 0.0, 0.0, 0.0, 0.0, 0.0])
    setup = make_setup(M, K0, np.zeros((6, 6)), g, np.zeros(6), constant_map(pair, 1.0),
                       dt=1e-3, y_lim=0.5, p_lim=1e9, separation=False)
    z0 = np.zeros(6)
    z0[3] = 1e-6
    st, ist = initial_state(setup, z0)
    status, j, fail = run_steps(setup, st, ist, 10_000, python=py)
    assert status == K.BEARING_RUNAWAY and 0.5 < abs(st[K.S_Z + 3]) < 5.0
    assert fail[4] == st[K.S_Z + 3] and fail[0] == pytest.approx(ist[0] * 1e-3, rel=1e-14)
    z0 = np.zeros(6)
    z0[1] = -1e-6
    K0 = np.zeros((6, 6))
    K0[1, 1] = -4e4
    setup = make_setup(M, K0, np.zeros((6, 6)), g, np.zeros(6), constant_map(pair, 1.0),
                       dt=1e-3, y_lim=0.5, p_lim=1e9, separation=False)
    st, ist = initial_state(setup, z0)
    status, j, fail = run_steps(setup, st, ist, 10_000, python=py)
    assert status == K.BEARING_RUNAWAY and fail[3] == st[K.S_Z + 1] < -0.5
    # non-finite
    setup = sdof_setup(constant_map(pair, 1e4), m=1.0, dt=1e-3)
    st, ist = initial_state(setup, np.zeros(6))
    st[K.S_V + 4] = np.inf
    with np.errstate(invalid="ignore", over="ignore"):
        status, j, fail = run_steps(setup, st, ist, 10, python=py)
    assert status == K.NONFINITE and fail[0] == pytest.approx(1e-3) and ist[0] == 1
    # model II leaving the map: bearing pushed beyond the map's range
    smap = triangle_map(pair, dd=(-1e-5, 1e-5), n_d=3)
    rsum, t1t2 = pair.base_radius_sum, pair.design_t1t2
    M = np.eye(6)
    Z = np.zeros((6, 6))
    g = np.array([0.0, 1.0, 0.0, 0.0, 0.0, 0.0])
    setup = make_setup(M, Z, Z, g, np.zeros(6), smap, dt=1e-4, model="II", rsum=rsum,
                       t1t2=t1t2, separation=False)
    v0 = np.zeros(6)
    v0[3] = 0.05           # y_g grows: T1T2 + y_g - y_p grows, the centre distance too
    v0[1], v0[2] = -0.01, 0.3
    st, ist = initial_state(setup, np.zeros(6), v0)
    before = None
    for _ in range(200):
        before = st.copy()
        status, j, fail = run_steps(setup, st, ist, 1, python=py)
        if status:
            break
    assert status == K.MAP_RANGE
    np.testing.assert_array_equal(st, before)      # the state stays at the last good step
    assert fail[0] == pytest.approx(ist[0] * 1e-4 + 1e-4, rel=1e-12)
    assert fail[6] == 0.0 and math.isnan(fail[7]) and fail[8] == 0 and math.isnan(fail[9])
    # the failing step's predictors (Newmark, beta = 1/4): z + dt v + dt^2/4 a, and the
    # centre distance of eq. 4 at the predicted bearing displacements
    xt = st[K.S_Z:K.S_Z + 6] + 1e-4 * st[K.S_V:K.S_V + 6] + 0.25e-8 * st[K.S_A:K.S_A + 6]
    assert fail[3] == pytest.approx(xt[1], abs=1e-15) and fail[4] == pytest.approx(xt[3],
                                                                                  abs=1e-15)
    yp = st[K.S_Z + 1] + 1e-4 * st[K.S_V + 1] + 0.5e-8 * st[K.S_A + 1]
    yg = st[K.S_Z + 3] + 1e-4 * st[K.S_V + 3] + 0.5e-8 * st[K.S_A + 3]
    assert fail[5] == pytest.approx(math.hypot(rsum, t1t2 + yg - yp) - math.hypot(rsum, t1t2),
                                    abs=1e-15)
    assert fail[5] > 1e-5 and np.isfinite(fail[2])
    assert fail[1] == pytest.approx(math.fmod((ist[0] + 1) * setup.fp[K.FP_HSTEP],
                                              smap.period) + xt[2] + 0.25e-8 * st[K.S_A + 2],
                                    abs=1e-14)
    # no convergence: one iteration allowed, a tolerance no step meets
    steep = triangle_map(pair, dd=(-2e-4, 2e-4), n_d=9, slope=2000.0)
    setup = make_setup(M, Z, Z, g, np.zeros(6), steep, dt=1e-4, model="II", rsum=rsum,
                       t1t2=t1t2, separation=False, tolerance=1e-30, rtol=1e-30,
                       max_iterations=1)
    z0 = np.zeros(6)
    z0[1] = 2e-5
    st, ist = initial_state(setup, z0, v0 * 0.2)
    status, j, fail = run_steps(setup, st, ist, 50, python=py)
    assert status == K.NOT_CONVERGED and fail[8] == 1 and ist[0] == 0
    assert fail[9] >= 1e-30 and fail[0] == pytest.approx(1e-4)
    assert np.isfinite(fail[6]) and fail[6] != 0.0 and fail[7] > 0.0 and np.isfinite(fail[2])


@pytest.mark.parametrize("engine", ENGINES)
def test_model_ii_iterates_to_the_fixed_point(engine, pair):
    """Model II with a map that depends strongly on the centre distance: a tight tolerance
    needs iterations (recorded), and the converged step satisfies ``|b1 - b2| < tol``
    with the stiffness of the converged centre distance; a loose tolerance accepts the first
    solve (no iteration, first residual = last residual)."""
    rsum, t1t2 = pair.base_radius_sum, pair.design_t1t2
    smap = triangle_map(pair, dd=(-2e-4, 2e-4), n_d=9, slope=2000.0)
    M = np.diag([1.0, 0.4, 1.0, 0.5, 1.0, 1.0])
    K0 = np.zeros((6, 6))
    K0[1, 1], K0[3, 3] = 2e6, 3e6
    g = np.array([0.0, 1.0, 0.0, -1.0, 0.0, 0.0])
    Q0 = np.zeros(6)
    for tol, iterate in ((1e-13, True), (1.0, False)):
        setup = make_setup(M, K0, np.zeros((6, 6)), g, Q0, smap, dt=2e-5, model="II",
                           rsum=rsum, t1t2=t1t2, separation=False, tolerance=tol, rtol=1e-3,
                           speed=50.0)
        z0 = np.zeros(6)
        z0[1], z0[3] = 4e-5, -3e-5
        status, rec, _, _, _ = _run(setup, z0, None, 80, engine)
        assert status == 0
        it, rb, ra = rec[1:, K.R_IT], rec[1:, K.R_RB], rec[1:, K.R_RA]
        dd = np.hypot(rsum, t1t2 + rec[1:, K.R_Z + 3] - rec[1:, K.R_Z + 1]) - math.hypot(rsum,
                                                                                          t1t2)
        np.testing.assert_allclose(rec[1:, K.R_DD], dd, rtol=0, atol=1e-15)
        if iterate:
            assert it.max() >= 2 and np.all(ra < tol) and np.all(rb > ra)
        else:
            assert np.all(it == 0) and np.all(ra == rb) and np.all(ra < 1e-6)
        assert np.all(rec[1:, K.R_RA] >= 0)


def test_law_torque_every_law_against_torque_law():
    """The compiled law function (plain Python under mutation) against
    :meth:`TorqueLaw.torque`, including table ends and nodes, and its remainder helpers."""
    laws = [TorqueLaw("constant", 3.5), TorqueLaw("linear", 0.02),
            TorqueLaw("quadratic", -1.5e-3),
            TorqueLaw("table", speeds=np.array([10.0, 20.0, 35.0, 50.0, 80.0]),
                      torques=np.array([5.0, -2.0, 7.0, 7.5, 1.0])),
            TorqueLaw("induction", synchronous_speed=150.0, breakdown_torque=60.0,
                      breakdown_slip=0.15)]
    w = np.concatenate([np.linspace(-20.0, 160.0, 181), [10.0, 20.0, 35.0, 50.0, 80.0]])
    for law in laws:
        p0, p1, p2 = law.params()
        tw, tt = law.table()
        for x in w:
            want = float(law.torque(x))
            assert K.law_torque(law.code, p0, p1, p2, tw, tt, x) == pytest.approx(
                want, rel=1e-13, abs=1e-13)
            assert K._law_torque_py(law.code, p0, p1, p2, tw, tt, x) == pytest.approx(
                want, rel=1e-13, abs=1e-13)
            wref = 90.0
            r = K._remainder(law.code, p0, p1, p2, tw, tt, wref, 1.25, -0.5, x - wref)
            assert r == pytest.approx(want - 1.25 + 0.5 * (x - wref), rel=1e-12, abs=1e-12)
    # the two wrappers read the input (+) and output (-) parameter blocks
    fp = np.zeros(K.N_FP)
    ip = np.zeros(K.N_IP, dtype=np.int64)
    ind = laws[4]
    tab = laws[3]
    ip[K.IP_INLAW], ip[K.IP_OUTLAW] = ind.code, tab.code
    fp[K.FP_IN_P0:K.FP_IN_P2 + 1] = ind.params()
    fp[K.FP_IN_WREF], fp[K.FP_IN_TREF], fp[K.FP_IN_SLOPE] = 120.0, 2.0, 0.3
    fp[K.FP_OUT_WREF], fp[K.FP_OUT_TREF], fp[K.FP_OUT_SLOPE] = 30.0, -1.0, 0.2
    tw, tt = tab.table()
    assert K._q_in(fp, ip, tw, tt, 4.0) == pytest.approx(
        float(ind.torque(124.0)) - 2.0 - 0.3 * 4.0, rel=1e-13)
    assert K._q_out(fp, ip, tw, tt, -3.0) == pytest.approx(
        -(float(tab.torque(27.0)) + 1.0 + 0.2 * 3.0), rel=1e-13)


def test_input_forcing_ripple_and_drive():
    """``_input_forcing`` against the ripple formula at ``theta_ref = n w dt`` and the drive's
    piecewise linear target (constant beyond the ends)."""
    fp = np.zeros(K.N_FP)
    fp[K.FP_DT], fp[K.FP_HSTEP] = 1e-3, 0.05
    sp_t, sp_w = np.array([0.0, 0.2, 0.5]), np.array([10.0, 30.0, 25.0])
    assert K._input_forcing(fp, 17, sp_t, sp_w) == 0.0
    fp[K.FP_RIP_AMP], fp[K.FP_RIP_ORDER], fp[K.FP_RIP_PHASE] = 2.0, 3.0, 0.4
    for n in (0, 1, 17, 1000):
        assert K._input_forcing(fp, n, sp_t, sp_w) == pytest.approx(
            2.0 * math.sin(3.0 * n * 0.05 + 0.4), abs=1e-14)
    fp[K.FP_RIP_AMP] = 0.0
    fp[K.FP_DRIVE_GAIN], fp[K.FP_WREF] = 1.5, 12.0
    for n in (0, 100, 200, 350, 500, 900):
        want = 1.5 * (np.interp(n * 1e-3, sp_t, sp_w) - 12.0)
        assert K._input_forcing(fp, n, sp_t, sp_w) == pytest.approx(want, rel=1e-13, abs=1e-14)
    fp[K.FP_RIP_AMP] = 2.0
    assert K._input_forcing(fp, 350, sp_t, sp_w) == pytest.approx(
        2.0 * math.sin(3.0 * 350 * 0.05 + 0.4) + 1.5 * (np.interp(0.35, sp_t, sp_w) - 12.0),
        rel=1e-13)


def test_no_excitation_is_inactive():
    eip, efp, etp, etg, els = K.no_excitation()
    assert eip.shape == (K.N_EIP,) and eip.dtype == np.int64 and not eip.any()
    assert efp.shape == (K.N_EFP,) and not efp.any()
    assert etp.shape == etg.shape == (1, 2) and els.shape == (3, 1, 1)

