r"""The time loop of the transverse (x-y) model with sliding friction: numba kernel and twin.

The scheme is the one of :mod:`geardyn.dynamics._kernel` (average-acceleration Newmark in
residual form on the deviations ``z`` from a rigid rotation at the steady speed, the stiffness
at the second-order predictor or at the start of the step, the map averaged over the step's
rotation, model II's centre-distance iteration with its two-cycle rule, nonlinear load laws
iterated to ``rtol``). What the transverse model adds (:mod:`geardyn.dynamics.transverse` derives
every term):

* the geometry of the step, at the configuration ``z_c`` (first the Taylor predictor of
  ``z_{n+1}``, then each solve's ``z_{n+1}``): ``D = (r_sum + x_g - x_p, T1T2 + y_g - y_p)``,
  ``d = |D|``, ``tau = sqrt(d^2 - r_sum^2)``, the rotation of the line of action
  ``phi = atan2(D_y, D_x) - atan2(tau, r_sum)``, its direction ``t = (-sin phi, cos phi)`` and
  normal ``n = (cos phi, sin phi)``;
* the exact mesh deflection ``p(z) = r_b1 theta_p - r_b2 theta_g - r_sum phi - tau + T1T2``,
  linearised about ``z_c`` with its exact gradient ``g_c`` (``+t`` on the pinion centre, ``-t``
  on the gear's, ``r_b1``, ``-r_b2`` on the rotations): ``p_{n+1} = p(z_c) + g_c (z_{n+1} - z_c)``;
* the map read at ``theta_p - phi`` (the pinion's roll relative to the turned line of action)
  and, for model II, ``dd = d(z_c) - d_0``;
* sliding friction: the generalised mesh force is ``-N b_c`` with ``b_c = g_c - f_c``, ``f_c``
  the friction directions per unit normal load (``mu`` times the load-share weighted, signed
  moment arms ``s_k``, ``tau - s_k`` and the normal ``n``); the sign of each pair is
  ``sign(s_pitch - s_k)``; the terms are averaged over the step's roll like the stiffness window
  (split where a pair enters or leaves contact or crosses the pitch point);
* the rank-one update with two vectors: ``u_c = S^-1 b_c``, ``sigma = g_c^T u_c``,
  ``N = (k p~ + q p~' + c g_c^T w) / (1 + c sigma)``, ``a = w - N u_c``;
* iteration until the geometry is consistent: ``|phi(z_{n+1}) - phi_c| T1T2 < tol`` and the
  mass-norm acceleration update below ``rtol`` (and model II's ``|b1 - b2| < tol``).

With the centres held on the line of action (``x`` fixed, ``XFREE = 0``) and no friction,
``phi = 0``, ``g_c = g`` and ``u_c = u`` are constants and every operation is the 6-DOF kernel's:
the paper's model is the special case (``tests/dynamics/test_transverse.py``).

The twin ``advance_transverse_python`` (module ``_transverse_twin``) is written separately: it
assembles the full effective matrix ``S + c b_c g_c^T`` and calls :func:`numpy.linalg.solve`,
reads the map with :func:`geardyn.stiffness.map.lookup_reference` and the geometry with the NumPy
functions of :mod:`geardyn.dynamics.transverse`, and averages the friction over the step's roll
with its own search of the events.
"""

from __future__ import annotations

import math

import numba
import numpy as np

from ..stiffness.map import lookup_box
from . import _kernel as K

__all__ = ["advance_transverse", "state_layout", "record_layout",
           "N_TFP", "N_TIP"]

