r"""Factorisations of a body's stiffness matrix: CHOLMOD's Cholesky where installed, SuperLU else.

A gear body's free-free stiffness ``K`` (plane elasticity, the bore fixed) is symmetric positive
definite, so it has a Cholesky factorisation ``P K P^T = L L^T`` (one triangular factor, half
the storage of an LU factorisation). geardyn factorises each body once and solves it for many
loads (:mod:`.solve`, :mod:`.substructure`); two solvers give the same displacements:

``"cholmod"``
    CHOLMOD's supernodal Cholesky (Chen, Davis, Hager & Rajamanickam 2006), through the
    ``cholespy`` package (EPFL's Realistic Graphics Lab; it uses CHOLMOD to factorise and to
    solve on the CPU and bundles SuiteSparse and METIS, binary wheels for Linux x86-64, macOS
    and Windows). It reads the lower triangle of ``K``, and geardyn hands it only that
    (:func:`lower_triangle`): CHOLMOD copies whatever it is given before it factorises, so the
    whole matrix would be held twice beside the factors.
``"superlu"``
    SciPy's SuperLU (``scipy.sparse.linalg.splu``) in its symmetric mode (minimum
    degree ordering on ``K^T + K``, diagonal pivots preferred), which geardyn used alone until
    2026-11-27. The fallback wherever ``cholespy`` is not installed (no wheel for the
    platform).

Measured by ``python3 benchmarks/run.py fe_solver`` (2-core AMD EPYC, 2026-11-27 22:43 UTC,
each solver in a fresh process on the same mesh): the paper's cracked pinion body, 150,880 DOFs,
loaded on its five refined teeth (240 loads, the largest body of ``geardyn run``). SuperLU
factorises in 2.24 s and solves in 13.4 s; CHOLMOD factorises in 4.44 s and solves in 3.03 s
(2.1x faster in all) and adds 119 MB to the process against SuperLU's 211 MB. The coefficients
differ by 1.5e-12 of the largest. For a healthy body (48 loads) the two take about the same
time. Until 2026-11-27 CHOLMOD was rejected here on its factorisation time alone
(docs/performance.md), before the solves of the cracked body were counted.

Choice: ``GEARDYN_FE_SOLVER`` = ``cholmod`` or ``superlu``; unset (the default), CHOLMOD where
``cholespy`` imports, SuperLU otherwise. The influence coefficients do not depend on the choice
beyond round-off (``tests/fe/test_factor.py``: 1e-9 relative, the issue's tolerance), so the
cache keys do not name it; each body's ``stats`` records the solver that made it.

References
----------
Chen, Y., Davis, T. A., Hager, W. W. & Rajamanickam, S. (2006). Algorithm 8xx: CHOLMOD,
supernodal sparse Cholesky factorization and update/downdate. Technical report TR-2006-005,
CISE Dept., University of Florida.
cholespy: a self-contained sparse Cholesky solver, https://github.com/rgl-epfl/cholespy and
https://pypi.org/project/cholespy/ (read 2026-11-27: CHOLMOD factorises, and solves on the CPU).
"""

from __future__ import annotations

import atexit
import os
import weakref

import numpy as np
import scipy.sparse as sp

from ...errors import InputError, NumericalError

__all__ = ["Factorisation", "factorise", "lower_triangle", "default_solver",
           "available_solvers", "SOLVERS", "SOLVER_ENV"]

#: The solvers geardyn knows, the preferred first.
SOLVERS = ("cholmod", "superlu")

#: Environment variable naming the solver (one of :data:`SOLVERS`); unset: the first available.
SOLVER_ENV = "GEARDYN_FE_SOLVER"

#: Right-hand sides per call to SuperLU's solve: its multi-column solve slows down per column as
#: the block grows (paper pinion at refinement 0.5, 53,144 DOFs, 48 columns: 4.0 s in one call,
#: 0.95 s one at a time, 0.70 s four at a time, 1.3 s eight at a time; measured 2026-11-24).
SUPERLU_BLOCK = 4

#: Right-hand sides per call to CHOLMOD's solve: its temporaries grow with the block (a
#: superelement's condensation solves hundreds of columns at once), its speed per column no
#: longer beyond about 8 (the paper pinion, 48 columns: 1.65 s one at a time, 0.80 s four,
#: 0.65 s eight, 0.66 s sixteen, 0.65-0.71 s all at once; measured 2026-11-27).
CHOLMOD_BLOCK = 32


