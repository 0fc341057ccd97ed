"""Helpers of the dynamics tests: small stiffness maps, single-DOF set-ups and an independent
right-hand side of the paper's equations for scipy's DOP853."""

from __future__ import annotations

import math

import numba
import numpy as np

import geardyn
from geardyn.dynamics import DynamicModel, make_setup
from geardyn.stiffness import StiffnessMap
from geardyn.stiffness.map import lookup

K_PAIR = 8e7  # N/m, one tooth pair of the paper's aluminium gears (docs/verification/dynamics.md)


def short_case(**over):
    """The paper's case with short times (tens of ms) and any dotted overrides."""
    base = {"simulation.settle_time": 0.0, "simulation.record_time": 0.02,
            "stiffness.method": "pem"}
    base.update({k.replace("__", "."): v for k, v in over.items()})
    return geardyn.paper_case(base)


def geometric_map(pair, dd=(-0.5e-3, 2e-3), n_d=6, k_pair=K_PAIR, n_seg=4) -> StiffnessMap:
    """Square-wave map: ``k_pair`` times the geometric number of pairs in contact."""
    pb, rb1 = pair.base_pitch, pair.pinion.base_radius

    def fn(theta, d):
        op = pair.operating(d, check=False)
        s = pair.pitch_point_s + rb1 * theta
        n_in = np.floor((s - op.s_start) / pb) - np.ceil((s - op.s_end) / pb) + 1
        return {"k_mb": k_pair * n_in}

    return StiffnessMap.from_function(pair, np.linspace(*dd, n_d), fn, n_seg=n_seg)


def triangle_map(pair, dd=(-0.5e-3, 2e-3), n_d=11, k_lo=8e7, k_hi=1.4e8, slope=40.0
                 ) -> StiffnessMap:
    """A continuous map, linear in each contact zone: ``k_hi`` at the entry handover, ``k_lo`` at
    the exit handover, times ``(1 - slope dd)``. Two kinks per mesh cycle (at the handovers, which
    move with ``dd``), otherwise smooth: the "smooth stiffness" of the convergence tests, which
    DOP853 can integrate tightly in seconds."""
    def fn(theta, d):
        n = theta.size // 4
        return {"k_mb": np.tile([k_lo, k_hi, k_hi, k_lo], n) * (1 - slope * d)}

    return StiffnessMap.from_function(pair, np.linspace(*dd, n_d), fn, n_seg=2)


def constant_map(pair, k) -> StiffnessMap:
    """One grid line, constant ``k`` [N/m]."""
    return StiffnessMap.from_function(pair, [0.0], lambda th, d: {"k_mb": np.full(th.size, k)},
                                      n_seg=2)


def sdof_setup(stiffness_map, *, m=1.0, c=0.0, dt=1e-3, speed=0.0, separation=False,
               force=0.0, **kw):
    """A single DOF ``m y'' + c y' + k(theta) y = force`` on DOF 1 (``g = e_1``); the other DOFs
    are unit masses without forces (the pinion angle DOF stays at its reference rotation)."""
    M = np.diag([1.0, m, 1.0, 1.0, 1.0, 1.0])
    Z = np.zeros((6, 6))
    g = np.array([0.0, 1.0, 0.0, 0.0, 0.0, 0.0])
    Q0 = np.zeros(6)
    Q0[1] = force
    return make_setup(M, Z, Z, g, Q0, stiffness_map, dt=dt, q_mb=c, speed=speed,
                      separation=separation, **kw)


# --------------------------------------------------------------------------- DOP853 reference
@numba.njit(cache=True)
def _rhs(y, par, model2, dd0, ddd, phase_a, length_a, mesh_angle, n_cycles, n_seg, values):
    (Im, mp, Ip, mg, Ig, Io, kcp, kcg, kyp, kyg, qcp, qcg, qyp, qyg, qstp, qstg, qmb, rb1, rb2,
     rsum, t1t2, d0, t_in, c_out) = par
    th_m, yp, th_p, yg, th_g, th_o = y[0], y[1], y[2], y[3], y[4], y[5]
    w_m, vp, w_p, vg, w_g, w_o = y[6], y[7], y[8], y[9], y[10], y[11]
    p = yp + rb1 * th_p - yg - rb2 * th_g          # eq. 15
    pd = vp + rb1 * w_p - vg - rb2 * w_g
    d = math.sqrt(rsum * rsum + (t1t2 + yg - yp) ** 2)  # eq. 4
    dd = d - d0 if model2 else 0.0
    k = lookup(th_p, dd, dd0, ddd, phase_a, length_a, mesh_angle, n_cycles, n_seg, values)
    h = 1.0 if p >= 0.0 else 0.0
    N = k * p + qmb * pd                              # eq. 14
    out = np.empty(12)
    out[:6] = y[6:]
    out[6] = (t_in - kcp * (th_m - th_p) - qcp * (w_m - w_p)) / Im                  # eq. 9
    out[7] = (-h * N - kyp * yp - qyp * vp) / mp                                     # eq. 10
    out[8] = (kcp * (th_m - th_p) + qcp * (w_m - w_p) - h * N * rb1 - qstp * w_p) / Ip  # eq. 11
    out[9] = (h * N - kyg * yg - qyg * vg) / mg                                      # eq. 12
    out[10] = (h * N * rb2 - kcg * (th_g - th_o) - qcg * (w_g - w_o) - qstg * w_g) / Ig  # eq. 13
    out[11] = (-c_out * w_o + kcg * (th_g - th_o) + qcg * (w_g - w_o)) / Io          # eq. 16
    return out


def dop853_reference(case, stiffness_map, model, y0, t_eval, rtol=1e-12):
    """Solve eqs. 9-16 (constant input torque, linear output law) with scipy's DOP853.

    ``y0`` = absolute ``[x, x']`` at ``t = 0``. Returns the solution at ``t_eval``, shape (12, n).
    """
    from scipy.integrate import solve_ivp

    dyn = DynamicModel.from_case(case, stiffness_map)
    assert dyn.input_law.kind == "constant" and dyn.output_law.kind == "linear"
    q = dyn.damping
    pair = dyn.pair
    par = (dyn.M[0, 0], dyn.M[1, 1], dyn.M[2, 2], dyn.M[3, 3], dyn.M[4, 4], dyn.M[5, 5],
           -dyn.K0[0, 2], -dyn.K0[4, 5], dyn.K0[1, 1], dyn.K0[3, 3], q["q_cp"], q["q_cg"],
           q["q_yp"], q["q_yg"], q["q_stp"], q["q_stg"], dyn.q_mb, dyn.r_b1, dyn.r_b2,
           pair.base_radius_sum, pair.design_t1t2, pair.design_centre_distance,
           dyn.input_law.coefficient, dyn.output_law.coefficient)
    arr = stiffness_map.arrays()
    m2 = model == "II"

    def f(t, y):
        return _rhs(y, par, m2, *arr)

    sol = solve_ivp(f, (0.0, float(t_eval[-1])), y0, method="DOP853", rtol=rtol, atol=1e-14,
                    t_eval=t_eval)
    assert sol.success, sol.message
    return sol.y
