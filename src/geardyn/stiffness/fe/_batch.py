r"""Compiled twins of the contact computations of :mod:`.contact` (issue 16, item 1).

* :func:`solve_compatibility_fast` (one problem) and :func:`solve_batch` (a block of problems
  of one size in one call) compute exactly what :func:`.contact.solve_compatibility` with the
  analytical local Hertz term of :meth:`.contact.PairContactModel.local_term` computes: the same
  active-set enumeration order (the previous active set first, then every subset by size in
  lexicographic order), the same acceptance tolerances, the same skip of an exactly singular
  KKT matrix, the same fixed point and stopping test. The small dense solves call LAPACK
  ``dgesv`` (SciPy's ``cython_lapack``, the routine numba's ``np.linalg.solve`` calls) directly:
  the same factorisation as through ``np.linalg.solve`` (:func:`_gesv`), compiled in a fraction
  of the time (numba's ``np.linalg.solve`` with its checks and messages took 2-3 s of the first
  run's compilation, measured with numba's compile events). Given the same inputs the results
  were equal bit for bit on 1200 positions of the cracked paper map (three centre distances,
  six mesh cycles around the cracked tooth) when written; the tests allow 1e-9
  (tests/fe/test_batched_contact.py).
* :func:`complete_nb` is :meth:`.contact.CandidateGenerator.complete` (the unloaded gaps, lever
  arms and roll lengths of the tip-corner contacts) on a block of positions, operation for
  operation; only ``math.hypot`` differs (numba calls the C library's, Python has its own), so
  lengths can differ in the last bit.

The compiled functions allocate nothing: their outputs and workspace are NumPy arrays made by
the Python functions that call them (:func:`_workspace`). numba compiles each allocating routine
(``np.zeros``, ``np.empty``, ``np.ascontiguousarray``: 19 of them) once per array type and
process; with them the contact completion and batch took 4.3-4.7 s to compile in a fresh numba
cache, without them 2.7-3.6 s (three alternating runs, numba's compile events, 2026-11-26),
with bit-identical results (and paper FE maps).
The KKT matrices are written column by column straight into the buffer LAPACK reads.

Used by :meth:`.model.FEStiffness.evaluate` (``compiled=True``); the maps agree with the
per-position pure-Python reference to 1e-9 relative (tests/fe/test_batched_contact.py; 6e-12
measured over the cracked paper map, benchmarks/bench_fe_eval.py). ``fastmath=False``
throughout.
"""

from __future__ import annotations

import itertools
import math

import llvmlite.binding
import numpy as np
from numba import njit, types
from numba.extending import get_cython_function_address

from ...errors import NumericalError

__all__ = ["subset_table", "solve_compatibility_fast", "solve_batch", "complete_nb"]

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


# LAPACK ``dgesv(n, nrhs, a, lda, ipiv, b, ldb, info)`` (Fortran: every argument by pointer,
# 32-bit integers), SciPy's, under a symbol name the compiled (and cached) code links against
llvmlite.binding.add_symbol("geardyn_dgesv",
                            get_cython_function_address("scipy.linalg.cython_lapack", "dgesv"))
_DGESV = types.ExternalFunction("geardyn_dgesv", types.void(*[types.voidptr] * 8))


@njit(cache=True, fastmath=False)
def _gesv(mat, x, k, ints, ipiv):
    """Solve ``A y = x`` in place by LAPACK ``dgesv`` (LU with partial pivoting): ``mat`` holds
    the ``k x k`` matrix ``A`` column by column in its first ``k * k`` entries (the layout
    LAPACK reads; overwritten by the factors), ``x`` the right-hand side in its first ``k``
    (overwritten by ``y``); ``ints`` (int32, 4) and ``ipiv`` (int32, >= k) are workspace.
    Returns LAPACK's ``info``: ``> 0`` is an exactly zero pivot (singular matrix, where
    ``np.linalg.solve`` raises ``LinAlgError``), and ``x`` is then undefined."""
    ints[0] = k
    ints[1] = 1
    ints[2] = max(k, 1)
    ints[3] = 0
    _DGESV(ints[0:].ctypes, ints[1:].ctypes, mat.ctypes, ints[2:].ctypes, ipiv.ctypes,
           x.ctypes, ints[2:].ctypes, ints[3:].ctypes)
    return ints[3]