#: CHOLMOD factorisations alive in this process (released at its exit: :func:`_release_all`)
_LIVE: weakref.WeakSet = weakref.WeakSet()


def _release_all() -> None:
    """Drop every live CHOLMOD factorisation before the interpreter shuts down.

    cholespy's binding (nanobind) prints "nanobind: leaked 1 instances! ..." to stderr at exit
    for each solver object still alive when its module is torn down, e.g. a body a script or
    a session fixture keeps to the end; released here, from an :mod:`atexit` handler, they are
    freed first and nothing is printed (``tests/fe/test_factor.py``)."""
    for fac in list(_LIVE):
        fac._impl = None


atexit.register(_release_all)


def _cholespy():
    """The ``cholespy`` module, or None where it is not installed (or does not load)."""
    try:
        import cholespy
    except ImportError:  # no wheel for the platform, or a broken shared library
        return None
    return cholespy


def available_solvers() -> tuple[str, ...]:
    """The solvers of :data:`SOLVERS` this Python can use, the preferred first."""
    return SOLVERS if _cholespy() is not None else ("superlu",)


def default_solver() -> str:
    """The solver :func:`factorise` uses when not told: ``GEARDYN_FE_SOLVER`` if set, else
    CHOLMOD where ``cholespy`` is installed, else SuperLU.

    Raises
    ------
    geardyn.errors.InputError
        ``GEARDYN_FE_SOLVER`` names no solver, or one that is not installed.
    """
    raw = os.environ.get(SOLVER_ENV, "").strip()
    if not raw:
        return available_solvers()[0]
    return _checked(raw, SOLVER_ENV)


def _checked(solver: str, field: str) -> str:
    if solver not in SOLVERS:
        raise InputError(field, solver, "'cholmod' (CHOLMOD's Cholesky, package cholespy) or "
                         "'superlu' (SciPy's SuperLU)")
    if solver not in available_solvers():
        raise InputError(field, solver, "'superlu': cholespy, which CHOLMOD needs, is not "
                         "installed here (python3 -m pip install cholespy)")
    return solver


class Factorisation:
    """A factorised symmetric positive-definite matrix, solved for any number of loads.

    Attributes
    ----------
    solver : str
        ``"cholmod"`` or ``"superlu"``.
    n : int
        Order of the matrix.
    """

    def __init__(self, solver: str, n: int, impl):
        self.solver = solver
        self.n = int(n)
        self._impl = impl

    def solve(self, rhs: np.ndarray) -> np.ndarray:
        """``x`` with ``A x = rhs``; ``rhs`` of shape ``(n,)`` or ``(n, k)`` (same shape out).

        Units: those of ``rhs`` divided by those of ``A`` (for a body's stiffness [N/m per m of
        width] and loads [N/m per m], displacements [m])."""
        b = np.asarray(rhs, dtype=float)
        if b.ndim not in (1, 2) or b.shape[0] != self.n:
            raise ValueError(f"rhs of shape {b.shape}: expected ({self.n},) or ({self.n}, k)")
        if b.ndim == 2 and b.shape[1] == 0:
            return np.zeros_like(b)
        if self.solver == "cholmod":
            if b.ndim == 1:
                x = np.empty_like(b)
                self._impl.solve(np.ascontiguousarray(b), x)
                return x
            x = np.empty(b.shape)
            for k in range(0, b.shape[1], CHOLMOD_BLOCK):
                part = np.ascontiguousarray(b[:, k:k + CHOLMOD_BLOCK])
                xk = np.empty_like(part)
                self._impl.solve(part, xk)
                x[:, k:k + CHOLMOD_BLOCK] = xk
            return x
        if b.ndim == 1:
            return self._impl.solve(b)
        x = np.empty(b.shape, order="F")
        for k in range(0, b.shape[1], SUPERLU_BLOCK):
            x[:, k:k + SUPERLU_BLOCK] = self._impl.solve(
                np.asfortranarray(b[:, k:k + SUPERLU_BLOCK]))
        return x

    def __repr__(self) -> str:
        return f"Factorisation(solver={self.solver!r}, n={self.n})"


