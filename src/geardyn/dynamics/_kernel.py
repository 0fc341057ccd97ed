r"""The time loop: one numba kernel for a chunk of steps, and its pure-Python twin.

The discrete equations (Newmark in residual form; HHT-alpha when ``alpha != 0``)
-------------------------------------------------------------------------------
The unknowns are the deviations ``z = x - x_ref`` from a rigid rotation at the steady speed,
``x_ref = w t e`` with ``e = [1, 0, 1, 0, r_b1/r_b2, r_b1/r_b2]``. Because ``K0 e = 0`` and
``g^T e = 0`` the deviations obey the same equations as ``x`` with a constant forcing ``Q0``, and
they stay small for ever, so the absolute angles (which grow without bound, ~1e4 rad after 100 s)
never enter the arithmetic: no precision decays over a long run. The pinion angle the stiffness
map needs is ``fmod((n+1) w dt, period) + z_p``, formed from the integer step count.

Per step ``n -> n+1`` with ``beta``, ``gamma`` (1/4, 1/2 for average acceleration;
``(1-alpha)^2/4``, ``1/2 - alpha`` for HHT):

.. math::
   z_{n+1} = \tilde z + \beta dt^2 a_{n+1},\quad \tilde z = z_n + dt v_n + (1/2-\beta) dt^2 a_n

   v_{n+1} = \tilde v + \gamma dt a_{n+1},\quad \tilde v = v_n + (1-\gamma) dt a_n

   M a_{n+1} + (1+\alpha)[C v_{n+1} + K_0 z_{n+1} + N_{n+1} g - Q(v_{n+1})]
     - \alpha [C v_n + K_0 z_n + N_n g - Q(v_n)] = 0

with ``C = C0 + D`` (``D`` the load laws linearised at the steady speed; ``Q`` the constant
forcing plus the nonlinear remainder of the laws) and the mesh force
``N = h (k_mb p + q_mb p')``, ``p = g^T z``. The mesh enters as a rank-one term: with
``S = M + (1+alpha)(gamma dt C + beta dt^2 K0)`` (constant), ``w = S^-1 r0`` (``r0`` all the
known terms), ``u = S^-1 g`` and ``sigma = g^T u``, Sherman-Morrison gives

.. math:: N_{n+1} = \frac{h (k \tilde p + q \tilde p') + c\, g^T w}{1 + (1+\alpha) c \sigma},
          \quad c = h (\beta dt^2 k + \gamma dt q), \quad a_{n+1} = w - (1+\alpha) N_{n+1} u .

So each step costs one 6x6 product; changing ``k`` (the model II iteration) costs a few scalar
operations. ``S^-1``, ``u`` and ``sigma`` are computed once.

Where the stiffness is evaluated
--------------------------------
* ``predictor`` (default): at the pinion angle of the second-order Taylor predictor
  ``theta_n + dt w_n + dt^2/2 a_n`` of ``theta_{n+1}`` (error O(dt^3), so the scheme keeps order 2);
  model II starts its centre-distance iteration from the same predictor of ``y_p``, ``y_g``.
* ``start`` (the paper's Fig. 7 flow chart): at ``theta_n``, and model II starts from ``d_n``.
  First order.

Model I uses ``k(theta, 0)`` and solves once. Model II iterates the paper's loop: evaluate
``k(theta, b1)``, solve, ``b2 = d(y_p, y_g)`` (eq. 4); stop when ``|b1 - b2| < tol`` and, from the
second solve on, the acceleration update is small in the mass norm,
``|a_m - a_{m-1}|_M <= rtol max(|a_m|_M, (1+alpha)|N u|_M)``; else ``b1 <- b2``. The first solve is
judged by the paper's criterion alone (the relative one needs two solves), so iterations happen
only where the centre distance moves fast relative to the predictor: at tooth handovers and the
crack (Fig. 9). Iterations, ``|b1 - b2|`` of the first and last solve are recorded.

``K(theta, d)`` jumps where a contact zone boundary (the entry handover, which moves with ``d``)
crosses ``theta``. When the step's handover lies between the two centre distances the iteration
visits, no fixed point exists: a higher ``k`` spreads the bearings, which moves the handover past
``theta`` and lowers ``k``, and back. The iterates then settle into a two-cycle
(``|b2_m - b2_{m-2}| <= 1e-3 tol`` while ``|b1 - b2| >= tol``); the step is accepted on the side of
the boundary the first solve chose (the handover is placed at a step boundary, the resolution of
any fixed-step scheme) and ``residual_after >= tol`` marks it in the record. Without this rule a
run at 170 N m and ``tol = 1e-8 m`` stopped after 0.24 s.

Tooth separation (eq. 15)
-------------------------
``h_{n+1} = 1`` when the *free* deflection ``p_free = g^T(z~ + beta dt^2 w)`` (the mesh deflection
at ``t_{n+1}`` if no mesh force acted) is ``>= 0``. This equals eq. 15 evaluated at ``t_{n+1}``
whenever eq. 15 has exactly one consistent solution; in the two corner cases that damping allows
(contact and no contact both consistent, or neither) it picks separation, resp. contact, the
physical choices. It is decided once per step (the mesh force never changes ``p_free``).

Nonlinear load laws (quadratic, table, induction) add their remainder ``Q(v_{n+1})`` to the same
loop, evaluated first at the predicted speed and iterated to ``rtol`` of the torque scale.

Tooth errors (:mod:`geardyn.modifications`)
-------------------------------------------
When ``eip[EI_ACTIVE] == 1`` eq. 15 becomes ``p - e`` per pair: once per step, at the same angle
as the stiffness (taken modulo the hunting period ``lcm(z1, z2) 2 pi / z1`` for the tooth
numbers), :func:`_excite` finds the (up to three) pairs in contact, each pair's error ``e_j``
(per-tooth tables of pitch, slope and form deviation interpolated in each gear's roll length,
closed-form tip relief, once-per-rev runout) and its load share ``s_j`` from the map. Pairs with
``p_free - e_j >= 0`` carry load; the mesh force is ``N = h (k f (p - e_bar) + q p')`` with
``f`` the loaded pairs' share and ``e_bar`` their share-weighted error, so the Sherman-Morrison
update keeps its form with ``k -> k f`` and ``p~ -> p~ - e_bar``. Runout also shifts the angle
at which the map is read by ``-e_run / r_b1`` (the mesh phase). Without errors nothing of this
runs and ``f = 1``, ``e_bar = 0`` leave every operation bit for bit as before.
"""

from __future__ import annotations

import math

import numba
import numpy as np

from ..run_limits import RECORD_VARIABLES
from ..stiffness.map import lookup_box, lookup_box_reference

__all__ = ["advance", "advance_python", "law_torque", "family_lookup", "no_family", "STATUS_TEXT",
           "N_STATE", "N_FP", "N_IP",
           "N_REC", "N_FAIL", "N_EIP", "N_EFP", "no_excitation"]

