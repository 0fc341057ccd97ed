r"""Compiled twin of the contact compatibility solve of :mod:`.contact` (issue 16, item 1).

:func:`solve_compatibility_fast` computes exactly what :func:`.contact.solve_compatibility` with
the analytical local Hertz term of :meth:`.contact.PairContactModel.local_term` computes: the same
active-set enumeration order (the previous active set first, then every subset by size in
lexicographic order), the same acceptance tolerances, the same fixed point and stopping test.
Only the small dense solves differ in implementation (numba's LAPACK ``gesv`` binding instead of
NumPy's), which changes results by rounding only; ``tests/fe/test_batched_contact.py`` checks
the maps against the pure-Python reference to 1e-9 relative. ``fastmath=False``; the
pure-Python twin is :func:`.contact.solve_compatibility`.
"""

from __future__ import annotations

import itertools
import math

import numpy as np
from numba import njit

from ...errors import NumericalError

__all__ = ["subset_table", "solve_compatibility_fast"]

_TABLES: dict[int, np.ndarray] = {}


def subset_table(n: int) -> np.ndarray:
    """Every non-empty subset of ``range(n)`` as a boolean row, in the enumeration order of
    :func:`.contact._qp` (by size, then lexicographic), shape ``(2**n - 1, n)``."""
    t = _TABLES.get(n)
    if t is None:
        rows = []
        for m in range(1, n + 1):
            for s in itertools.combinations(range(n), m):
                r = np.zeros(n, np.bool_)
                r[list(s)] = True
                rows.append(r)
        t = np.array(rows, dtype=np.bool_).reshape(-1, n)
        _TABLES[n] = t
    return t


@njit(cache=True, fastmath=False)
def _try(c, g, a, torque, sel, amax, scale_f, f, w):
    n = g.size
    k = 0
    for j in range(n):
        if sel[j]:
            k += 1
    idx = np.empty(k, np.int64)
    q = 0
    for j in range(n):
        if sel[j]:
            idx[q] = j
            q += 1
    mat = np.zeros((k + 1, k + 1))
    rhs = np.empty(k + 1)
    for p in range(k):
        for r in range(k):
            mat[p, r] = c[idx[p], idx[r]]
        mat[p, k] = -a[idx[p]]
        mat[k, p] = a[idx[p]]
        rhs[p] = -g[idx[p]]
    rhs[k] = torque
    # The reference skips an exactly singular KKT matrix (LinAlgError) and tries the next set;
    # here numba's solve raises instead. With C positive definite and a > 0 the KKT matrix of
    # every subset is regular, so the two paths never differ on the maps of geardyn's cases.
    sol = np.linalg.solve(mat, rhs)
    for j in range(n):
        f[j] = 0.0
    for p in range(k):
        f[idx[p]] = sol[p]
    dth = sol[k]
    for j in range(n):
        if f[j] < -1e-10 * scale_f:
            return False, dth
    tol = 1e-9 * max(dth * amax, 1e-30)
    for j in range(n):
        acc = 0.0
        for r in range(n):
            acc += c[j, r] * f[r]
        w[j] = acc + g[j] - dth * a[j]
    for j in range(n):
        if not sel[j] and w[j] < -tol:
            return False, dth
    for j in range(n):
        if f[j] < 0.0:
            f[j] = 0.0
        if sel[j]:
            w[j] = 0.0
        elif w[j] < 0.0:
            w[j] = 0.0
    return True, dth


@njit(cache=True, fastmath=False)
def _qp_nb(c, g, a, torque, first, table, f, w):
    n = g.size
    amax = a[0]
    for j in range(n):
        if a[j] > amax:
            amax = a[j]
    scale_f = torque / amax
    anyfirst = False
    for j in range(n):
        if first[j]:
            anyfirst = True
    if anyfirst:
        ok, dth = _try(c, g, a, torque, first, amax, scale_f, f, w)
        if ok:
            return True, dth
    for r in range(table.shape[0]):
        if anyfirst:
            same = True
            for j in range(n):
                if table[r, j] != first[j]:
                    same = False
            if same:
                continue
        ok, dth = _try(c, g, a, torque, table[r], amax, scale_f, f, w)
        if ok:
            return True, dth
    return False, 0.0


@njit(cache=True, fastmath=False)
def _solve_nb(c0, gap, arm, torque, radius, e1, e2, estar, half_width, local, table,
              tol, max_iter):
    n = gap.size
    f = np.zeros(n)
    w = np.zeros(n)
    first = np.empty(n, np.bool_)
    for j in range(n):
        first[j] = gap[j] <= 0
    ok, dth = _qp_nb(c0, gap, arm, torque, first, table, f, w)
    if not ok:
        return 1, f, dth, w, 0
    it = 0
    if local:
        cf = -(2 / math.pi) * (1 / e1 + 1 / e2)
        c = np.empty((n, n))
        fn = np.zeros(n)
        converged = False
        for k in range(1, max_iter + 1):
            it = k
            for j in range(n):
                for r in range(n):
                    c[j, r] = c0[j, r]
            for j in range(n):
                fj = max(f[j], 1e-9)
                b = math.sqrt(4 * fj * radius[j] / (math.pi * estar))
                c[j, j] = c[j, j] + cf * math.log(b / half_width)
                first[j] = f[j] > 0
            ok, dth_new = _qp_nb(c, gap, arm, torque, first, table, fn, w)
            if not ok:
                return 1, f, dth, w, it
            dmax = 0.0
            fmax = fn[0]
            for j in range(n):
                d = abs(fn[j] - f[j])
                if d > dmax:
                    dmax = d
                if fn[j] > fmax:
                    fmax = fn[j]
            done = abs(dth_new - dth) <= tol * abs(dth_new) and dmax <= tol * 1e3 * fmax
            for j in range(n):
                f[j] = fn[j]
            dth = dth_new
            if done:
                converged = True
                break
        if not converged:
            return 2, f, dth, w, it
    return 0, f, dth, w, it


def solve_compatibility_fast(c0, gap, arm, torque, radius, *, plane_modulus, half_width,
                             local=True, tol=1e-10, max_iter=60):
    """Compiled :func:`.contact.solve_compatibility` with the local Hertz term.

    Parameters
    ----------
    c0 : ndarray, shape (n, n)
        Compliance at the reference patch [m^2/N per m].
    gap, arm, radius : ndarray, shape (n,)
        Unloaded gaps [m], pinion lever arms [m], relative radii of curvature [m].
    torque : float
        Pinion torque per unit width [N m/m].
    plane_modulus : (float, float)
        Plane moduli of the pinion and the gear [Pa].
    half_width : float
        Reference patch half-width [m].

    Returns
    -------
    (force, rotation, separation, iterations)
    """
    from .contact import ContactResult

    gap = np.ascontiguousarray(gap, float)
    e1, e2 = plane_modulus
    estar = 1.0 / (1.0 / e1 + 1.0 / e2)
    status, f, dth, w, it = _solve_nb(np.ascontiguousarray(c0, float), gap,
                                      np.ascontiguousarray(arm, float), float(torque),
                                      np.ascontiguousarray(radius, float), float(e1), float(e2),
                                      estar, float(half_width), bool(local),
                                      subset_table(gap.size), float(tol), int(max_iter))
    if status == 1:
        raise NumericalError("no solution of the contact compatibility problem",
                             state={"candidates": gap.size})
    if status == 2:
        raise NumericalError("local contact iteration did not converge", state={"rotation": dth})
    return ContactResult(force=f, rotation=float(dth), separation=w, iterations=int(it))
