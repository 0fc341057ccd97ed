"""Pure-Python/NumPy twin of :func:`geardyn.dynamics._transverse_kernel.advance_transverse`.

Written separately from the kernel: each solve assembles the full effective matrix
``M + gamma dt (C + h q b g^T) + beta dt^2 (K0 + h k b g^T)`` and calls
:func:`numpy.linalg.solve` (no Sherman-Morrison), the geometry and friction come from the NumPy
functions of :mod:`geardyn.dynamics.transverse`, the map from
:func:`geardyn.stiffness.map.lookup_box_reference` and :func:`~geardyn.stiffness.map.lookup_reference`.
About a hundred times slower; the tests compare the two.
"""

from __future__ import annotations

import math

import numpy as np

from ..stiffness.map import MapArrays, lookup_box_reference, lookup_reference
from . import _kernel as K
from . import _transverse_kernel as T
from .transverse import friction_terms, line_of_action, mesh_deflection

__all__ = ["advance_transverse_python"]


def _vectors(nd, tip, tfp, phi, m_f, a_1, a_2):
    g = np.zeros(nd)
    b = np.zeros(nd)
    t = (-math.sin(phi), math.cos(phi))
    nn = (math.cos(phi), math.sin(phi))
    g[tip[T.TI_YP]], g[tip[T.TI_YG]] = t[1], -t[1]
    g[tip[T.TI_THP]], g[tip[T.TI_THG]] = tfp[T.TF_RB1], -tfp[T.TF_RB2]
    f = np.zeros(nd)
    f[tip[T.TI_YP]], f[tip[T.TI_YG]] = -m_f * nn[1], m_f * nn[1]
    f[tip[T.TI_THP]], f[tip[T.TI_THG]] = a_1, -a_2
    if tip[T.TI_XFREE] == 1:
        g[tip[T.TI_XP]], g[tip[T.TI_XG]] = t[0], -t[0]
        f[tip[T.TI_XP]], f[tip[T.TI_XG]] = -m_f * nn[0], m_f * nn[0]
    b[:] = g - f
    return g, b


def _geom(z, tip, rsum, t1t2):
    xf = tip[T.TI_XFREE] == 1
    xp = z[tip[T.TI_XP]] if xf else 0.0
    xg = z[tip[T.TI_XG]] if xf else 0.0
    d, tau, phi = line_of_action(xp, z[tip[T.TI_YP]], xg, z[tip[T.TI_YG]], rsum, t1t2)
    return float(d), float(tau), float(phi)


def _deflect(z, tip, tfp, t1t2):
    xf = tip[T.TI_XFREE] == 1
    return float(mesh_deflection(z[tip[T.TI_THP]], z[tip[T.TI_THG]],
                                 z[tip[T.TI_XP]] if xf else 0.0, z[tip[T.TI_YP]],
                                 z[tip[T.TI_XG]] if xf else 0.0, z[tip[T.TI_YG]],
                                 tfp[T.TF_RB1], tfp[T.TF_RB2], t1t2))