# float parameters
FP_DT, FP_BETA, FP_GAMMA, FP_ALPHA, FP_QMB, FP_RSUM, FP_T1T2, FP_D0 = 0, 1, 2, 3, 4, 5, 6, 7
FP_TOL, FP_RTOL, FP_HSTEP, FP_PLIM, FP_YLIM, FP_SIGMA, FP_UNORM = 8, 9, 10, 11, 12, 13, 14
FP_IN_P0, FP_IN_P1, FP_IN_P2, FP_IN_WREF, FP_IN_TREF, FP_IN_SLOPE = 15, 16, 17, 18, 19, 20
FP_OUT_P0, FP_OUT_P1, FP_OUT_P2, FP_OUT_WREF, FP_OUT_TREF, FP_OUT_SLOPE = 21, 22, 23, 24, 25, 26
FP_TSCALE = 27
FP_RIP_AMP, FP_RIP_ORDER, FP_RIP_PHASE = 28, 29, 30  # input torque ripple (issue 14.3)
FP_DRIVE_GAIN, FP_WREF = 31, 32  # speed-controlled drive following a speed profile
N_FP = 33
# integer parameters
IP_MODEL, IP_EVAL, IP_MAXIT, IP_SEP, IP_INLAW, IP_OUTLAW, IP_IN_NL, IP_OUT_NL = range(8)
IP_WINDOW = 8  # 1: the stiffness averaged over each step's rotation (map.lookup_box)
N_IP = 9
# state
S_Z, S_V, S_A = 0, 6, 12
S_N, S_K, S_H, S_DD, S_IT, S_RB, S_RA, S_QIN, S_QOUT = 18, 19, 20, 21, 22, 23, 24, 25, 26
S_E, S_RIP = 27, 28
S_FEL = 29  # elastic mesh force of the step: the load a K(theta, d, F) family is read at
N_STATE = 30
# record columns
R_Z, R_V, R_N, R_DD, R_K, R_H, R_IT, R_RB, R_RA, R_E = 0, 6, 12, 13, 14, 15, 16, 17, 18, 19
N_REC = 20
# geardyn.run_limits estimates a record's size before the run without importing this module
# (numba): the same width there. A literal here, not an import, so that numba's cache, which
# keys the kernel on this file, sees any change of it
if N_REC != RECORD_VARIABLES:  # (not an assert: python -O would drop it)
    raise RuntimeError("geardyn.run_limits.RECORD_VARIABLES differs from the kernel's N_REC")
# tooth errors (geardyn.modifications): integer and float parameters
EI_ACTIVE, EI_Z1, EI_Z2, EI_NR, EI_TABLE, EI_RUNOUT, EI_SHARES = range(7)
N_EIP = 7
EF_PITCH_S, EF_S_END, EF_PB, EF_RB1, EF_U2TIP, EF_HPER, EF_RATIO = range(7)
EF_GEAR0 = 7  # then per gear (pinion, gear):
EG_ULO, EG_DU, EG_RELIEF, EG_RSTART, EG_RINV, EG_RPOW, EG_RUNOUT, EG_RPHASE = range(8)
EF_PER_GEAR = 8
N_EFP = EF_GEAR0 + 2 * EF_PER_GEAR
# failure information
N_FAIL = 10
FAIL_NAMES = ("time", "theta_p", "mesh_deflection", "y_p", "y_g", "centre_distance_change",
              "mesh_force", "mesh_stiffness", "iterations", "residual")

OK, NONFINITE, MESH_RUNAWAY, BEARING_RUNAWAY, MAP_RANGE, NOT_CONVERGED = 0, 1, 2, 3, 4, 5
STATUS_TEXT = {
    NONFINITE: "the solution became NaN or infinite (divergence)",
    MESH_RUNAWAY: "runaway mesh deflection or tooth separation (|p| beyond the sanity limit)",
    BEARING_RUNAWAY: "runaway bearing displacement (|y| beyond the sanity limit)",
    MAP_RANGE: "the centre distance left the stiffness map's range",
    NOT_CONVERGED: "the centre distance iteration did not converge",
}


@numba.njit(cache=True, nogil=True, fastmath=False)
def law_torque(code, p0, p1, p2, tw, tt, w):
    """Torque [N m] of a law at speed ``w`` [rad/s]: 0 constant ``p0``; 1 linear ``p0 w``;
    2 quadratic ``p0 w |w|``; 3 table ``(tw, tt)`` (constant beyond the ends); 4 Kloss
    ``2 p1 s p2 / (s^2 + p2^2)``, ``s = (p0 - w)/p0``."""
    if code == 0:
        return p0
    if code == 1:
        return p0 * w
    if code == 2:
        return p0 * w * abs(w)
    if code == 3:
        n = tw.shape[0]
        if w <= tw[0]:
            return tt[0]
        if w >= tw[n - 1]:
            return tt[n - 1]
        lo = 0
        hi = n - 1
        while hi - lo > 1:
            mid = (lo + hi) // 2
            if tw[mid] <= w:
                lo = mid
            else:
                hi = mid
        f = (w - tw[lo]) / (tw[hi] - tw[lo])
        return tt[lo] + f * (tt[hi] - tt[lo])
    s = (p0 - w) / p0
    return 2.0 * p1 * s * p2 / (s * s + p2 * p2)


@numba.njit(cache=True, nogil=True, fastmath=False)
def _remainder(code, p0, p1, p2, tw, tt, wref, tref, slope, dz):
    """``T(wref + dz) - T(wref) - T'(wref) dz``: the part of a law the linearisation misses."""
    return law_torque(code, p0, p1, p2, tw, tt, wref + dz) - tref - slope * dz


@numba.njit(cache=True, nogil=True, fastmath=False)
def _q_in(fp, ip, tw, tt, dz):
    return _remainder(ip[IP_INLAW], fp[FP_IN_P0], fp[FP_IN_P1], fp[FP_IN_P2], tw, tt,
                      fp[FP_IN_WREF], fp[FP_IN_TREF], fp[FP_IN_SLOPE], dz)


@numba.njit(cache=True, nogil=True, fastmath=False)
def _q_out(fp, ip, tw, tt, dz):
    return -_remainder(ip[IP_OUTLAW], fp[FP_OUT_P0], fp[FP_OUT_P1], fp[FP_OUT_P2], tw, tt,
                       fp[FP_OUT_WREF], fp[FP_OUT_TREF], fp[FP_OUT_SLOPE], dz)