@njit(cache=True, fastmath=False)
def _try(c, g, a, torque, sel, amax, scale_f, f, w, idx, mat, rhs, ints, ipiv):
    n = g.size
    k = 0
    for j in range(n):
        if sel[j]:
            idx[k] = j
            k += 1
    m = k + 1
    for p in range(k):  # the KKT matrix, column-major: entry (row p, column r) at p + r * m
        for r in range(k):
            mat[p + r * m] = c[idx[p], idx[r]]
        mat[p + k * m] = -a[idx[p]]
        mat[k + p * m] = a[idx[p]]
        rhs[p] = -g[idx[p]]
    mat[k + k * m] = 0.0
    rhs[k] = torque
    # Like the reference, an exactly singular KKT matrix (LAPACK gesv reports a zero pivot, where
    # NumPy raises LinAlgError) skips this set and the enumeration tries the next one.
    if _gesv(mat, rhs, m, ints, ipiv) != 0:
        return False, 0.0
    for j in range(n):
        f[j] = 0.0
    for p in range(k):
        f[idx[p]] = rhs[p]
    dth = rhs[k]
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
def _qp_nb(c, g, a, torque, first, table, f, w, idx, mat, rhs, ints, ipiv):
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
        ok, dth = _try(c, g, a, torque, first, amax, scale_f, f, w, idx, mat, rhs, ints, ipiv)
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
        ok, dth = _try(c, g, a, torque, table[r], amax, scale_f, f, w, idx, mat, rhs, ints,
                       ipiv)
        if ok:
            return True, dth
    return False, 0.0


@njit(cache=True, fastmath=False)
def _solve_nb(c0, gap, arm, torque, radius, e1, e2, estar, half_width, local, table,
              tol, max_iter, f, w, fn, c, first, idx, mat, rhs, ints, ipiv):
    """One contact problem; ``f`` (force) and ``w`` (separation) are written, the arrays after
    them are workspace (:func:`_workspace`). Returns ``(status, rotation, iterations)``."""
    n = gap.size
    for j in range(n):
        f[j] = 0.0
        w[j] = 0.0
        first[j] = gap[j] <= 0
    ok, dth = _qp_nb(c0, gap, arm, torque, first, table, f, w, idx, mat, rhs, ints, ipiv)
    if not ok:
        return 1, dth, 0
    it = 0
    if local:
        cf = -(2 / math.pi) * (1 / e1 + 1 / e2)
        for j in range(n):
            fn[j] = 0.0
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
            ok, dth_new = _qp_nb(c, gap, arm, torque, first, table, fn, w, idx, mat, rhs, ints,
                                 ipiv)
            if not ok:
                return 1, dth, it
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
            return 2, dth, it
    return 0, dth, it


def _workspace(n: int) -> tuple:
    """Workspace of :func:`_solve_nb` for ``n`` candidates: ``fn``, ``c``, ``first``, ``idx``,
    ``mat``, ``rhs``, ``ints``, ``ipiv``, allocated here rather than in compiled code (see the
    module docstring)."""
    return (np.zeros(n), np.zeros((n, n)), np.zeros(n, np.bool_), np.zeros(n, np.int64),
            np.zeros((n + 1) * (n + 1)), np.zeros(n + 1), np.zeros(4, np.int32),
            np.zeros(n + 1, np.int32))


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
    f, w = np.zeros(gap.size), np.zeros(gap.size)
    status, dth, it = _solve_nb(np.ascontiguousarray(c0, float), gap,
                                np.ascontiguousarray(arm, float), float(torque),
                                np.ascontiguousarray(radius, float), float(e1), float(e2),
                                estar, float(half_width), bool(local), subset_table(gap.size),
                                float(tol), int(max_iter), f, w, *_workspace(gap.size))
    if status == 1:
        raise NumericalError("no solution of the contact compatibility problem",
                             state={"candidates": gap.size})
    if status == 2:
        raise NumericalError("local contact iteration did not converge", state={"rotation": dth})
    return ContactResult(force=f, rotation=float(dth), separation=w, iterations=int(it))


@njit(cache=True, fastmath=False)
def _solve_batch_nb(c0, gap, arm, torque, radius, e1, e2, estar, half_width, local, table,
                    tol, max_iter, status, force, rotation, separation, iterations, fn, c, first,
                    idx, mat, rhs, ints, ipiv):
    for p in range(gap.shape[0]):
        st, dth, it = _solve_nb(c0[p], gap[p], arm[p], torque, radius[p], e1, e2, estar,
                                half_width, local, table, tol, max_iter, force[p],
                                separation[p], fn, c, first, idx, mat, rhs, ints, ipiv)
        status[p] = st
        rotation[p] = dth
        iterations[p] = it


