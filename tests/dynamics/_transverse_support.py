"""An independent right-hand side of the transverse model for scipy's DOP853, and an explicit
involute construction of the flank approach (the oracles of ``test_transverse.py``)."""

from __future__ import annotations

import math

import numba
import numpy as np

from geardyn.dynamics.transverse import TransverseModel
from geardyn.stiffness.map import lookup


@numba.njit(cache=True)
def _rhs(y, par, mu, model2, pitch_s, s_end, pb, u2tip, dd0, ddd, phase_a, length_a,
         mesh_angle, n_cycles, n_seg, values):
    """Newton's laws for the 8 DOFs written from the free-body diagrams: contact point, force
    vectors and moments by cross products (not through the generalised-force vector)."""
    (Im, mp, Ip, mg, Ig, Io, kcp, kcg, kxp, kyp, kxg, kyg, qcp, qcg, qxp, qyp, qxg, qyg, qstp,
     qstg, qmb, rb1, rb2, t1t2, d0, t_in, c_out) = par
    rsum = rb1 + rb2
    th_m, xp, yp, th_p, xg, yg, th_g, th_o = y[0], y[1], y[2], y[3], y[4], y[5], y[6], y[7]
    w_m, vxp, vyp, w_p, vxg, vyg, w_g, w_o = (y[8], y[9], y[10], y[11], y[12], y[13], y[14],
                                              y[15])
    # pinion centre O1 = (xp, yp); gear centre O2 = (rsum + xg, t1t2 + yg)
    dx = rsum + xg - xp
    dy = t1t2 + yg - yp
    d = math.sqrt(dx * dx + dy * dy)
    tau = math.sqrt(d * d - rsum * rsum)
    phi = math.atan2(dy, dx) - math.atan2(tau, rsum)
    nx, ny = math.cos(phi), math.sin(phi)
    tx, ty = -ny, nx
    p = rb1 * th_p - rb2 * th_g - rsum * phi - tau + t1t2
    # d p / dt by a central difference of the same formula (independent of the gradient)
    hh = 1e-7
    dxp = rsum + (xg + hh * vxg) - (xp + hh * vxp)
    dyp = t1t2 + (yg + hh * vyg) - (yp + hh * vyp)
    dxm = rsum + (xg - hh * vxg) - (xp - hh * vxp)
    dym = t1t2 + (yg - hh * vyg) - (yp - hh * vyp)
    dpl = math.sqrt(dxp * dxp + dyp * dyp)
    dmi = math.sqrt(dxm * dxm + dym * dym)
    taup = math.sqrt(dpl * dpl - rsum * rsum)
    taum = math.sqrt(dmi * dmi - rsum * rsum)
    phip = math.atan2(dyp, dxp) - math.atan2(taup, rsum)
    phim = math.atan2(dym, dxm) - math.atan2(taum, rsum)
    pd = rb1 * w_p - rb2 * w_g - (rsum * (phip - phim) + (taup - taum)) / (2 * hh)
    dd = d - d0 if model2 else 0.0
    th = th_p - phi
    k = lookup(th, dd, dd0, ddd, phase_a, length_a, mesh_angle, n_cycles, n_seg, values)
    N = k * p + qmb * pd if p >= 0.0 else 0.0
    # forces and moments of the pairs in contact (equal shares), by cross products
    fpx = -N * tx
    fpy = -N * ty
    mom_p = -N * rb1
    mom_g = N * rb2  # in the gear's driven direction
    if mu > 0.0:
        s_th = pitch_s + rb1 * th
        n_exit = math.floor((s_th - s_end) / pb)
        cnt = 0
        for kk in range(3):
            s = s_th - (n_exit + 1 + kk) * pb
            if s >= tau - u2tip:
                cnt += 1
        s_pitch = tau * rb1 / rsum
        for kk in range(3):
            s = s_th - (n_exit + 1 + kk) * pb
            if s < tau - u2tip:
                continue
            f = mu * N / cnt * (1.0 if s < s_pitch else -1.0)   # on the pinion along -n
            # contact point relative to each centre
            r1x, r1y = rb1 * nx + s * tx, rb1 * ny + s * ty
            r2x, r2y = r1x - dx, r1y - dy
            fx, fy = -f * nx, -f * ny
            fpx += fx
            fpy += fy
            mom_p += r1x * fy - r1y * fx
            mom_g -= r2x * (-fy) - r2y * (-fx)   # gear's driven direction is clockwise
    out = np.empty(16)
    out[:8] = y[8:]
    out[8] = (t_in - kcp * (th_m - th_p) - qcp * (w_m - w_p)) / Im
    out[9] = (fpx - kxp * xp - qxp * vxp) / mp
    out[10] = (fpy - kyp * yp - qyp * vyp) / mp
    out[11] = (kcp * (th_m - th_p) + qcp * (w_m - w_p) + mom_p - qstp * w_p) / Ip
    out[12] = (-fpx - kxg * xg - qxg * vxg) / mg
    out[13] = (-fpy - kyg * yg - qyg * vyg) / mg
    out[14] = (mom_g - kcg * (th_g - th_o) - qcg * (w_g - w_o) - qstg * w_g) / Ig
    out[15] = (-c_out * w_o + kcg * (th_g - th_o) + qcg * (w_g - w_o)) / Io
    return out