# transverse float parameters
TF_RB1, TF_RB2, TF_MU, TF_PITCH_S, TF_S_END, TF_PB, TF_U2TIP, TF_SIGMA0, TF_UNORM = range(9)
N_TFP = 9
# transverse integer parameters: DOF indices (-1: held at zero) and switches
TI_XP, TI_YP, TI_THP, TI_XG, TI_YG, TI_THG, TI_OUT, TI_XFREE, TI_SHARES = range(9)
N_TIP = 9
# scalars after z, v, a in the state
SC_N, SC_K, SC_H, SC_DD, SC_IT, SC_RB, SC_RA, SC_QIN, SC_QOUT, SC_RIP = range(10)
SC_PHI, SC_MF, SC_A1, SC_A2, SC_P, SC_E = 10, 11, 12, 13, 14, 15
N_SC = 16
# record columns after z, v
RC_N, RC_DD, RC_K, RC_H, RC_IT, RC_RB, RC_RA, RC_PHI, RC_MF, RC_A1, RC_A2, RC_P, RC_E = range(13)
N_RC = 13


def state_layout(nd: int) -> tuple[int, int, int, int, int]:
    """``(S_Z, S_V, S_A, S_SC, N_STATE)`` offsets of a state with ``nd`` DOFs."""
    return 0, nd, 2 * nd, 3 * nd, 3 * nd + N_SC


def record_layout(nd: int) -> tuple[int, int, int, int]:
    """``(R_Z, R_V, R_SC, N_REC)`` offsets of a record row with ``nd`` DOFs."""
    return 0, nd, 2 * nd, 2 * nd + N_RC


@numba.njit(cache=True, nogil=True, fastmath=False)
def _geometry(z, tip, rsum, t1t2):
    """``(d, tau, phi)`` of the configuration ``z`` [m, m, rad]."""
    dy = t1t2 + z[tip[TI_YG]] - z[tip[TI_YP]]
    if tip[TI_XFREE] == 1:
        dx = rsum + z[tip[TI_XG]] - z[tip[TI_XP]]
        d = math.sqrt(dx * dx + dy * dy)
        tau = math.sqrt(max(d * d - rsum * rsum, 0.0))
        phi = math.atan2(dy, dx) - math.atan2(tau, rsum)
    else:  # the 6-DOF model's eq. 4; the line of action keeps its direction
        d = math.sqrt(rsum * rsum + dy * dy)
        tau = abs(dy)
        phi = 0.0
    return d, tau, phi


@numba.njit(cache=True, nogil=True, fastmath=False)
def _friction_point(sx, tau, dd, tfp, tip, dd0, ddd, phase_a, length_a, mesh_angle, n_cycles,
                    n_seg, kvals, els):
    """Friction per unit normal load at the roll position ``sx = s_pitch0 + r_b1 theta`` of the
    map angle ``theta``: ``(m_f, A_1, A_2)``.

    ``m_f = mu sum w_k sg_k`` (force along the normal ``n`` on the gear, minus on the pinion),
    ``A_1 = mu sum w_k sg_k s_k`` and ``A_2 = mu sum w_k sg_k (tau - s_k)`` [m] (moments on the
    pinion and, against its rotation, the gear) over the slots in contact; ``w_k`` the map's
    load shares scaled to sum 1 (equal shares without them), ``sg_k = sign(s_pitch - s_k)``.
    """
    rb1 = tfp[TF_RB1]
    pb = tfp[TF_PB]
    th = (sx - tfp[TF_PITCH_S]) / rb1
    n_exit = math.floor((sx - tfp[TF_S_END]) / pb)
    s_start = tau - tfp[TF_U2TIP]
    s_pitch = tau * rb1 / (rb1 + tfp[TF_RB2])
    sh0 = sh1 = sh2 = 1.0
    if tip[TI_SHARES] == 1:
        _, sh0, sh1, sh2 = K._lookup4(th, dd, dd0, ddd, phase_a, length_a, mesh_angle,
                                      n_cycles, n_seg, kvals, els)
    tot = 0.0
    mf = 0.0
    a1 = 0.0
    a2 = 0.0
    for k in range(3):
        s = sx - (n_exit + 1 + k) * pb
        if s < s_start - 1e-12:
            continue
        sh = sh0 if k == 0 else (sh1 if k == 1 else sh2)
        sg = 1.0 if s < s_pitch else (-1.0 if s > s_pitch else 0.0)
        tot += sh
        mf += sh * sg
        a1 += sh * sg * s
        a2 += sh * sg * (tau - s)
    if not tot > 0.0:
        return 0.0, 0.0, 0.0
    mu = tfp[TF_MU]
    return mu * mf / tot, mu * a1 / tot, mu * a2 / tot