def solve_batch(c0, gap, arm, torque, radius, *, plane_modulus, half_width, local=True,
                tol=1e-10, max_iter=60):
    """:func:`solve_compatibility_fast` of many contact problems of one size in one call.

    Parameters
    ----------
    c0 : ndarray, shape (p, n, n)
        Compliances at the reference patch [m^2/N per m].
    gap, arm, radius : ndarray, shape (p, n)
        Unloaded gaps [m], pinion lever arms [m], relative radii of curvature [m].
    torque : float
        Pinion torque per unit width [N m/m].
    plane_modulus : (float, float)
        Plane moduli of the pinion and the gear [Pa].
    half_width : float
        Reference patch half-width [m].

    Returns
    -------
    status : ndarray of int, shape (p,)
        0 solved; 1 no active set satisfies the optimality conditions; 2 the local Hertz
        fixed point did not converge in ``max_iter`` iterations. The caller re-solves the
        positions with ``status != 0`` by the pure-Python reference (which raises the matching
        :class:`~geardyn.errors.NumericalError` if it fails too).
    force : ndarray, shape (p, n)
        Contact forces per unit width [N/m].
    rotation : ndarray, shape (p,)
        Pinion hub rotations [rad].
    separation : ndarray, shape (p, n)
        Loaded gaps [m].
    iterations : ndarray of int, shape (p,)
        Fixed-point iterations of the local term.
    """
    gap = np.ascontiguousarray(gap, float)
    if gap.ndim != 2:
        raise ValueError("solve_batch expects gaps of shape (positions, candidates)")
    e1, e2 = plane_modulus
    estar = 1.0 / (1.0 / e1 + 1.0 / e2)
    npos, n = gap.shape
    out = (np.zeros(npos, np.int64), np.zeros((npos, n)), np.zeros(npos), np.zeros((npos, n)),
           np.zeros(npos, np.int64))
    _solve_batch_nb(np.ascontiguousarray(c0, float), gap, np.ascontiguousarray(arm, float),
                    float(torque), np.ascontiguousarray(radius, float), float(e1), float(e2),
                    estar, float(half_width), bool(local), subset_table(n), float(tol),
                    int(max_iter), *out, *_workspace(n))
    return out


@njit(cache=True, fastmath=False)
def _wrap_angle(a):
    return (a + math.pi) % (2 * math.pi) - math.pi


@njit(cache=True, fastmath=False)
def _complete_nb(s, s_start, s_end, t1t2, o2x, o2y, rb1, rb2, ua1, ua2, kind, u1, u2, gap, arm,
                 radius):
    """:func:`complete_nb` into the given arrays (``kind``, ``u1``, ``u2``, ``gap``, ``arm``,
    ``radius``, each of the shape of ``s``, all written)."""
    npos, n = s.shape
    for p in range(npos):
        for k in range(n):
            sk = s[p, k]
            a1 = sk
            a2 = t1t2 - sk
            g = 0.0
            lever = rb1
            kind[p, k] = 0
            if sk > s_end:  # pinion tip corner
                kind[p, k] = 1
                beta = (sk - ua1) / rb1
                cx = rb1 * math.cos(beta) + ua1 * (-math.sin(beta))
                cy = rb1 * math.sin(beta) + ua1 * math.cos(beta)
                vx = cx - o2x
                vy = cy - o2y
                r = math.hypot(vx, vy)
                gam = math.atan2(vy, vx) - math.acos(rb2 / r)
                lam = math.sqrt(r * r - rb2 * rb2)
                g = lam + rb2 * _wrap_angle(gam - math.pi) - (t1t2 - sk)
                a1 = ua1
                a2 = lam - g
                t2x = o2x + rb2 * math.cos(gam)
                t2y = o2y + rb2 * math.sin(gam)
                ex = -math.sin(gam)
                ey = math.cos(gam)
                lever = abs(t2x * ey - t2y * ex)
            elif sk < s_start:  # gear tip corner
                kind[p, k] = 2
                gn = t1t2 - sk
                gam = math.pi + (gn - ua2) / rb2
                cx = o2x + rb2 * math.cos(gam) + ua2 * (-math.sin(gam))
                cy = o2y + rb2 * math.sin(gam) + ua2 * math.cos(gam)
                r = math.hypot(cx, cy)
                beta = math.atan2(cy, cx) - math.acos(rb1 / r)
                lam = math.sqrt(r * r - rb1 * rb1)
                g = lam + rb1 * _wrap_angle(beta) - sk
                a1 = lam - g
                a2 = ua2
            u1[p, k] = a1
            u2[p, k] = a2
            gap[p, k] = g
            arm[p, k] = lever
            rho1 = max(a1, 1e-9)
            rho2 = max(a2, 1e-9)
            radius[p, k] = rho1 * rho2 / (rho1 + rho2)


def complete_nb(s, s_start, s_end, t1t2, o2x, o2y, rb1, rb2, ua1, ua2):
    """Compiled twin of :meth:`.contact.CandidateGenerator.complete` on a block of positions.

    Parameters
    ----------
    s : ndarray, shape (p, n)
        LOA positions of the candidates [m].
    s_start, s_end, t1t2, o2x, o2y, rb1, rb2, ua1, ua2 : float
        The operating geometry (as in :meth:`.contact.CandidateGenerator.complete`) [m].

    Returns
    -------
    kind, u1, u2, gap, arm, radius : ndarray, shape (p, n)
        Computed by :func:`_complete_nb` with the operations of the reference in the same order
        (the reference's ``math.hypot`` is Python's own algorithm, numba's the C library's, so
        the corner distance may differ from it in the last bit). The arrays are allocated here,
        not in compiled code (:func:`_workspace`).
    """
    s = np.ascontiguousarray(s, float)
    out = (np.zeros(s.shape, np.int64), *(np.zeros(s.shape) for _ in range(5)))
    _complete_nb(s, float(s_start), float(s_end), float(t1t2), float(o2x), float(o2y),
                 float(rb1), float(rb2), float(ua1), float(ua2), *out)
    return out