def dop853_transverse(case, stiffness_map, model, y0, t_eval, rtol=1e-12):
    """Solve the transverse model (constant input torque, linear output law, equal load shares)
    with DOP853 from absolute ``y0 = [x, x']`` (8 + 8); returns shape (16, n)."""
    from scipy.integrate import solve_ivp

    tm = TransverseModel.from_case(case, stiffness_map)
    dyn = tm.base
    assert dyn.input_law.kind == "constant" and dyn.output_law.kind == "linear"
    assert "load_share" not in getattr(stiffness_map, "extra", {})
    q = dyn.damping
    pair = dyn.pair
    op = pair.operating(0.0, check=False)
    par = (dyn.M[0, 0], dyn.M[1, 1], dyn.M[2, 2], dyn.M[3, 3], dyn.M[4, 4], dyn.M[5, 5],
           -dyn.K0[0, 2], -dyn.K0[4, 5], tm.K0[1, 1], dyn.K0[1, 1], tm.K0[4, 4], dyn.K0[3, 3],
           q["q_cp"], q["q_cg"], tm.C0[1, 1], q["q_yp"], tm.C0[4, 4], q["q_yg"], q["q_stp"],
           q["q_stg"], dyn.q_mb, dyn.r_b1, dyn.r_b2, pair.design_t1t2,
           pair.design_centre_distance, dyn.input_law.coefficient, dyn.output_law.coefficient)
    arr = stiffness_map.arrays()
    geo = (pair.pitch_point_s, op.s_end, pair.base_pitch, op.t1t2 - op.s_start)

    def f(t, y):
        return _rhs(y, par, tm.friction_coefficient, model == "II", *geo, *arr)

    sol = solve_ivp(f, (0.0, float(t_eval[-1])), y0, method="DOP853", rtol=rtol, atol=1e-14,
                    t_eval=t_eval)
    assert sol.success, sol.message
    return sol.y


# ----------------------------------------------------------------------------- involutes
def _flank(rb, centre, angle, u):
    """Point at roll angle ``u`` of the involute whose string unwinds counter-clockwise from a
    base circle of radius ``rb`` at ``centre``: tangent point at polar angle ``angle - u``, the
    point ``rb u`` further along the circle's counter-clockwise tangent there."""
    a = angle - u
    return np.asarray(centre, float) + rb * np.array([math.cos(a) - u * math.sin(a),
                                                      math.sin(a) + u * math.cos(a)])


def flank_gap(rb1, rb2, centre1, centre2, start1, start2, u1, u2, half_range=0.15):
    """Smallest distance between a pinion flank and a gear flank [m] (both involutes of the kind
    of :func:`_flank`, starting at polar angles ``start1``, ``start2``), by bounded least squares
    over the two roll angles within ``half_range`` of ``u1``, ``u2`` (the working flanks; the
    rest of the curves, down to their cusps on the base circles, is no tooth): an explicit
    construction that knows nothing of lines of action. The pinion turning counter-clockwise by
    ``a`` is ``start1 + a``; the gear turning in its driven (clockwise) direction by ``b`` is
    ``start2 - b``."""
    from scipy.optimize import least_squares

    lo = [u1 - half_range, u2 - half_range]
    hi = [u1 + half_range, u2 + half_range]
    r = least_squares(lambda x: _flank(rb1, centre1, start1, x[0])
                      - _flank(rb2, centre2, start2, x[1]), [u1, u2], bounds=(lo, hi),
                      xtol=1e-15, ftol=1e-15, gtol=1e-15)
    assert np.all(r.x > np.array(lo) + 1e-6) and np.all(r.x < np.array(hi) - 1e-6)
    return math.sqrt(2.0 * r.cost)