@numba.njit(cache=True, nogil=True, fastmath=False)
def _input_forcing(fp, n, sp_t, sp_w):
    """Explicit input torque at step ``n`` [N m]: the ripple ``A sin(k theta_ref + phi)``
    (``theta_ref = n w dt``) plus the speed-controlled drive's ``c (w_target(t) - w_ref)``
    (``w_target`` piecewise linear in ``(sp_t, sp_w)``, constant beyond the ends)."""
    out = 0.0
    if fp[FP_RIP_AMP] != 0.0:
        out += fp[FP_RIP_AMP] * math.sin(fp[FP_RIP_ORDER] * (n * fp[FP_HSTEP]) + fp[FP_RIP_PHASE])
    if fp[FP_DRIVE_GAIN] != 0.0:
        # np.int64(3), not 3: numba compiles a callee once more for each literal argument
        # (Literal[int](3)); a typed value shares the compiled law_torque of the other calls
        wt = law_torque(np.int64(3), 0.0, 0.0, 0.0, sp_t, sp_w, n * fp[FP_DT])
        out += fp[FP_DRIVE_GAIN] * (wt - fp[FP_WREF])
    return out


def no_family():
    """Load-family arrays of a single map (the kernel reads ``kvals`` only)."""
    return (np.zeros(0), np.zeros((1, 1)), np.zeros((1, 1)), np.zeros((1, 1, 1)))


def no_excitation():
    """Excitation arrays of perfect involutes (the kernel skips the tooth-error branch)."""
    return (np.zeros(N_EIP, dtype=np.int64), np.zeros(N_EFP), np.zeros((1, 2)),
            np.zeros((1, 2)), np.zeros((3, 1, 1)))


@numba.njit(cache=True, nogil=True, fastmath=False)
def _table_value(tab, row, u, ulo, du, nr):
    """Linear interpolation of ``tab[row]`` on ``ulo + du * arange(nr)`` (constant beyond)."""
    x = (u - ulo) / du
    if x <= 0.0:
        return tab[row, 0]
    if x >= nr - 1:
        return tab[row, nr - 1]
    k = int(math.floor(x))
    if k > nr - 2:
        k = nr - 2
    t = x - k
    return tab[row, k] * (1.0 - t) + tab[row, k + 1] * t


@numba.njit(cache=True, nogil=True, fastmath=False)
def _relief(efp, base, u):
    """Tip relief ``C_a x^k`` of one gear at roll length ``u`` [m]."""
    c = efp[base + EG_RELIEF]
    if c <= 0.0:
        return 0.0
    x = (u - efp[base + EG_RSTART]) * efp[base + EG_RINV]
    if x <= 0.0:
        return 0.0
    if efp[base + EG_RPOW] == 1.0:
        return c * x
    return c * x * x


@numba.njit(cache=True, nogil=True, fastmath=False)
def _lookup4(theta, dd, dd0, ddd, phase_a, length_a, mesh_angle, n_cycles, n_seg, kvals, els):
    """``k_mb`` and the three load shares at ``(theta, dd)`` with the cell found once: the
    arithmetic of :func:`geardyn.stiffness.map.lookup` (NaN outside the ``dd`` range)."""
    n_d = kvals.shape[0]
    if n_d == 1:
        i = 0
        w = 0.0
    else:
        x = (dd - dd0) / ddd
        if x < -1e-9 or x > (n_d - 1) + 1e-9:
            return np.nan, 0.0, 0.0, 0.0
        i = int(math.floor(x))
        if i < 0:
            i = 0
        if i > n_d - 2:
            i = n_d - 2
        w = x - i
        if w < 0.0:
            w = 0.0
        if w > 1.0:
            w = 1.0
    i2 = i + 1 if n_d > 1 else 0
    a = phase_a[i] + w * (phase_a[i2] - phase_a[i])
    la = length_a[i] + w * (length_a[i2] - length_a[i])
    period = n_cycles * mesh_angle
    r = (theta - a) % period
    c = int(math.floor(r / mesh_angle))
    if c >= n_cycles:
        c = n_cycles - 1
    r -= c * mesh_angle
    if la > 1e-12 * mesh_angle and r < la:
        zone = 0
        f = r / la
    else:
        zone = 1
        lb = mesh_angle - la
        f = (r - la) / lb if lb > 1e-12 * mesh_angle else 0.0
        if f < 0.0:
            f = 0.0
    if f > 1.0:
        f = 1.0
    u = f * (n_seg - 1)
    jn = int(math.floor(u))
    if jn > n_seg - 2:
        jn = n_seg - 2
    t = u - jn
    base = (2 * c + zone) * n_seg + jn
    k = kvals[i, base] * (1.0 - t) + kvals[i, base + 1] * t
    s0 = els[0, i, base] * (1.0 - t) + els[0, i, base + 1] * t
    s1 = els[1, i, base] * (1.0 - t) + els[1, i, base + 1] * t
    s2 = els[2, i, base] * (1.0 - t) + els[2, i, base + 1] * t
    if n_d > 1:
        k = k * (1.0 - w) + (kvals[i2, base] * (1.0 - t) + kvals[i2, base + 1] * t) * w
        s0 = s0 * (1.0 - w) + (els[0, i2, base] * (1.0 - t) + els[0, i2, base + 1] * t) * w
        s1 = s1 * (1.0 - w) + (els[1, i2, base] * (1.0 - t) + els[1, i2, base + 1] * t) * w
        s2 = s2 * (1.0 - w) + (els[2, i2, base] * (1.0 - t) + els[2, i2, base + 1] * t) * w
    return k, s0, s1, s2


@numba.njit(cache=True, nogil=True, fastmath=False)
def _excite(th, tha, b1, rsum, dd, pfree, sep, eip, efp, etp, etg, els,
            dd0, ddd, phase_a, length_a, mesh_angle, n_cycles, n_seg, kvals):
    """Tooth errors of the step (see :mod:`geardyn.modifications`).

    ``th`` map angle, ``tha`` the same angle modulo the hunting period [rad], ``b1`` the
    centre distance, ``dd`` its change [m], ``pfree`` the free mesh deflection [m].

    Returns ``(th_k, e_bar, frac, h, k)``: the angle of the contact pattern (runout shifts it),
    the share-weighted error of the loaded pairs [m], their share of ``k_mb``, the contact flag
    and ``k_mb(th_k, dd)`` [N/m] (NaN when the map has no load shares or ``dd`` is off the map:
    the caller then looks it up itself).
    """
    rb1 = efp[EF_RB1]
    run = 0.0
    if eip[EI_RUNOUT] == 1:
        bp = EF_GEAR0
        bg = EF_GEAR0 + EF_PER_GEAR
        run = efp[bp + EG_RUNOUT] * math.sin(tha + efp[bp + EG_RPHASE]) \
            + efp[bg + EG_RUNOUT] * math.sin(tha * efp[EF_RATIO] + efp[bg + EG_RPHASE])
    th_k = th - run / rb1
    tha_e = tha - run / rb1
    t1t2 = math.sqrt(b1 * b1 - rsum * rsum)
    s_start = t1t2 - efp[EF_U2TIP]
    pb = efp[EF_PB]
    s_th = efp[EF_PITCH_S] + rb1 * tha_e
    n_exit = int(math.floor((s_th - efp[EF_S_END]) / pb))
    z1 = eip[EI_Z1]
    z2 = eip[EI_Z2]
    nr = eip[EI_NR]
    bp = np.int64(EF_GEAR0)  # typed, not literal: one compiled _relief (see _input_forcing)
    bg = np.int64(EF_GEAR0 + EF_PER_GEAR)
    tot = 0.0
    sa = 0.0
    se = 0.0
    cnt = 0
    nact = 0
    sh0 = sh1 = sh2 = 1.0
    kk = np.nan
    if eip[EI_SHARES] == 1:
        kk, sh0, sh1, sh2 = _lookup4(th_k, dd, dd0, ddd, phase_a, length_a, mesh_angle,
                                     n_cycles, n_seg, kvals, els)
    for k in range(3):
        nk = n_exit + 1 + k
        s = s_th - nk * pb
        if s < s_start - 1e-12:
            continue
        cnt += 1
        ek = run + _relief(efp, bp, s) + _relief(efp, bg, t1t2 - s)
        if eip[EI_TABLE] == 1:
            ek += _table_value(etp, nk % z1, s, efp[bp + EG_ULO], efp[bp + EG_DU], nr) \
                + _table_value(etg, nk % z2, t1t2 - s, efp[bg + EG_ULO], efp[bg + EG_DU], nr)
        sh = sh0 if k == 0 else (sh1 if k == 1 else sh2)
        tot += sh
        if (not sep) or pfree - ek >= 0.0:
            nact += 1
            sa += sh
            se += sh * ek
    if cnt == 0:
        return th_k, run, 1.0, 1.0, kk
    if nact == 0:
        return th_k, 0.0, 1.0, 0.0, kk
    if sa <= 0.0:  # only pairs the map gives no share (a handover node): no error weighting
        return th_k, run, 1.0, 1.0, kk
    frac = 1.0 if nact == cnt else sa / tot
    return th_k, se / sa, frac, 1.0, kk