@numba.njit(cache=True, nogil=True, fastmath=False)
def _friction(th, hs, tau, dd, tfp, tip, dd0, ddd, phase_a, length_a, mesh_angle, n_cycles,
              n_seg, kvals, els):
    """Friction per unit normal load ``(m_f, A_1, A_2)`` at map angle ``th``, averaged over the
    step's roll ``[s - hs, s + hs]`` (``hs`` [m]; 0: the point value).

    The terms jump where a pair enters (``s_k = s_start``) or leaves (``s_k = s_end``) contact and
    where it crosses the pitch point (the sign). The window is split at those events (at most
    one of each kind: the window is far shorter than a base pitch) and each part evaluated at its
    midpoint, weighted by its length: exact for the piecewise-linear terms, as
    :func:`geardyn.stiffness.map.lookup_box` is for the stiffness, so the scheme keeps order 2.
    Without an event inside the window the point value is returned.
    """
    if tfp[TF_MU] == 0.0:
        return 0.0, 0.0, 0.0
    rb1 = tfp[TF_RB1]
    pb = tfp[TF_PB]
    sx = tfp[TF_PITCH_S] + rb1 * th
    if not hs > 0.0:
        return _friction_point(sx, tau, dd, tfp, tip, dd0, ddd, phase_a, length_a, mesh_angle,
                               n_cycles, n_seg, kvals, els)
    ev0 = tau - tfp[TF_U2TIP]
    ev1 = tfp[TF_S_END]
    ev2 = tau * rb1 / (rb1 + tfp[TF_RB2])
    br = np.empty(3)
    nb = 0
    for c in (ev0, ev1, ev2):
        # offset delta in (-hs, hs) with sx + delta = c + m pb for an integer m
        dl = (c - sx + hs) % pb - hs
        if -hs < dl < hs:
            br[nb] = dl
            nb += 1
    if nb == 0:
        return _friction_point(sx, tau, dd, tfp, tip, dd0, ddd, phase_a, length_a, mesh_angle,
                               n_cycles, n_seg, kvals, els)
    for i in range(nb):  # sort the breakpoints
        for k in range(i + 1, nb):
            if br[k] < br[i]:
                t = br[i]
                br[i] = br[k]
                br[k] = t
    mf = 0.0
    a1 = 0.0
    a2 = 0.0
    lo = -hs
    for i in range(nb + 1):
        hi = br[i] if i < nb else hs
        if hi > lo:
            m, p1, p2 = _friction_point(sx + 0.5 * (lo + hi), tau, dd, tfp, tip, dd0, ddd,
                                        phase_a, length_a, mesh_angle, n_cycles, n_seg, kvals,
                                        els)
            mf += (hi - lo) * m
            a1 += (hi - lo) * p1
            a2 += (hi - lo) * p2
        lo = hi
    return mf / (2.0 * hs), a1 / (2.0 * hs), a2 / (2.0 * hs)