def lower_triangle(A) -> sp.csc_matrix:
    """The lower triangle of the square sparse matrix ``A`` (diagonal included), in CSC.

    What CHOLMOD reads of a symmetric matrix (``stype = -1``), with half the entries: cholespy
    copies its input into a CHOLMOD matrix before it factorises, so a whole matrix would sit in
    memory twice (the caller's and CHOLMOD's copy) beside the factors.
    Unlike ``scipy.sparse.tril`` no COO copy of the whole matrix is made: the entries are
    filtered in ``A``'s own compressed format (one row or column index per entry, 4 bytes, and
    a mask), and only the kept half is transposed where ``A`` is CSR. ``A`` itself is returned,
    not copied, where it is CSC and already lower triangular.

    Measured on the paper's cracked pinion body (150,880 DOFs, free-free stiffness 3,313,988
    entries, 1,732,111 in its lower triangle), CHOLMOD in a fresh process, 2026-11-28: peak
    resident set of the factorisation 324-340 MB against 356-358 MB with the whole matrix;
    the displacements bit for bit the same (``tests/fe/test_factor.py``).

    Parameters
    ----------
    A : scipy.sparse matrix, shape (n, n)

    Returns
    -------
    scipy.sparse.csc_matrix, shape (n, n)
        ``A[i, j]`` for ``i >= j``, zero above the diagonal; the same units as ``A``.
    """
    if not sp.issparse(A):
        raise TypeError(f"a scipy.sparse matrix is needed, not {type(A).__name__}")
    if A.shape[0] != A.shape[1]:
        raise ValueError(f"a square matrix is needed, not {A.shape}")
    if A.format not in ("csr", "csc"):
        A = A.tocsc()
    n = A.shape[0]
    # the major index of each entry: the row of a CSR entry, the column of a CSC one
    major = np.repeat(np.arange(n, dtype=A.indices.dtype), np.diff(A.indptr))
    # lower triangle: column <= row, i.e. CSR minor <= major, CSC minor >= major
    keep = A.indices <= major if A.format == "csr" else A.indices >= major
    if A.format == "csc" and keep.all():
        return A
    counts = np.bincount(major[keep], minlength=n)
    del major
    indptr = np.zeros(n + 1, dtype=A.indptr.dtype)
    np.cumsum(counts, out=indptr[1:])
    cls = sp.csr_matrix if A.format == "csr" else sp.csc_matrix
    L = cls((A.data[keep], A.indices[keep], indptr), shape=A.shape)
    return L.tocsc() if A.format == "csr" else L


def factorise(A, solver: str | None = None) -> Factorisation:
    """Factorise the symmetric positive-definite sparse matrix ``A`` once.

    Parameters
    ----------
    A : scipy.sparse matrix, shape (n, n)
        Symmetric positive definite (CHOLMOD reads its lower triangle only, and is handed
        :func:`lower_triangle`: a caller that frees its whole matrix first and passes only
        the lower triangle holds less memory while CHOLMOD factorises).
    solver : {"cholmod", "superlu"}, optional
        Default :func:`default_solver`.

    Returns
    -------
    Factorisation

    Raises
    ------
    geardyn.errors.NumericalError
        ``A`` is not positive definite (CHOLMOD) or singular (SuperLU): a body that is not held
        (no fixed bore) or a mesh with a loose part.
    """
    solver = default_solver() if solver is None else _checked(solver, "solver")
    if not sp.issparse(A):
        A = sp.csc_matrix(A)
    n = A.shape[0]
    if A.shape != (n, n):
        raise ValueError(f"a square matrix is needed, not {A.shape}")
    if solver == "cholmod":
        A = lower_triangle(A)
        cholespy = _cholespy()
        try:
            impl = cholespy.CholeskySolverD(n, A.indptr, A.indices, A.data,
                                            cholespy.MatrixType.CSC)
        except ValueError as exc:  # "Matrix is not positive definite!"
            raise NumericalError(f"the stiffness matrix ({n} DOFs) is not positive definite "
                                 f"(CHOLMOD: {exc}); is the body held, and is its mesh "
                                 "in one piece?") from exc
        fac = Factorisation("cholmod", n, impl)
        _LIVE.add(fac)
        return fac
    from scipy.sparse.linalg import splu

    A = sp.csc_matrix(A)
    try:
        impl = splu(A, permc_spec="MMD_AT_PLUS_A", options={"SymmetricMode": True})
    except RuntimeError as exc:  # "Factor is exactly singular"
        raise NumericalError(f"the stiffness matrix ({n} DOFs) is singular (SuperLU: {exc}); "
                             "is the body held, and is its mesh in one piece?") from exc
    return Factorisation("superlu", n, impl)