@numba.njit(cache=True, nogil=True, fastmath=False)
def update_small(an, ap, M, force_scale, rtol):
    """Whether the acceleration update of a re-solve is small in the mass norm:
    ``|an - ap|_M <= rtol max(|an|_M, force_scale)`` (``force_scale`` the mesh force's
    ``(1+alpha) |N u|_M``)."""
    n = an.shape[0]
    da = 0.0
    aa = 0.0
    for i in range(n):
        for k in range(n):
            da += (an[i] - ap[i]) * M[i, k] * (an[k] - ap[k])
            aa += an[i] * M[i, k] * an[k]
    return not da > rtol * rtol * max(aa, force_scale ** 2)


def two_cycle_py(take_next, it, history_b2, history_k, res, tol):
    """The twins' copy of :func:`no_fixed_point` over their iterate histories (written on
    lists, independently of the kernels): ``(accept, take_next)``."""
    if take_next:
        return True, take_next
    if it >= 2 and abs(history_b2[-1] - history_b2[-3]) <= 1e-3 * tol and res >= tol:
        if abs(history_k[-1] - history_k[0]) <= abs(history_k[-2] - history_k[0]):
            return True, take_next
        return False, True
    return False, take_next


@numba.njit(cache=True, nogil=True, fastmath=False)
def no_fixed_point(take_next, it, b2, b2_m2, res, tol, kk, k_first, k_m1):
    """Model II's rule for a step without a fixed point (module text): the iterates settle into
    a two-cycle across a contact zone boundary (``|b2_m - b2_{m-2}| <= 1e-3 tol`` while
    ``|b1 - b2| >= tol``); accept the solve on the first solve's side. Returns
    ``(accept, take_next)``: accept now, or mark the next solve as the one to accept."""
    if take_next:
        return True, take_next
    if it >= 2 and abs(b2 - b2_m2) <= 1e-3 * tol and res >= tol:
        if abs(kk - k_first) <= abs(k_m1 - k_first):
            return True, take_next
        return False, True
    return False, take_next


@numba.njit(cache=True, nogil=True, fastmath=False)
def family_lookup(theta, h, dd, force, dd0, ddd, mesh_angle, n_cycles, n_seg, lf_force,
                  lf_phase, lf_length, lf_vals):
    """``K(theta, d, F)`` from maps at the loads ``lf_force`` [N] (increasing): the window
    average :func:`geardyn.stiffness.map.lookup_box` of the two maps bracketing ``force``,
    interpolated linearly in ``force``, constant beyond the ends [N/m]."""
    nfm = lf_force.shape[0]
    if force <= lf_force[0]:
        i = 0
        w = 0.0
    elif force >= lf_force[nfm - 1]:
        i = nfm - 2
        w = 1.0
    else:
        i = 0
        while i < nfm - 2 and force >= lf_force[i + 1]:
            i += 1
        w = (force - lf_force[i]) / (lf_force[i + 1] - lf_force[i])
    k0 = lookup_box(theta, h, dd, dd0, ddd, lf_phase[i], lf_length[i], mesh_angle, n_cycles,
                    n_seg, lf_vals[i])
    if w == 0.0:
        return k0
    k1 = lookup_box(theta, h, dd, dd0, ddd, lf_phase[i + 1], lf_length[i + 1], mesh_angle,
                    n_cycles, n_seg, lf_vals[i + 1])
    if w == 1.0:
        return k1
    return k0 + w * (k1 - k0)


@numba.njit(cache=True, nogil=True, fastmath=False)
def _consistent_k(th, h, dd, fel0, frac, hh, pt, pdt, gw, ebar, q, bdt2, gdt, opa, sigma, rtol,
                  dd0, ddd, mesh_angle, n_cycles, n_seg, lf_force, lf_phase, lf_length, lf_vals):
    """The stiffness ``k`` with ``k = K(theta, d, F(k))``, ``F(k)`` the elastic mesh force the
    step's solve gives with ``k`` (a scalar function through the Sherman-Morrison update:
    ``N(k)`` and ``p(k) = p~ + beta dt^2 (g^T w - (1+alpha) N sigma)``), by the secant method
    from ``K`` at the load ``fel0``; to ``rtol`` of ``k`` (at most 50 steps)."""
    k = family_lookup(th, h, dd, fel0, dd0, ddd, mesh_angle, n_cycles, n_seg, lf_force,
                      lf_phase, lf_length, lf_vals)
    k_prev = np.nan
    r_prev = np.nan
    for _ in range(50):
        keff = k * frac
        nf = 0.0
        if hh > 0.0:
            c = bdt2 * keff + gdt * q
            nf = (keff * (pt - ebar) + q * pdt + c * gw) / (1.0 + opa * c * sigma)
        pn = pt + bdt2 * (gw - opa * nf * sigma)
        fel = hh * keff * (pn - ebar)
        r = family_lookup(th, h, dd, fel, dd0, ddd, mesh_angle, n_cycles, n_seg, lf_force,
                          lf_phase, lf_length, lf_vals) - k
        if abs(r) <= rtol * abs(k):
            return k
        k_next = k + r
        if k_prev == k_prev and r != r_prev:
            k_next = k - r * (k - k_prev) / (r - r_prev)
        k_prev = k
        r_prev = r
        k = k_next
    return k