@numba.njit(cache=True, nogil=True, fastmath=False)
def _mesh_vectors(z, tip, tfp, phi, mf, a1, a2, gc, bc):
    """Fill the deflection gradient ``gc`` and the force direction ``bc = gc - f`` at ``phi``."""
    for i in range(gc.shape[0]):
        gc[i] = 0.0
        bc[i] = 0.0
    tx = -math.sin(phi)
    ty = math.cos(phi)
    nx = math.cos(phi)
    ny = math.sin(phi)
    gc[tip[TI_YP]] = ty
    gc[tip[TI_YG]] = -ty
    gc[tip[TI_THP]] = tfp[TF_RB1]
    gc[tip[TI_THG]] = -tfp[TF_RB2]
    bc[tip[TI_YP]] = ty + mf * ny
    bc[tip[TI_YG]] = -ty - mf * ny
    bc[tip[TI_THP]] = tfp[TF_RB1] - a1
    bc[tip[TI_THG]] = -tfp[TF_RB2] + a2
    if tip[TI_XFREE] == 1:
        gc[tip[TI_XP]] = tx
        gc[tip[TI_XG]] = -tx
        bc[tip[TI_XP]] = tx + mf * nx
        bc[tip[TI_XG]] = -tx - mf * nx


@numba.njit(cache=True, nogil=True, fastmath=False)
def _deflection(z, tip, tfp, rsum, t1t2, tau, phi):
    """Exact mesh deflection ``r_b1 theta_p - r_b2 theta_g - r_sum phi - tau + T1T2`` [m]."""
    return (tfp[TF_RB1] * z[tip[TI_THP]] - tfp[TF_RB2] * z[tip[TI_THG]]) \
        - rsum * phi - tau + t1t2