def advance_transverse_python(n_steps, rec_start, decim, out, j, st, ist, fail,
                              M, K0, C, Q0, Sinv, SK, SC, sQ, g0, u0, fp, ip, tfp, tip,
                              dd0, ddd, phase_a, length_a, mesh_angle, n_cycles, n_seg, kvals,
                              els, in_w, in_t, out_w, out_t, sp_t, sp_w, eip, efp, etp, etg):
    """Same arguments and results as the kernel (ignores ``Sinv``, ``SK``, ``SC``, ``sQ``,
    ``u0``)."""
    arrays = MapArrays(dd0, ddd, phase_a, length_a, mesh_angle, n_cycles, n_seg, kvals)
    nd = M.shape[0]
    s_v, s_a, s_sc = nd, 2 * nd, 3 * nd
    dt, beta, gam = fp[K.FP_DT], fp[K.FP_BETA], fp[K.FP_GAMMA]
    q, rsum, t1t2, d0 = fp[K.FP_QMB], fp[K.FP_RSUM], fp[K.FP_T1T2], fp[K.FP_D0]
    tol, rtol, hstep = fp[K.FP_TOL], fp[K.FP_RTOL], fp[K.FP_HSTEP]
    model2, ev_start, maxit = ip[K.IP_MODEL] == 2, ip[K.IP_EVAL] == 1, ip[K.IP_MAXIT]
    sep, in_nl, out_nl = ip[K.IP_SEP] == 1, ip[K.IP_IN_NL] == 1, ip[K.IP_OUT_NL] == 1
    xfree, mu, io = tip[T.TI_XFREE] == 1, tfp[T.TF_MU], int(tip[T.TI_OUT])
    rb1, rb2, pb = tfp[T.TF_RB1], tfp[T.TF_RB2], tfp[T.TF_PB]
    period = n_cycles * mesh_angle
    S = M + gam * dt * C + beta * dt * dt * K0
    share_maps = [MapArrays(dd0, ddd, phase_a, length_a, mesh_angle, n_cycles, n_seg, els[k])
                  for k in range(3)] if tip[T.TI_SHARES] == 1 else None

    def law(which, dz):
        if which == 0:
            w0 = fp[K.FP_IN_WREF]
            return (K._law_torque_py(ip[K.IP_INLAW], fp[K.FP_IN_P0], fp[K.FP_IN_P1],
                                     fp[K.FP_IN_P2], in_w, in_t, w0 + dz)
                    - fp[K.FP_IN_TREF] - fp[K.FP_IN_SLOPE] * dz)
        w0 = fp[K.FP_OUT_WREF]
        return -(K._law_torque_py(ip[K.IP_OUTLAW], fp[K.FP_OUT_P0], fp[K.FP_OUT_P1],
                                  fp[K.FP_OUT_P2], out_w, out_t, w0 + dz)
                 - fp[K.FP_OUT_TREF] - fp[K.FP_OUT_SLOPE] * dz)

    def friction_point(sx, tau, dd):
        th = (sx - tfp[T.TF_PITCH_S]) / rb1
        n_exit = math.floor((sx - tfp[T.TF_S_END]) / pb)
        s = sx - (n_exit + 1 + np.arange(3)) * pb
        inc = s >= tau - tfp[T.TF_U2TIP] - 1e-12
        if share_maps is not None:
            sh = np.array([float(lookup_reference(np.array(th), np.array(dd), m))
                           for m in share_maps])
        else:
            sh = np.ones(3)
        return np.array(friction_terms(s[inc], sh[inc], tau, rb1, rb2, mu))

    def friction(th, hwin, tau, dd):
        """Window average: the events (entry, exit, pitch point) of every pair within reach
        split the window; each part's midpoint value weighted by its length."""
        if mu == 0.0:
            return 0.0, 0.0, 0.0
        sx = tfp[T.TF_PITCH_S] + rb1 * th
        if not hwin > 0.0:
            return tuple(friction_point(sx, tau, dd))
        events = np.array([tau - tfp[T.TF_U2TIP], tfp[T.TF_S_END], tau * rb1 / (rb1 + rb2)])
        m = np.arange(-200, 201)[:, None]
        cand = (events[None, :] + m * pb - sx).ravel()
        cuts = np.sort(cand[(cand > -hwin) & (cand < hwin)])
        edges = np.concatenate([[-hwin], cuts, [hwin]])
        if cuts.size == 0:
            return tuple(friction_point(sx, tau, dd))
        acc = sum((hi - lo) * friction_point(sx + 0.5 * (lo + hi), tau, dd)
                  for lo, hi in zip(edges[:-1], edges[1:], strict=True) if hi > lo)
        return tuple(acc / (2.0 * hwin))

    def write(jj):
        out[jj, :nd], out[jj, nd:2 * nd] = st[:nd], st[s_v:s_v + nd]
        base, rb = s_sc, 2 * nd
        for rc, sc in ((T.RC_N, T.SC_N), (T.RC_DD, T.SC_DD), (T.RC_K, T.SC_K),
                       (T.RC_H, T.SC_H), (T.RC_IT, T.SC_IT), (T.RC_RB, T.SC_RB),
                       (T.RC_RA, T.SC_RA), (T.RC_PHI, T.SC_PHI), (T.RC_MF, T.SC_MF),
                       (T.RC_A1, T.SC_A1), (T.RC_A2, T.SC_A2), (T.RC_P, T.SC_P),
                       (T.RC_E, T.SC_E)):
            out[jj, rb + rc] = st[base + sc]

    n = int(ist[0])
    if ist[1] == 0 and n >= rec_start and (n - rec_start) % decim == 0 and j < out.shape[0]:
        write(j)
        j += 1
        ist[1] = 1
    for _ in range(n_steps):
        z, v, a = st[:nd].copy(), st[s_v:s_v + nd].copy(), st[s_a:s_a + nd].copy()
        xt = z + dt * v + dt * dt * (0.5 - beta) * a
        vt = v + dt * (1 - gam) * a
        load = Q0.copy()
        rip1 = 0.0
        if fp[K.FP_RIP_AMP] != 0.0:
            rip1 = fp[K.FP_RIP_AMP] * math.sin(fp[K.FP_RIP_ORDER] * ((n + 1) * hstep)
                                               + fp[K.FP_RIP_PHASE])
        if fp[K.FP_DRIVE_GAIN] != 0.0:
            rip1 += fp[K.FP_DRIVE_GAIN] * (float(np.interp((n + 1) * dt, sp_t, sp_w))
                                           - fp[K.FP_WREF])
        load[0] += rip1
        if in_nl:
            load[0] += law(0, v[0] + dt * a[0])
        if out_nl:
            load[io] += law(1, v[io] + dt * a[io])
        zc = z.copy() if ev_start else z + dt * v + 0.5 * dt * dt * a
        th_p = (np.fmod(n * hstep, period) if ev_start else np.fmod((n + 1) * hstep, period)) \
            + zc[tip[T.TI_THP]]
        hbox = 0.5 * abs(hstep + dt * v[tip[T.TI_THP]]) if ip[K.IP_WINDOW] == 1 else 0.0
        dc, tau, phi = _geom(zc, tip, rsum, t1t2)
        nn = n if ev_start else n + 1
        tha_p = np.fmod(nn * hstep, efp[K.EF_HPER]) + zc[tip[T.TI_THP]] \
            if eip[K.EI_ACTIVE] == 1 else 0.0
        ebar, frac, shift = 0.0, 1.0, 0.0
        it, res_b, res, a_prev, hh = 0, np.nan, np.nan, None, 1.0
        history_b2, history_k, take_next = [], [], False
        status = K.OK
        nf = kk = 0.0
        while True:
            b1 = dc if model2 else d0
            g, _ = _vectors(nd, tip, tfp, phi, 0.0, 0.0, 0.0)
            p_c = _deflect(zc, tip, tfp, t1t2) + g @ (xt - zc)
            if it == 0:  # contact by the free deflection at t_{n+1}
                a_free = np.linalg.solve(S, load - C @ vt - K0 @ xt)
                p_free = p_c + beta * dt * dt * (g @ a_free)
                hh = 0.0 if (sep and p_free < 0.0) else 1.0
                if eip[K.EI_ACTIVE] == 1:  # tooth errors: the 6-DOF twin's excitation
                    th0 = th_p - phi
                    th_k, ebar, frac, hh = K._excite_py(th0, tha_p - phi, b1, rsum, b1 - d0,
                                                        p_free, sep, eip, efp, etp, etg, els,
                                                        arrays)
                    shift = th0 - th_k
            th = th_p - phi - shift
            kk = lookup_box_reference(th, hbox, b1 - d0, arrays)
            if np.isnan(kk):
                status = K.MAP_RANGE
                break
            m_f, a_1, a_2 = friction(th, rb1 * hbox, tau, b1 - d0)
            g, b = _vectors(nd, tip, tfp, phi, m_f, a_1, a_2)
            ke = kk * frac
            Seff = S + hh * (beta * dt * dt * ke + gam * dt * q) * np.outer(b, g)
            rhs = load - C @ vt - K0 @ xt - hh * (ke * (p_c - ebar) + q * (g @ vt)) * b
            an = np.linalg.solve(Seff, rhs)
            nf = hh * (ke * (p_c + beta * dt * dt * (g @ an) - ebar)
                       + q * (g @ (vt + gam * dt * an)))
            zc = xt + beta * dt * dt * an
            dn, taun, phin = _geom(zc, tip, rsum, t1t2)
            b2 = dn
            conv = True
            if model2:
                res = abs(b1 - b2)
                if it == 0:
                    res_b = res
                conv = res < tol
            if xfree and not abs(phin - phi) * t1t2 < tol:
                conv = False
            if a_prev is not None:
                da = (an - a_prev) @ M @ (an - a_prev)
                sc = max(an @ M @ an, (nf * tfp[T.TF_UNORM]) ** 2)
                if da > rtol * rtol * sc:
                    conv = False
            if in_nl or out_nl:
                vn = vt + gam * dt * an
                dq0 = law(0, vn[0]) - (load[0] - Q0[0] - rip1) if in_nl else 0.0
                dq5 = law(1, vn[io]) - (load[io] - Q0[io]) if out_nl else 0.0
                if max(abs(dq0), abs(dq5)) > rtol * fp[K.FP_TSCALE]:
                    conv = False
                    load[0] += dq0
                    load[io] += dq5
            history_b2.append(b2)
            history_k.append(kk)
            if model2 and not conv:  # the 6-DOF twin's rule for a step without a fixed point
                conv, take_next = K.two_cycle_py(take_next, it, history_b2, history_k, res, tol)
            if conv:
                break
            if it >= maxit:
                status = K.NOT_CONVERGED
                break
            a_prev = an
            dc, tau, phi = dn, taun, phin
            it += 1
        if status != K.OK:
            fail[:] = [(n + 1) * dt, th_p, 0.0, zc[tip[T.TI_YP]], zc[tip[T.TI_YG]], b1 - d0, nf,
                       kk, it, res]
            return status, j
        zn, vn = xt + beta * dt * dt * an, vt + gam * dt * an
        st[:nd], st[s_v:s_v + nd], st[s_a:s_a + nd] = zn, vn, an
        _, _, phi_n = _geom(zn, tip, rsum, t1t2)
        p_n = _deflect(zn, tip, tfp, t1t2)
        sc = st[s_sc:]
        sc[T.SC_N], sc[T.SC_K], sc[T.SC_H], sc[T.SC_DD] = nf, kk * frac, hh, b2 - d0
        sc[T.SC_E] = ebar
        sc[T.SC_IT], sc[T.SC_RB], sc[T.SC_RA], sc[T.SC_RIP] = it, res_b, res, rip1
        sc[T.SC_PHI], sc[T.SC_MF], sc[T.SC_A1], sc[T.SC_A2] = phi_n, m_f, a_1, a_2
        sc[T.SC_P] = p_n
        if in_nl:
            sc[T.SC_QIN] = law(0, vn[0])
        if out_nl:
            sc[T.SC_QOUT] = law(1, vn[io])
        n += 1
        ist[0], ist[1] = n, 0
        disp = [abs(zn[tip[T.TI_YP]]), abs(zn[tip[T.TI_YG]])]
        if xfree:
            disp += [abs(zn[tip[T.TI_XP]]), abs(zn[tip[T.TI_XG]])]
        status = K.OK
        if not np.all(np.isfinite(np.r_[zn, vn, an, nf, p_n])):
            status = K.NONFINITE
        elif abs(p_n) > fp[K.FP_PLIM]:
            status = K.MESH_RUNAWAY
        elif max(disp) > fp[K.FP_YLIM]:
            status = K.BEARING_RUNAWAY
        if status != K.OK:
            fail[:] = [n * dt, np.fmod(n * hstep, period) + zn[tip[T.TI_THP]], p_n,
                       zn[tip[T.TI_YP]], zn[tip[T.TI_YG]], b2 - d0, nf, kk, it, res]
            return status, j
        if n >= rec_start and (n - rec_start) % decim == 0 and j < out.shape[0]:
            write(j)
            j += 1
            ist[1] = 1
    return K.OK, j