@numba.njit(cache=True, nogil=True, fastmath=False)
def advance(n_steps, rec_start, decim, out, j, st, ist, fail,
            M, K0, C, Q0, Sinv, SK, SC, sQ, u, g, fp, ip,
            dd0, ddd, phase_a, length_a, mesh_angle, n_cycles, n_seg, kvals,
            in_w, in_t, out_w, out_t, eip, efp, etp, etg, els, sp_t, sp_w,
            lf_force, lf_phase, lf_length, lf_vals):
    """Advance the state ``st`` (step count ``ist[0]``) by up to ``n_steps`` steps.

    Writes a record row into ``out[j]`` after every step ``n >= rec_start`` with
    ``(n - rec_start) % decim == 0`` (and for the current state if it is such a step and
    ``ist[1] == 0``, which marks it as not yet recorded).

    Returns
    -------
    (status, j)
        ``status`` 0 on success, else a failure code (see :data:`STATUS_TEXT`) with ``fail``
        filled; the state is left at the last good step (map range, no convergence) or at the
        step that failed the sanity check (NaN, runaway); ``j`` the next free record row.
    """
    dt = fp[FP_DT]
    beta = fp[FP_BETA]
    gam = fp[FP_GAMMA]
    al = fp[FP_ALPHA]
    opa = 1.0 + al
    q = fp[FP_QMB]
    rsum = fp[FP_RSUM]
    t1t2 = fp[FP_T1T2]
    d0 = fp[FP_D0]
    tol = fp[FP_TOL]
    rtol = fp[FP_RTOL]
    hstep = fp[FP_HSTEP]
    plim = fp[FP_PLIM]
    ylim = fp[FP_YLIM]
    sigma = fp[FP_SIGMA]
    unorm = fp[FP_UNORM]
    tscale = fp[FP_TSCALE]
    model2 = ip[IP_MODEL] == 2
    ev_start = ip[IP_EVAL] == 1
    maxit = ip[IP_MAXIT]
    box = ip[IP_WINDOW] == 1
    sep = ip[IP_SEP] == 1
    in_nl = ip[IP_IN_NL] == 1
    out_nl = ip[IP_OUT_NL] == 1
    bdt2 = beta * dt * dt
    gdt = gam * dt
    period = n_cycles * mesh_angle
    eact = eip[EI_ACTIVE] == 1
    hper = efp[EF_HPER]
    rip = fp[FP_RIP_AMP] != 0.0 or fp[FP_DRIVE_GAIN] != 0.0
    dtr = 0.0
    fam = lf_force.shape[0] >= 2  # K(theta, d, F): maps at several loads

    xt = np.empty(6)
    vt = np.empty(6)
    w = np.empty(6)
    an = np.empty(6)
    ap = np.empty(6)

    # record the current state if it is a record step not yet written
    n = ist[0]
    if ist[1] == 0 and n >= rec_start and (n - rec_start) % decim == 0 and j < out.shape[0]:
        _write(out, j, st)
        j += 1
        ist[1] = 1

    for _ in range(n_steps):
        # ---- predictors
        for i in range(6):
            xt[i] = st[S_Z + i] + dt * st[S_V + i] + dt * dt * (0.5 - beta) * st[S_A + i]
            vt[i] = st[S_V + i] + dt * (1.0 - gam) * st[S_A + i]
        qin = 0.0
        qout = 0.0
        if in_nl:
            qin = _q_in(fp, ip, in_w, in_t, st[S_V] + dt * st[S_A])
        if out_nl:
            qout = _q_out(fp, ip, out_w, out_t, st[S_V + 5] + dt * st[S_A + 5])
        # ---- w = S^-1 (known part of the residual), with SC = S^-1 C, SK = S^-1 K0, sQ = S^-1 Q0
        for i in range(6):
            acc = sQ[i]
            for k in range(6):
                acc -= SC[i, k] * vt[k] + SK[i, k] * xt[k]
            w[i] = opa * acc
        if in_nl or out_nl:
            for i in range(6):
                w[i] += opa * (Sinv[i, 0] * qin + Sinv[i, 5] * qout)
        if rip:  # input torque ripple and drive at t_{n+1} (see _input_forcing)
            dtr = _input_forcing(fp, n + 1, sp_t, sp_w)
            for i in range(6):
                w[i] += opa * Sinv[i, 0] * dtr
        if al != 0.0:
            for i in range(6):
                acc = -sQ[i] + st[S_N] * u[i] - Sinv[i, 0] * st[S_QIN] - Sinv[i, 5] * st[S_QOUT]
                if rip:
                    acc -= Sinv[i, 0] * st[S_RIP]
                for k in range(6):
                    acc += SC[i, k] * st[S_V + k] + SK[i, k] * st[S_Z + k]
                w[i] += al * acc
        gw = 0.0
        pt = 0.0
        pdt = 0.0
        for i in range(6):
            gw += g[i] * w[i]
            pt += g[i] * xt[i]
            pdt += g[i] * vt[i]
        # ---- contact state (eq. 15 at t_{n+1}, decided by the free deflection)
        hh = 1.0
        if sep and pt + bdt2 * gw < 0.0:
            hh = 0.0
        # ---- where the stiffness is evaluated
        if ev_start:
            th = np.fmod(n * hstep, period) + st[S_Z + 2]
            ype = st[S_Z + 1]
            yge = st[S_Z + 3]
        else:
            th = np.fmod((n + 1) * hstep, period) + st[S_Z + 2] + dt * st[S_V + 2] \
                + 0.5 * dt * dt * st[S_A + 2]
            ype = st[S_Z + 1] + dt * st[S_V + 1] + 0.5 * dt * dt * st[S_A + 1]
            yge = st[S_Z + 3] + dt * st[S_V + 3] + 0.5 * dt * dt * st[S_A + 3]
        if model2:
            e = t1t2 + yge - ype
            b1 = math.sqrt(rsum * rsum + e * e)
        else:
            b1 = d0
        # half the rotation of this step: the window of the stiffness average (lookup_box)
        hbox = 0.5 * abs(hstep + dt * st[S_V + 2]) if box else 0.0
        # ---- tooth errors: e_bar, the loaded pairs' share and the pattern's angle
        th_k = th
        ebar = 0.0
        frac = 1.0
        k_pre = np.nan
        if eact:
            if ev_start:
                tha = np.fmod(n * hstep, hper) + st[S_Z + 2]
            else:
                tha = np.fmod((n + 1) * hstep, hper) + st[S_Z + 2] + dt * st[S_V + 2] \
                    + 0.5 * dt * dt * st[S_A + 2]
            th_k, ebar, frac, hh, k_pre = _excite(th, tha, b1, rsum, b1 - d0, pt + bdt2 * gw,
                                                  sep, eip, efp, etp, etg, els, dd0, ddd,
                                                  phase_a, length_a, mesh_angle, n_cycles, n_seg,
                                                  kvals)
        # typed, not literal (see _input_forcing): numba's type inference would otherwise
        # compile no_fixed_point and _fail for Literal[int](0) and Literal[bool](False) too
        it = np.int64(0)
        res_b = np.nan
        res = np.nan
        kk = 0.0
        nf = 0.0
        b2 = d0
        b2_m1 = np.nan
        b2_m2 = np.nan
        k_first = 0.0
        k_m1 = 0.0
        take_next = bool(it)  # False
        status = OK
        fel = st[S_FEL]  # the load the family is read at: first the last step's
        fel_new = fel
        while True:
            if fam:
                kk = _consistent_k(th_k, hbox, b1 - d0, fel, frac, hh, pt, pdt, gw, ebar, q,
                                   bdt2, gdt, opa, sigma, rtol, dd0, ddd, mesh_angle, n_cycles,
                                   n_seg, lf_force, lf_phase, lf_length, lf_vals)
            elif it == 0 and k_pre == k_pre and hbox <= 0.0:  # found with the shares there
                kk = k_pre
            else:
                kk = lookup_box(th_k, hbox, b1 - d0, dd0, ddd, phase_a, length_a, mesh_angle,
                                n_cycles, n_seg, kvals)
            if kk != kk:
                status = MAP_RANGE
                break
            if it == 0:
                k_first = kk
            keff = kk * frac
            if hh > 0.0:
                c = bdt2 * keff + gdt * q
                nf = (keff * (pt - ebar) + q * pdt + c * gw) / (1.0 + opa * c * sigma)
            else:
                nf = 0.0
            for i in range(6):
                an[i] = w[i] - opa * nf * u[i]
            e = t1t2 + (xt[3] + bdt2 * an[3]) - (xt[1] + bdt2 * an[1])
            b2 = math.sqrt(rsum * rsum + e * e)
            conv = True
            if fam:  # the stiffness at the load of this solve: iterate until it is consistent
                pn = 0.0
                for i in range(6):
                    pn += g[i] * (xt[i] + bdt2 * an[i])
                fel_new = hh * keff * (pn - ebar)
                k_new = family_lookup(th_k, hbox, b1 - d0, fel_new, dd0, ddd, mesh_angle,
                                      n_cycles, n_seg, lf_force, lf_phase, lf_length, lf_vals)
                if abs(k_new - kk) > rtol * abs(kk):
                    conv = False
            if model2:
                res = abs(b1 - b2)
                if it == 0:
                    res_b = res
                if not res < tol:
                    conv = False
            if it > 0 and not update_small(an, ap, M, opa * nf * unorm, rtol):
                conv = False
            if in_nl or out_nl:
                dq0 = 0.0
                dq5 = 0.0
                if in_nl:
                    dq0 = _q_in(fp, ip, in_w, in_t, vt[0] + gdt * an[0]) - qin
                if out_nl:
                    dq5 = _q_out(fp, ip, out_w, out_t, vt[5] + gdt * an[5]) - qout
                if abs(dq0) > rtol * tscale or abs(dq5) > rtol * tscale:
                    conv = False
                    qin += dq0
                    qout += dq5
                    gw = 0.0
                    for i in range(6):
                        w[i] += opa * (Sinv[i, 0] * dq0 + Sinv[i, 5] * dq5)
                        gw += g[i] * w[i]
            if model2 and not conv:
                # no fixed point: the iterates alternate between the two sides of a contact
                # zone boundary (a handover inside this step). Keep the side of the first solve.
                conv, take_next = no_fixed_point(take_next, it, b2, b2_m2, res, tol, kk, k_first,
                                                 k_m1)
            if conv:
                break
            if it >= maxit:
                status = NOT_CONVERGED
                break
            for i in range(6):
                ap[i] = an[i]
            b2_m2 = b2_m1
            b2_m1 = b2
            k_m1 = kk
            if model2:
                b1 = b2
            fel = fel_new
            it += 1
        if status != OK:
            _fail(fail, (n + 1) * dt, th, pt + bdt2 * gw, xt[1], xt[3], b1 - d0, nf, kk, it,
                  res)
            return status, j
        # ---- commit
        for i in range(6):
            st[S_Z + i] = xt[i] + bdt2 * an[i]
            st[S_V + i] = vt[i] + gdt * an[i]
            st[S_A + i] = an[i]
        st[S_N] = nf
        st[S_K] = kk * frac
        st[S_H] = hh
        st[S_E] = ebar
        st[S_RIP] = dtr
        if fam:
            st[S_FEL] = fel_new
        st[S_DD] = b2 - d0
        st[S_IT] = it
        st[S_RB] = res_b
        st[S_RA] = res
        if in_nl:
            st[S_QIN] = _q_in(fp, ip, in_w, in_t, st[S_V])
        if out_nl:
            st[S_QOUT] = _q_out(fp, ip, out_w, out_t, st[S_V + 5])
        n += 1
        ist[0] = n
        ist[1] = 0
        # ---- sanity
        p = 0.0
        tot = nf
        for i in range(6):
            p += g[i] * st[S_Z + i]
            tot += st[S_V + i] + st[S_A + i]
        if not math.isfinite(tot + p):
            status = NONFINITE
        elif abs(p) > plim:
            status = MESH_RUNAWAY
        elif abs(st[S_Z + 1]) > ylim or abs(st[S_Z + 3]) > ylim:
            status = BEARING_RUNAWAY
        if status != OK:
            _fail(fail, n * dt, np.fmod(n * hstep, period) + st[S_Z + 2], p, st[S_Z + 1],
                  st[S_Z + 3], b2 - d0, nf, kk, it, res)
            return status, j
        # ---- record
        if n >= rec_start and (n - rec_start) % decim == 0 and j < out.shape[0]:
            _write(out, j, st)
            j += 1
            ist[1] = 1
    return OK, j


