"""The compiled look-ups of a boundary-fitted stiffness map (:mod:`.map`): :func:`lookup` at a
point, :func:`lookup_box` averaged over a pinion-angle window (what the time-step kernels call),
and ``_lookup_many`` behind :meth:`.map.StiffnessMap.__call__`. Their pure-NumPy twins,
:func:`.map.lookup_reference` and :func:`.map.lookup_box_reference`, are in :mod:`.map`, and
the tests compare the two.

They live apart from :mod:`.map` so that importing the map (a process that builds FE bodies,
writes or reads a map file) does not import numba: about 53 MB and 0.3 s, measured 2026-11-27,
while the FE bodies' factorisations are the peak of a run's memory. ``geardyn.stiffness.map``
still gives :func:`lookup` and :func:`lookup_box` (imported from here on first use).
``fastmath=False`` throughout.
"""

from __future__ import annotations

import math

import numba
import numpy as np

__all__ = ["lookup", "lookup_box"]


@numba.njit(cache=True, nogil=True, fastmath=False)
def lookup(theta, dd, dd0, ddd, phase_a, length_a, mesh_angle, n_cycles, n_seg, values):
    """Evaluate a boundary-fitted map at pinion angle ``theta`` [rad] and change ``dd`` [m].

    Returns NaN when ``dd`` lies outside the map's centre-distance range (by more than 1e-9 of
    the spacing) so callers can stop with a clear error. A single grid line is constant in ``dd``.
    """
    n_d = values.shape[0]
    # -- centre-distance cell
    if n_d == 1:
        i = 0
        w = 0.0
    else:
        x = (dd - dd0) / ddd
        if x < -1e-9 or x > (n_d - 1) + 1e-9:
            return np.nan
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
    # -- cycle, zone and fraction at this centre distance
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
    j = int(math.floor(u))
    if j > n_seg - 2:
        j = n_seg - 2
    t = u - j
    base = (2 * c + zone) * n_seg + j
    v1 = values[i, base] * (1.0 - t) + values[i, base + 1] * t
    if n_d == 1:
        return v1
    v2 = values[i2, base] * (1.0 - t) + values[i2, base + 1] * t
    return v1 * (1.0 - w) + v2 * w


@numba.njit(cache=True, nogil=True, fastmath=False)
def lookup_box(theta, h, dd, dd0, ddd, phase_a, length_a, mesh_angle, n_cycles, n_seg, values):
    r"""The map averaged over the pinion-angle window ``[theta - h, theta + h]`` [rad] at ``dd``.

    A time-step integrator that samples ``K(theta)`` at the end of each step places every
    contact handover (a step of ``K``) at the next step boundary: the handover times are
    quantised to the step ``dt``, with an error that differs from one mesh cycle to the next
    whenever ``dt`` is not commensurate with the mesh period. That jitter is not periodic with
    the mesh, so it survives time-synchronous averaging and appears in the residual of a
    healthy gear (measured on the paper case, model I, PEM map: residual RMS 1.6 % of the TSA's
    STD at ``dt = 1e-5 s``, falling as ``dt``: ``tests/dynamics/test_handover_window.py``).
    Sampling the window average

    .. math:: \bar K(\theta) = \frac{1}{2h} \int_{\theta-h}^{\theta+h} K(\vartheta, d)\,
              d\vartheta, \qquad h = \tfrac12 |\Delta\theta_{step}|,

    turns each step of ``K`` into a ramp one time step wide whose samples carry the handover's
    position inside the step (the averaging of discontinuous coefficients over a cell, as in
    finite-volume cell averages); where ``K`` is linear in the window the average equals the
    point value, so away from the handovers the results are unchanged bit for bit and the
    scheme keeps its order. The integral is exact for the map's piecewise-linear zones: a
    window that holds a handover ``theta_b`` is split there and each part is evaluated at its
    midpoint; a window that holds none returns :func:`lookup` at ``theta`` (a map node inside
    the window changes the slope only, an O(h^2) difference). Only the handover nearest to
    ``theta`` is split (windows wider than a contact zone are not meant: ``h`` is half a time
    step's rotation, about 0.2 % of a mesh cycle on the paper's case).

    Returns NaN where :func:`lookup` does.
    """
    if not h > 0.0:
        return lookup(theta, dd, dd0, ddd, phase_a, length_a, mesh_angle, n_cycles, n_seg,
                      values)
    n_d = values.shape[0]
    if n_d == 1:
        a = phase_a[0]
        la = length_a[0]
    else:
        x = (dd - dd0) / ddd
        if x < -1e-9 or x > (n_d - 1) + 1e-9:
            return np.nan
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
        a = phase_a[i] + w * (phase_a[i + 1] - phase_a[i])
        la = length_a[i] + w * (length_a[i + 1] - length_a[i])
    r = (theta - a) % mesh_angle
    # the nearest handover: the cycle's start (r = 0 or mesh_angle) or the zone boundary r = la
    tb = np.nan
    dist = h
    if r < dist:
        tb = theta - r
        dist = r
    if mesh_angle - r < dist:
        tb = theta + (mesh_angle - r)
        dist = mesh_angle - r
    if la > 1e-12 * mesh_angle and abs(r - la) < dist:
        tb = theta - (r - la)
    if tb != tb:
        return lookup(theta, dd, dd0, ddd, phase_a, length_a, mesh_angle, n_cycles, n_seg,
                      values)
    lo = theta - h
    hi = theta + h
    vl = lookup(0.5 * (lo + tb), dd, dd0, ddd, phase_a, length_a, mesh_angle, n_cycles, n_seg,
                values)
    vr = lookup(0.5 * (tb + hi), dd, dd0, ddd, phase_a, length_a, mesh_angle, n_cycles, n_seg,
                values)
    return ((tb - lo) * vl + (hi - tb) * vr) / (2.0 * h)


@numba.njit(cache=True, nogil=True, fastmath=False)
def _lookup_many(theta, dd, dd0, ddd, phase_a, length_a, mesh_angle, n_cycles, n_seg, values):
    """:func:`lookup` at each ``(theta[k], dd[k])``; also the index of the first non-finite
    ``theta`` (-1 if none), which is not looked up (its cell index would be undefined)."""
    out = np.empty(theta.size)
    first_bad = -1
    for k in range(theta.size):
        if not math.isfinite(theta[k]):
            out[k] = np.nan
            if first_bad < 0:
                first_bad = k
            continue
        out[k] = lookup(theta[k], dd[k], dd0, ddd, phase_a, length_a, mesh_angle, n_cycles,
                        n_seg, values)
    return out, first_bad