@numba.njit(cache=True, nogil=True, fastmath=False)
def advance_transverse(n_steps, rec_start, decim, out, j, st, ist, fail,
                       M, K0, C, Q0, Sinv, SK, SC, sQ, g0, u0, fp, ip, tfp, tip,
                       dd0, ddd, phase_a, length_a, mesh_angle, n_cycles, n_seg, kvals, els,
                       in_w, in_t, out_w, out_t, sp_t, sp_w, eip, efp, etp, etg):
    """Advance the transverse state ``st`` by up to ``n_steps`` steps (see the module text).

    Same calling convention as :func:`geardyn.dynamics._kernel.advance`; ``fp``/``ip`` are the
    6-DOF parameter arrays (time step, tolerances, laws, ripple, drive, model, window), ``tfp`` /
    ``tip`` the transverse ones. Returns ``(status, j)``.
    """
    nd = M.shape[0]
    s_v = nd
    s_a = 2 * nd
    s_sc = 3 * nd
    dt = fp[K.FP_DT]
    beta = fp[K.FP_BETA]
    gam = fp[K.FP_GAMMA]
    q = fp[K.FP_QMB]
    rsum = fp[K.FP_RSUM]
    t1t2 = fp[K.FP_T1T2]
    d0 = fp[K.FP_D0]
    tol = fp[K.FP_TOL]
    rtol = fp[K.FP_RTOL]
    hstep = fp[K.FP_HSTEP]
    plim = fp[K.FP_PLIM]
    ylim = fp[K.FP_YLIM]
    tscale = fp[K.FP_TSCALE]
    model2 = ip[K.IP_MODEL] == 2
    ev_start = ip[K.IP_EVAL] == 1
    maxit = ip[K.IP_MAXIT]
    box = ip[K.IP_WINDOW] == 1
    sep = ip[K.IP_SEP] == 1
    in_nl = ip[K.IP_IN_NL] == 1
    out_nl = ip[K.IP_OUT_NL] == 1
    rip = fp[K.FP_RIP_AMP] != 0.0 or fp[K.FP_DRIVE_GAIN] != 0.0
    xfree = tip[TI_XFREE] == 1
    mu = tfp[TF_MU]
    const_vec = (not xfree) and mu == 0.0
    io = tip[TI_OUT]
    ithp = tip[TI_THP]
    eact = eip[K.EI_ACTIVE] == 1  # tooth errors, relief, runout (geardyn.modifications)
    hper = efp[K.EF_HPER]
    rb1 = tfp[TF_RB1]
    bdt2 = beta * dt * dt
    gdt = gam * dt
    period = n_cycles * mesh_angle
    dtr = 0.0

    xt = np.empty(nd)
    vt = np.empty(nd)
    w = np.empty(nd)
    an = np.empty(nd)
    ap = np.empty(nd)
    zc = np.empty(nd)
    gc = np.empty(nd)
    bc = np.empty(nd)
    uc = np.empty(nd)

    n = ist[0]
    if ist[1] == 0 and n >= rec_start and (n - rec_start) % decim == 0 and j < out.shape[0]:
        _write_t(out, j, st, nd)
        j += 1
        ist[1] = 1

    for _ in range(n_steps):
        # ---- predictors
        for i in range(nd):
            xt[i] = st[i] + dt * st[s_v + i] + dt * dt * (0.5 - beta) * st[s_a + i]
            vt[i] = st[s_v + i] + dt * (1.0 - gam) * st[s_a + i]
        qin = 0.0
        qout = 0.0
        if in_nl:
            qin = K._q_in(fp, ip, in_w, in_t, st[s_v] + dt * st[s_a])
        if out_nl:
            qout = K._q_out(fp, ip, out_w, out_t, st[s_v + io] + dt * st[s_a + io])
        for i in range(nd):
            acc = sQ[i]
            for k in range(nd):
                acc -= SC[i, k] * vt[k] + SK[i, k] * xt[k]
            w[i] = acc
        if in_nl or out_nl:
            for i in range(nd):
                w[i] += Sinv[i, 0] * qin + Sinv[i, io] * qout
        if rip:
            dtr = K._input_forcing(fp, n + 1, sp_t, sp_w)
            for i in range(nd):
                w[i] += Sinv[i, 0] * dtr
        # ---- the configuration the geometry is first evaluated at
        for i in range(nd):
            if ev_start:
                zc[i] = st[i]
            else:
                zc[i] = st[i] + dt * st[s_v + i] + 0.5 * dt * dt * st[s_a + i]
        th_ref = np.fmod(n * hstep, period) if ev_start else np.fmod((n + 1) * hstep, period)
        hbox = 0.5 * abs(hstep + dt * st[s_v + ithp]) if box else 0.0
        # typed, not literal: one compiled no_fixed_point and _fail (see _kernel._input_forcing)
        it = np.int64(0)
        res_b = np.nan
        res = np.nan
        kk = 0.0
        nf = 0.0
        hh = 1.0
        b2 = d0
        b2_m1 = np.nan
        b2_m2 = np.nan
        k_first = 0.0
        k_m1 = 0.0
        take_next = bool(it)  # False
        status = K.OK
        dc, tau, phi = _geometry(zc, tip, rsum, t1t2)
        th_p = th_ref + zc[ithp]  # the predictor's pinion angle, kept over the iterations
        tha_p = 0.0
        if eact:
            tha_p = (np.fmod(n * hstep, hper) if ev_start else np.fmod((n + 1) * hstep, hper)) \
                + zc[ithp]
        mf = 0.0
        a1 = 0.0
        a2 = 0.0
        pt = 0.0
        ebar = 0.0
        frac = 1.0
        shift = 0.0
        k_pre = np.nan
        while True:
            b1 = dc if model2 else d0
            gw = 0.0
            pdt = 0.0
            sig = 0.0
            if const_vec:
                pt = 0.0
                for i in range(nd):
                    gw += g0[i] * w[i]
                    pt += g0[i] * xt[i]
                    pdt += g0[i] * vt[i]
            else:
                _mesh_vectors(zc, tip, tfp, phi, 0.0, 0.0, 0.0, gc, bc)
                pt = _deflection(zc, tip, tfp, rsum, t1t2, tau, phi)
                for i in range(nd):
                    gw += gc[i] * w[i]
                    pt += gc[i] * (xt[i] - zc[i])
                    pdt += gc[i] * vt[i]
            if it == 0:  # contact decided once, by the free deflection at t_{n+1} (eq. 15)
                hh = 1.0
                if sep and pt + bdt2 * gw < 0.0:
                    hh = 0.0
                if eact:  # tooth errors: e_bar, the loaded pairs' share, runout's angle shift
                    th0 = th_p - phi
                    th_k, ebar, frac, hh, k_pre = K._excite(
                        th0, tha_p - phi, b1, rsum, b1 - d0, pt + bdt2 * gw, sep, eip, efp,
                        etp, etg, els, dd0, ddd, phase_a, length_a, mesh_angle, n_cycles, n_seg,
                        kvals)
                    shift = th0 - th_k
            th = th_p - phi - shift
            if it == 0 and k_pre == k_pre and hbox <= 0.0:  # found with the shares there
                kk = k_pre
            else:
                kk = lookup_box(th, hbox, b1 - d0, dd0, ddd, phase_a, length_a, mesh_angle,
                                n_cycles, n_seg, kvals)
            if kk != kk:
                status = K.MAP_RANGE
                break
            if it == 0:
                k_first = kk
            mf, a1, a2 = _friction(th, rb1 * hbox, tau, b1 - d0, tfp, tip, dd0, ddd, phase_a,
                                   length_a, mesh_angle, n_cycles, n_seg, kvals, els)
            if const_vec:
                for i in range(nd):
                    uc[i] = u0[i]
                sig = tfp[TF_SIGMA0]
            else:
                _mesh_vectors(zc, tip, tfp, phi, mf, a1, a2, gc, bc)
                for i in range(nd):
                    acc = 0.0
                    for k in range(nd):
                        acc += Sinv[i, k] * bc[k]
                    uc[i] = acc
                for i in range(nd):
                    sig += gc[i] * uc[i]
            keff = kk * frac
            if hh > 0.0:
                c = bdt2 * keff + gdt * q
                nf = (keff * (pt - ebar) + q * pdt + c * gw) / (1.0 + c * sig)
            else:
                nf = 0.0
            for i in range(nd):
                an[i] = w[i] - nf * uc[i]
                zc[i] = xt[i] + bdt2 * an[i]
            dn, taun, phin = _geometry(zc, tip, rsum, t1t2)
            b2 = dn
            conv = True
            if model2:
                res = abs(b1 - b2)
                if it == 0:
                    res_b = res
                if not res < tol:
                    conv = False
            if xfree and not abs(phin - phi) * t1t2 < tol:
                conv = False
            if it > 0 and not K.update_small(an, ap, M, nf * tfp[TF_UNORM], rtol):
                conv = False
            if in_nl or out_nl:
                dq0 = 0.0
                dq5 = 0.0
                if in_nl:
                    dq0 = K._q_in(fp, ip, in_w, in_t, vt[0] + gdt * an[0]) - qin
                if out_nl:
                    dq5 = K._q_out(fp, ip, out_w, out_t, vt[io] + gdt * an[io]) - qout
                if abs(dq0) > rtol * tscale or abs(dq5) > rtol * tscale:
                    conv = False
                    qin += dq0
                    qout += dq5
                    for i in range(nd):
                        w[i] += Sinv[i, 0] * dq0 + Sinv[i, io] * dq5
            if model2 and not conv:  # a step without a fixed point (the 6-DOF kernel's rule)
                conv, take_next = K.no_fixed_point(take_next, it, b2, b2_m2, res, tol, kk,
                                                   k_first, k_m1)
            if conv:
                break
            if it >= maxit:
                status = K.NOT_CONVERGED
                break
            for i in range(nd):
                ap[i] = an[i]
            b2_m2 = b2_m1
            b2_m1 = b2
            k_m1 = kk
            dc = dn
            tau = taun
            phi = phin
            it += 1
        if status != K.OK:
            K._fail(fail, (n + 1) * dt, th_p, pt, zc[tip[TI_YP]], zc[tip[TI_YG]],
                    b1 - d0, nf, kk, it, res)
            return status, j
        # ---- commit
        for i in range(nd):
            st[i] = xt[i] + bdt2 * an[i]
            st[s_v + i] = vt[i] + gdt * an[i]
            st[s_a + i] = an[i]
        d_n, tau_n, phi_n = _geometry(st, tip, rsum, t1t2)
        p_n = 0.0
        if const_vec:
            for i in range(nd):
                p_n += g0[i] * st[i]
        else:
            p_n = _deflection(st, tip, tfp, rsum, t1t2, tau_n, phi_n)
        st[s_sc + SC_N] = nf
        st[s_sc + SC_K] = kk * frac
        st[s_sc + SC_E] = ebar
        st[s_sc + SC_H] = hh
        st[s_sc + SC_DD] = b2 - d0
        st[s_sc + SC_IT] = it
        st[s_sc + SC_RB] = res_b
        st[s_sc + SC_RA] = res
        st[s_sc + SC_RIP] = dtr
        st[s_sc + SC_PHI] = phi_n
        st[s_sc + SC_MF] = mf
        st[s_sc + SC_A1] = a1
        st[s_sc + SC_A2] = a2
        st[s_sc + SC_P] = p_n
        if in_nl:
            st[s_sc + SC_QIN] = K._q_in(fp, ip, in_w, in_t, st[s_v])
        if out_nl:
            st[s_sc + SC_QOUT] = K._q_out(fp, ip, out_w, out_t, st[s_v + io])
        n += 1
        ist[0] = n
        ist[1] = 0
        # ---- sanity
        tot = nf + p_n
        for i in range(nd):
            tot += st[s_v + i] + st[s_a + i]
        ymax = abs(st[tip[TI_YP]])
        if abs(st[tip[TI_YG]]) > ymax:
            ymax = abs(st[tip[TI_YG]])
        if xfree:
            if abs(st[tip[TI_XP]]) > ymax:
                ymax = abs(st[tip[TI_XP]])
            if abs(st[tip[TI_XG]]) > ymax:
                ymax = abs(st[tip[TI_XG]])
        if not math.isfinite(tot):
            status = K.NONFINITE
        elif abs(p_n) > plim:
            status = K.MESH_RUNAWAY
        elif ymax > ylim:
            status = K.BEARING_RUNAWAY
        if status != K.OK:
            K._fail(fail, n * dt, np.fmod(n * hstep, period) + st[ithp], p_n, st[tip[TI_YP]],
                    st[tip[TI_YG]], b2 - d0, nf, kk, it, res)
            return status, j
        if n >= rec_start and (n - rec_start) % decim == 0 and j < out.shape[0]:
            _write_t(out, j, st, nd)
            j += 1
            ist[1] = 1
    return K.OK, j


@numba.njit(cache=True, nogil=True, fastmath=False)
def _write_t(out, j, st, nd):
    for i in range(nd):
        out[j, i] = st[i]
        out[j, nd + i] = st[nd + i]
    base = 3 * nd
    rb = 2 * nd
    out[j, rb + RC_N] = st[base + SC_N]
    out[j, rb + RC_DD] = st[base + SC_DD]
    out[j, rb + RC_K] = st[base + SC_K]
    out[j, rb + RC_H] = st[base + SC_H]
    out[j, rb + RC_IT] = st[base + SC_IT]
    out[j, rb + RC_RB] = st[base + SC_RB]
    out[j, rb + RC_RA] = st[base + SC_RA]
    out[j, rb + RC_PHI] = st[base + SC_PHI]
    out[j, rb + RC_MF] = st[base + SC_MF]
    out[j, rb + RC_A1] = st[base + SC_A1]
    out[j, rb + RC_A2] = st[base + SC_A2]
    out[j, rb + RC_P] = st[base + SC_P]
    out[j, rb + RC_E] = st[base + SC_E]