@numba.njit(cache=True, nogil=True, fastmath=False)
def _write(out, j, st):
    for i in range(6):
        out[j, R_Z + i] = st[S_Z + i]
        out[j, R_V + i] = st[S_V + i]
    out[j, R_N] = st[S_N]
    out[j, R_DD] = st[S_DD]
    out[j, R_K] = st[S_K]
    out[j, R_H] = st[S_H]
    out[j, R_IT] = st[S_IT]
    out[j, R_RB] = st[S_RB]
    out[j, R_RA] = st[S_RA]
    out[j, R_E] = st[S_E]


@numba.njit(cache=True, nogil=True, fastmath=False)
def _fail(fail, t, th, p, yp, yg, dd, nf, kk, it, res):
    fail[0] = t
    fail[1] = th
    fail[2] = p
    fail[3] = yp
    fail[4] = yg
    fail[5] = dd
    fail[6] = nf
    fail[7] = kk
    fail[8] = it
    fail[9] = res


# --------------------------------------------------------------------------- the Python twin
def _law_torque_py(code, p0, p1, p2, tw, tt, w):
    if code == 0:
        return p0
    if code == 1:
        return p0 * w
    if code == 2:
        return p0 * w * abs(w)
    if code == 3:
        return float(np.interp(w, tw, tt))
    s = (p0 - w) / p0
    return 2.0 * p1 * s * p2 / (s * s + p2 * p2)


def _excite_py(th, tha, b1, rsum, dd, pfree, sep, eip, efp, etp, etg, els, arrays):
    """NumPy twin of :func:`_excite` (``numpy.interp`` tables, ``lookup_reference`` shares)."""
    from ..stiffness.map import lookup_reference

    rb1, pb = efp[EF_RB1], efp[EF_PB]
    gears = (EF_GEAR0, EF_GEAR0 + EF_PER_GEAR)
    run = 0.0
    if eip[EI_RUNOUT] == 1:
        run = sum(efp[b + EG_RUNOUT] * math.sin(a + efp[b + EG_RPHASE])
                  for b, a in zip(gears, (tha, tha * efp[EF_RATIO]), strict=True))
    th_k, tha_e = th - run / rb1, tha - run / rb1
    t1t2 = math.sqrt(b1 * b1 - rsum * rsum)
    s_th = efp[EF_PITCH_S] + rb1 * tha_e
    n_exit = math.floor((s_th - efp[EF_S_END]) / pb)

    def relief(b, uu):
        c = efp[b + EG_RELIEF]
        x = (uu - efp[b + EG_RSTART]) * efp[b + EG_RINV]
        return c * x ** efp[b + EG_RPOW] if c > 0 and x > 0 else 0.0

    def table(tab, row, b, uu):
        grid = efp[b + EG_ULO] + efp[b + EG_DU] * np.arange(eip[EI_NR])
        return float(np.interp(uu, grid, tab[row]))

    rows = []
    for k in range(3):
        nk = n_exit + 1 + k
        s = s_th - nk * pb
        if s < t1t2 - efp[EF_U2TIP] - 1e-12:
            continue
        ek = run + relief(gears[0], s) + relief(gears[1], t1t2 - s)
        if eip[EI_TABLE] == 1:
            ek += table(etp, nk % eip[EI_Z1], gears[0], s) \
                + table(etg, nk % eip[EI_Z2], gears[1], t1t2 - s)
        sh = 1.0
        if eip[EI_SHARES] == 1:
            sh = float(lookup_reference(np.array(th_k), np.array(dd),
                                        arrays._replace(values=els[k])))
        rows.append((ek, sh, (not sep) or pfree - ek >= 0.0))
    if not rows:
        return th_k, run, 1.0, 1.0
    act = [(e, sh) for e, sh, a in rows if a]
    if not act:
        return th_k, 0.0, 1.0, 0.0
    sa = sum(sh for _, sh in act)
    if sa <= 0.0:
        return th_k, run, 1.0, 1.0
    frac = 1.0 if len(act) == len(rows) else sa / sum(sh for _, sh, _ in rows)
    return th_k, sum(e * sh for e, sh in act) / sa, frac, 1.0


def advance_python(n_steps, rec_start, decim, out, j, st, ist, fail,
                   M, K0, C, Q0, Sinv, SK, SC, sQ, u, g, fp, ip,
                   dd0, ddd, phase_a, length_a, mesh_angle, n_cycles, n_seg, kvals,
                   in_w, in_t, out_w, out_t, eip, efp, etp, etg, els, sp_t, sp_w,
                   lf_force, lf_phase, lf_length, lf_vals):
    """Pure-Python/NumPy twin of :func:`advance` (same arguments and results).

    Written separately: it assembles the full effective matrix
    ``M + (1+alpha)(gamma dt (C + h q g g^T) + beta dt^2 (K0 + h k g g^T))`` and calls
    :func:`numpy.linalg.solve` (no Sherman-Morrison; ignores ``Sinv``, ``SK``, ``SC``, ``sQ``,
    ``u``), evaluates the map
    with :func:`geardyn.stiffness.map.lookup_reference` and the laws with :func:`numpy.interp`.
    About 100 times slower; used by the tests and as the benchmark's NumPy baseline.
    """
    from ..stiffness.map import MapArrays

    arrays = MapArrays(dd0, ddd, phase_a, length_a, mesh_angle, n_cycles, n_seg, kvals)
    family = [MapArrays(dd0, ddd, lf_phase[i], lf_length[i], mesh_angle, n_cycles, n_seg,
                        lf_vals[i]) for i in range(lf_force.shape[0])]

    def k_of_load(th, h, dd, force):
        """K(theta, d, F): np.interp over the loads of the family's window averages."""
        ks = [lookup_box_reference(th, h, dd, m) for m in family]
        return float(np.interp(force, lf_force, ks))

    dt, beta, gam, al = fp[FP_DT], fp[FP_BETA], fp[FP_GAMMA], fp[FP_ALPHA]
    opa = 1 + al
    q, rsum, t1t2, d0 = fp[FP_QMB], fp[FP_RSUM], fp[FP_T1T2], fp[FP_D0]
    tol, rtol, hstep = fp[FP_TOL], fp[FP_RTOL], fp[FP_HSTEP]
    model2, ev_start, maxit = ip[IP_MODEL] == 2, ip[IP_EVAL] == 1, ip[IP_MAXIT]
    sep, in_nl, out_nl = ip[IP_SEP] == 1, ip[IP_IN_NL] == 1, ip[IP_OUT_NL] == 1
    period = n_cycles * mesh_angle
    gg = np.outer(g, g)
    S = M + opa * (gam * dt * C + beta * dt * dt * K0)

    def q_in(dz):
        f = _law_torque_py
        w0 = fp[FP_IN_WREF]
        return (f(ip[IP_INLAW], fp[FP_IN_P0], fp[FP_IN_P1], fp[FP_IN_P2], in_w, in_t, w0 + dz)
                - fp[FP_IN_TREF] - fp[FP_IN_SLOPE] * dz)

    def q_out(dz):
        f = _law_torque_py
        w0 = fp[FP_OUT_WREF]
        return -(f(ip[IP_OUTLAW], fp[FP_OUT_P0], fp[FP_OUT_P1], fp[FP_OUT_P2], out_w, out_t,
                   w0 + dz) - fp[FP_OUT_TREF] - fp[FP_OUT_SLOPE] * dz)

    def write(jj):
        out[jj, R_Z:R_Z + 6] = st[S_Z:S_Z + 6]
        out[jj, R_V:R_V + 6] = st[S_V:S_V + 6]
        out[jj, [R_N, R_DD, R_K, R_H, R_IT, R_RB, R_RA, R_E]] = st[[S_N, S_DD, S_K, S_H, S_IT,
                                                                    S_RB, S_RA, S_E]]

    n = int(ist[0])
    if ist[1] == 0 and n >= rec_start and (n - rec_start) % decim == 0 and j < out.shape[0]:
        write(j)
        j += 1
        ist[1] = 1
    for _ in range(n_steps):
        z, v, a = st[S_Z:S_Z + 6].copy(), st[S_V:S_V + 6].copy(), st[S_A:S_A + 6].copy()
        xt = z + dt * v + dt * dt * (0.5 - beta) * a
        vt = v + dt * (1 - gam) * a
        load = Q0.copy()
        rip1 = 0.0
        if fp[FP_RIP_AMP] != 0.0:
            rip1 = fp[FP_RIP_AMP] * math.sin(fp[FP_RIP_ORDER] * ((n + 1) * hstep)
                                             + fp[FP_RIP_PHASE])
        if fp[FP_DRIVE_GAIN] != 0.0:
            rip1 += fp[FP_DRIVE_GAIN] * (float(np.interp((n + 1) * dt, sp_t, sp_w))
                                         - fp[FP_WREF])
        load[0] += rip1
        if in_nl:
            load[0] += q_in(v[0] + dt * a[0])
        if out_nl:
            load[5] += q_out(v[5] + dt * a[5])
        old = np.zeros(6)
        if al != 0.0:
            old = C @ v + K0 @ z - Q0 + st[S_N] * g
            old[0] -= st[S_QIN] + st[S_RIP]
            old[5] -= st[S_QOUT]
        # free solve decides the contact state
        a_free = np.linalg.solve(S, opa * (load - C @ vt - K0 @ xt) + al * old)
        hh = 0.0 if (sep and g @ (xt + beta * dt * dt * a_free) < 0.0) else 1.0
        if ev_start:
            th = np.fmod(n * hstep, period) + z[2]
            ype, yge = z[1], z[3]
        else:
            th = np.fmod((n + 1) * hstep, period) + z[2] + dt * v[2] + 0.5 * dt * dt * a[2]
            ype = z[1] + dt * v[1] + 0.5 * dt * dt * a[1]
            yge = z[3] + dt * v[3] + 0.5 * dt * dt * a[3]
        b1 = math.hypot(rsum, t1t2 + yge - ype) if model2 else d0
        th_k, ebar, frac = th, 0.0, 1.0
        if eip[EI_ACTIVE] == 1:
            nn = n if ev_start else n + 1
            zth = z[2] if ev_start else z[2] + dt * v[2] + 0.5 * dt * dt * a[2]
            tha = np.fmod(nn * hstep, efp[EF_HPER]) + zth
            th_k, ebar, frac, hh = _excite_py(th, tha, b1, rsum, b1 - d0,
                                              g @ (xt + beta * dt * dt * a_free), sep, eip, efp,
                                              etp, etg, els, arrays)
        hbox = 0.5 * abs(hstep + dt * v[2]) if ip[IP_WINDOW] == 1 else 0.0
        it, res_b, res, a_prev = 0, np.nan, np.nan, None
        history_b2, history_k, take_next = [], [], False
        status = OK
        fel = st[S_FEL]
        while True:
            if family and len(family) >= 2:
                kk = k_of_load(th_k, hbox, b1 - d0, fel)
            else:
                kk = lookup_box_reference(th_k, hbox, b1 - d0, arrays)
            if np.isnan(kk):
                status = MAP_RANGE
                nf = 0.0
                break
            K = K0 + hh * kk * frac * gg
            Ct = C + hh * q * gg
            Seff = M + opa * (gam * dt * Ct + beta * dt * dt * K)
            rhs = opa * (load - Ct @ vt - K @ xt + hh * kk * frac * ebar * g) + al * old
            an = np.linalg.solve(Seff, rhs)
            zn, vn = xt + beta * dt * dt * an, vt + gam * dt * an
            nf = hh * (kk * frac * (g @ zn - ebar) + q * (g @ vn))
            b2 = math.hypot(rsum, t1t2 + zn[3] - zn[1])
            conv = True
            if model2:
                res = abs(b1 - b2)
                if it == 0:
                    res_b = res
                conv = res < tol
            if family and len(family) >= 2:
                fel_new = hh * kk * frac * (g @ zn - ebar)
                if abs(k_of_load(th_k, hbox, b1 - d0, fel_new) - kk) > rtol * abs(kk):
                    conv = False
            if a_prev is not None:
                da = (an - a_prev) @ M @ (an - a_prev)
                sc = max(an @ M @ an, (opa * nf) ** 2 * fp[FP_UNORM] ** 2)
                if da > rtol * rtol * sc:
                    conv = False
            if in_nl or out_nl:
                dq0 = q_in(vn[0]) - (load[0] - Q0[0] - rip1) if in_nl else 0.0
                dq5 = q_out(vn[5]) - (load[5] - Q0[5]) if out_nl else 0.0
                if max(abs(dq0), abs(dq5)) > rtol * fp[FP_TSCALE]:
                    conv = False
                    load[0] += dq0
                    load[5] += dq5
            history_b2.append(b2)
            history_k.append(kk)
            if model2 and not conv:     # a two-cycle across a zone boundary: see the kernel
                conv, take_next = two_cycle_py(take_next, it, history_b2, history_k, res, tol)
            if conv:
                break
            if it >= maxit:
                status = NOT_CONVERGED
                break
            a_prev = an
            if model2:
                b1 = b2
            if family and len(family) >= 2:
                fel = fel_new
            it += 1
        if status != OK:
            fail[:] = [(n + 1) * dt, th, g @ xt, xt[1], xt[3], b1 - d0, nf, kk, it, res]
            return status, j
        st[S_Z:S_Z + 6], st[S_V:S_V + 6], st[S_A:S_A + 6] = zn, vn, an
        st[S_N], st[S_K], st[S_H], st[S_DD] = nf, kk * frac, hh, b2 - d0
        st[S_IT], st[S_RB], st[S_RA], st[S_E], st[S_RIP] = it, res_b, res, ebar, rip1
        if family and len(family) >= 2:
            st[S_FEL] = fel_new
        if in_nl:
            st[S_QIN] = q_in(vn[0])
        if out_nl:
            st[S_QOUT] = q_out(vn[5])
        n += 1
        ist[0], ist[1] = n, 0
        p = g @ zn
        status = OK
        if not np.all(np.isfinite(np.r_[zn, vn, an, nf])):
            status = NONFINITE
        elif abs(p) > fp[FP_PLIM]:
            status = MESH_RUNAWAY
        elif abs(zn[1]) > fp[FP_YLIM] or abs(zn[3]) > fp[FP_YLIM]:
            status = BEARING_RUNAWAY
        if status != OK:
            fail[:] = [n * dt, np.fmod(n * hstep, period) + zn[2], p, zn[1], zn[3], b2 - d0,
                       nf, kk, it, res]
            return status, j
        if n >= rec_start and (n - rec_start) % decim == 0 and j < out.shape[0]:
            write(j)
            j += 1
            ist[1] = 1
    return OK, j
