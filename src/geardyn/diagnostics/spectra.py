"""Order spectrum and the exact order-domain filter (regular, residual, difference signals).

All functions here take a time synchronous average (TSA) holding exactly one shaft revolution of
N samples (see :func:`geardyn.diagnostics.tsa`). Such a record is one period of a periodic
signal, so its discrete Fourier transform is exact: bin k is shaft order k, and zeroing bins
(together with their conjugates ``N - k``) is an exact, zero-phase order-domain filter with no
leakage and no window.

Signal decomposition used throughout (McFadden 1986; Zakrajsek 1989; Lebold et al. 2000), with
``Z`` the number of teeth of the gear on the averaged shaft:

* **regular** y: shaft orders ``1..S`` and all mesh harmonics ``m*Z`` (optionally their
  sidebands ``m*Z +/- 1..B``); zero mean by default;
* **difference** d = x - mean(x) - y(with first-order sidebands): what is left after removing
  the regular signal and the first-order sidebands of the mesh harmonics (FM4, M6A, M8A);
* **residual** r = x minus a preset set of orders (mesh harmonics, optionally DC and shaft
  orders), sidebands kept (NA4, the paper's residual).

References
----------
McFadden, P. D. (1986). Detecting fatigue cracks in gears by amplitude and phase demodulation of
the meshing vibration. J. Vib. Acoust. Stress Reliab. Des., 108(2), 165-170.

Stewart, R. M. (1977). Some useful data analysis techniques for gearbox diagnostics. Report
MHM/R/10/77, Machine Health Monitoring Group, ISVR, University of Southampton.

Zakrajsek, J. J. (1989). An investigation of gear mesh failure prediction techniques. NASA
TM-102340.

Zakrajsek, J. J., Townsend, D. P., Decker, H. J. (1993). An analysis of gear fault detection
methods as applied to pitting fatigue failure data. NASA TM-105950.

Lebold, M., McClintic, K., Campbell, R., Byington, C., Maynard, K. (2000). Review of vibration
analysis methods for gearbox diagnostics and prognostics. Proc. 54th Meeting of the Society
for Machinery Failure Prevention Technology, 623-634.

MathWorks, Predictive Maintenance Toolbox: ``tsaregular``, ``tsaresidual``, ``tsadifference``
documentation (R2018b+).
"""

from __future__ import annotations

from collections.abc import Iterable
from dataclasses import dataclass

import numpy as np
from scipy import fft as sfft

from geardyn.errors import InputError

from .tsa import _as_float_array, _check_int

__all__ = [
    "OrderSpectrum",
    "RESIDUAL_PRESETS",
    "order_spectrum",
    "order_filter",
    "mesh_orders",
    "regular_orders",
    "regular",
    "residual",
    "residual_orders",
    "difference",
]


@dataclass(frozen=True)
class OrderSpectrum:
    """Single-sided amplitude spectrum of a one-revolution record, per shaft order.

    Attributes
    ----------
    orders : ndarray, shape (N//2 + 1,)
        Shaft order of each bin [-] (bin k = order k).
    amplitude : ndarray, shape (..., N//2 + 1)
        Amplitude per order: RMS or peak, in the unit of the signal, or in dB re ``db_ref``
        when ``db`` is True.
    scaling : str
        ``"rms"`` or ``"peak"``.
    db : bool
        Whether ``amplitude`` is in dB (20*log10(a/db_ref)).
    db_ref : float
        dB reference, in the unit of the signal.
    """

    orders: np.ndarray
    amplitude: np.ndarray
    scaling: str
    db: bool
    db_ref: float


def order_spectrum(x, *, scaling: str = "rms", db: bool = False, db_ref: float = 1.0,
                   axis: int = -1) -> OrderSpectrum:
    """Amplitude per shaft order of a one-revolution (TSA) record.

    With :math:`X_k = \\sum_n x_n e^{-2\\pi i k n/N}`:

    * RMS scaling (default): :math:`a_k = \\sqrt2 |X_k| / N` for ``0 < k < N/2``,
      :math:`a_0 = |X_0|/N` (the mean), :math:`a_{N/2} = |X_{N/2}|/N` for even N;
      a component :math:`A\\cos(k\\theta + \\phi)` gives :math:`A/\\sqrt2`;
    * peak scaling: :math:`a_k = 2|X_k|/N` (``0 < k < N/2``), DC and Nyquist as above;
      the same component gives A.

    No window is applied: the record is one period of a periodic signal. In dB,
    :math:`20\\log_{10}(a_k / a_{ref})`; empty bins are floored at the smallest positive
    float (about -6000 dB) rather than -inf.

    Parameters
    ----------
    x : array_like, shape (..., N)
        One shaft revolution per row (unit u).
    scaling : {"rms", "peak"}
        Amplitude convention.
    db : bool
        Return dB re ``db_ref`` instead of linear amplitude.
    db_ref : float
        Reference amplitude for dB, unit u (default 1).
    axis : int
        Axis holding the revolution.

    Returns
    -------
    OrderSpectrum
        ``orders`` [-] and ``amplitude`` [u or dB].

    Examples
    --------
    ``0.05*cos(46*theta)`` gives ``20*log10(0.05/sqrt(2)) = -29.0309`` dB at order 46.
    """
    xa = np.moveaxis(_as_float_array(x, "x", ndim=(1, 2, 3), min_size=2), axis, -1)
    if scaling not in ("rms", "peak"):
        raise InputError("scaling", scaling, "'rms' or 'peak'")
    if not (np.isfinite(db_ref) and db_ref > 0):
        raise InputError("db_ref", db_ref, "a positive reference amplitude")
    n = xa.shape[-1]
    spec = np.abs(sfft.rfft(xa, axis=-1)) / n
    factor = np.sqrt(2.0) if scaling == "rms" else 2.0
    spec[..., 1:] *= factor
    if n % 2 == 0:
        spec[..., -1] /= factor
    if db:
        spec = 20.0 * np.log10(np.maximum(spec, np.finfo(np.float64).tiny) / db_ref)
    return OrderSpectrum(orders=np.arange(n // 2 + 1, dtype=np.float64),
                         amplitude=np.moveaxis(spec, -1, axis), scaling=scaling, db=bool(db),
                         db_ref=float(db_ref))


def order_filter(x, orders: Iterable[int], *, keep: bool = False, axis: int = -1) -> np.ndarray:
    """Exact order-domain filter of a one-revolution record (FFT bin masking).

    .. math:: y = \\mathcal F^{-1}\\bigl[ H_k X_k \\bigr], \\quad H_k = H_{N-k} \\in \\{0, 1\\}

    with :math:`H_k = 0` for the listed orders (``keep=False``, band-stop) or :math:`H_k = 1`
    only for the listed orders (``keep=True``, band-pass). Conjugate bins ``N - k`` are treated
    with ``k`` so the output stays real and zero-phase.

    Parameters
    ----------
    x : array_like, shape (..., N)
        One shaft revolution (unit u).
    orders : iterable of int
        Shaft orders ``0 <= k <= N//2`` to remove (or keep); out-of-range orders are an error.
    keep : bool
        Keep only ``orders`` instead of removing them.
    axis : int
        Axis holding the revolution.

    Returns
    -------
    ndarray
        Filtered record, same shape and unit as ``x``.
    """
    xa = np.moveaxis(_as_float_array(x, "x", ndim=(1, 2, 3), min_size=2), axis, -1)
    n = xa.shape[-1]
    ords = np.unique(np.asarray(list(orders), dtype=np.int64))
    if ords.size and (ords.min() < 0 or ords.max() > n // 2):
        bad = ords[(ords < 0) | (ords > n // 2)][0]
        raise InputError("orders", int(bad), f"shaft orders between 0 and N//2 = {n // 2}")
    spec = sfft.rfft(xa, axis=-1)
    mask = np.zeros(n // 2 + 1, dtype=bool)
    mask[ords] = True
    if keep:
        spec[..., ~mask] = 0.0
    else:
        spec[..., mask] = 0.0
    return np.moveaxis(sfft.irfft(spec, n=n, axis=-1), -1, axis)


# --------------------------------------------------------------------------------------------
# order sets
# --------------------------------------------------------------------------------------------
def _check_teeth(teeth) -> int:
    return _check_int(teeth, "teeth", 1, "a positive integer number of teeth")


def mesh_orders(teeth: int, samples_per_rev: int, *, harmonics: int | None = None) -> np.ndarray:
    """Mesh harmonic orders ``m*Z``, ``m = 1..M``, that fit below the Nyquist order ``N//2``.

    Parameters
    ----------
    teeth : int
        Number of teeth Z of the gear on the averaged shaft [-].
    samples_per_rev : int
        N, samples per revolution [-].
    harmonics : int, optional
        M, number of mesh harmonics; default all with ``m*Z <= N//2``.

    Returns
    -------
    ndarray of int
        The orders [-].
    """
    z = _check_teeth(teeth)
    nyq = int(samples_per_rev) // 2
    mmax = nyq // z
    if harmonics is not None:
        mmax = min(mmax, _check_int(harmonics, "mesh_harmonics", 1))
    return z * np.arange(1, mmax + 1, dtype=np.int64)


def regular_orders(teeth: int, samples_per_rev: int, *, shaft_harmonics: int = 2,
                   mesh_harmonics: int | None = None, sidebands: int = 0,
                   include_dc: bool = False) -> np.ndarray:
    """Orders of the regular signal: shaft orders, mesh harmonics and their sidebands.

    Set: ``{0 if include_dc} U {1..S} U {m*Z + s : m = 1..M, |s| <= B}``, clipped to
    ``1..N//2`` (S = ``shaft_harmonics``, M = ``mesh_harmonics``, B = ``sidebands``).

    Parameters
    ----------
    teeth : int
        Z [-].
    samples_per_rev : int
        N [-].
    shaft_harmonics : int
        S, number of shaft-order harmonics (orders 1..S) in the regular signal [-].
    mesh_harmonics : int, optional
        M; default all below Nyquist.
    sidebands : int
        B, sidebands kept each side of every mesh harmonic [-].
    include_dc : bool
        Include order 0 (the mean).

    Returns
    -------
    ndarray of int
        Sorted orders [-].
    """
    nyq = int(samples_per_rev) // 2
    s = _check_int(shaft_harmonics, "shaft_harmonics", 0)
    b = _check_int(sidebands, "sidebands", 0)
    mesh = mesh_orders(teeth, samples_per_rev, harmonics=mesh_harmonics)
    parts = [np.arange(1, min(s, nyq) + 1)]
    if include_dc:
        parts.append(np.array([0]))
    for off in range(-b, b + 1):
        parts.append(mesh + off)
    out = np.unique(np.concatenate(parts).astype(np.int64))
    low = 0 if include_dc else 1  # a sideband reaching order 0 is not the mean
    return out[(out >= low) & (out <= nyq)]


def _n_last(x) -> int:
    return np.shape(x)[-1]


def regular(x, *, teeth: int, shaft_harmonics: int = 2, mesh_harmonics: int | None = None,
            sidebands: int = 0, include_dc: bool = False) -> np.ndarray:
    """Regular signal y of a TSA: shaft orders and mesh harmonics only (zero mean by default).

    :math:`y = \\mathcal F^{-1}[H X]` keeping the orders of :func:`regular_orders`. With the
    defaults (S = 2 shaft orders, all mesh harmonics, no sidebands, no DC) this is the regular
    signal of Stewart (1977) / Zakrajsek (1989) and of MATLAB's ``tsaregular`` (primary shaft
    order with NumHarmonics harmonics, gear mesh orders, NumSidebands sidebands), except that
    MATLAB limits the mesh harmonics to NumHarmonics while here all are kept unless
    ``mesh_harmonics`` is given.

    Parameters
    ----------
    x : array_like, shape (..., N)
        One revolution (unit u).
    teeth, shaft_harmonics, mesh_harmonics, sidebands, include_dc
        See :func:`regular_orders`.

    Returns
    -------
    ndarray
        Regular signal, unit u.
    """
    ords = regular_orders(teeth, _n_last(x), shaft_harmonics=shaft_harmonics,
                          mesh_harmonics=mesh_harmonics, sidebands=sidebands,
                          include_dc=include_dc)
    return order_filter(x, ords, keep=True)


def difference(x, *, teeth: int, shaft_harmonics: int = 2, mesh_harmonics: int | None = None,
               sidebands: int = 1) -> np.ndarray:
    """Difference signal d: the TSA minus its mean, regular signal and first-order sidebands.

    .. math:: d = x - \\bar x - y_{S, M, B}

    i.e. the orders of :func:`regular_orders` with ``include_dc=True`` and ``sidebands=B``
    (default 1) are removed. This is the signal of FM4, M6A and M8A (Stewart 1977; Martin 1989;
    Zakrajsek 1989; MATLAB ``tsadifference`` with NumSidebands = 1).

    Parameters
    ----------
    x : array_like, shape (..., N)
        One revolution (unit u).
    teeth : int
        Z [-].
    shaft_harmonics : int
        S, shaft orders 1..S removed [-].
    mesh_harmonics : int, optional
        M, mesh harmonics removed; default all below Nyquist.
    sidebands : int
        B, sidebands removed each side of each mesh harmonic [-] (default 1).

    Returns
    -------
    ndarray
        Difference signal, unit u.
    """
    ords = regular_orders(teeth, _n_last(x), shaft_harmonics=shaft_harmonics,
                          mesh_harmonics=mesh_harmonics, sidebands=sidebands, include_dc=True)
    return order_filter(x, ords, keep=False)


#: Residual presets: which orders each removes (S shaft orders, M mesh harmonics).
RESIDUAL_PRESETS: dict[str, dict] = {
    # Xue & Howard: "removes all the gear mesh harmonics and only includes the sidebands";
    # the mean (the 0th mesh harmonic) goes too - the paper removes the transmission error's DC.
    "paper": {"shaft_harmonics": 0, "mesh_harmonics": None, "remove_dc": True},
    # MATLAB tsaresidual defaults: shaft order 1 always, the orderList (here the mesh order Z)
    # and their harmonics up to NumHarmonics = 2, i.e. orders 1, 2, Z, 2Z; the mean is kept.
    "matlab": {"shaft_harmonics": 2, "mesh_harmonics": 2, "remove_dc": False},
    # Zakrajsek (NASA TM-102340, TM-105950): residual = TSA minus the shaft frequency and its
    # (low) harmonics and the mesh frequency and its harmonics, first-order sidebands kept.
    # Implemented: DC, shaft orders 1 and 2, all mesh harmonics below Nyquist.
    "zakrajsek": {"shaft_harmonics": 2, "mesh_harmonics": None, "remove_dc": True},
}


def residual_orders(teeth: int, samples_per_rev: int, *, preset: str = "paper",
                    shaft_harmonics: int | None = None, mesh_harmonics: int | None = None,
                    remove_dc: bool | None = None) -> np.ndarray:
    """Orders removed by :func:`residual` for a preset and overrides (see there)."""
    if preset not in RESIDUAL_PRESETS:
        raise InputError("residual_preset", preset, "one of " + ", ".join(
            repr(p) for p in RESIDUAL_PRESETS))
    cfg = dict(RESIDUAL_PRESETS[preset])
    if shaft_harmonics is not None:
        cfg["shaft_harmonics"] = shaft_harmonics
    if mesh_harmonics is not None:
        cfg["mesh_harmonics"] = mesh_harmonics
    if remove_dc is not None:
        cfg["remove_dc"] = bool(remove_dc)
    return regular_orders(teeth, samples_per_rev, shaft_harmonics=cfg["shaft_harmonics"],
                          mesh_harmonics=cfg["mesh_harmonics"], sidebands=0,
                          include_dc=cfg["remove_dc"])


def residual(x, *, teeth: int, preset: str = "paper", shaft_harmonics: int | None = None,
             mesh_harmonics: int | None = None, remove_dc: bool | None = None) -> np.ndarray:
    """Residual signal: the TSA with mesh harmonics (and per preset DC / shaft orders) removed.

    .. math:: r = \\mathcal F^{-1}[H X], \\quad H_k = 0 \\text{ for removed orders } k

    Presets (overridable by the keyword arguments):

    ``"paper"`` (default; Xue & Howard)
        All mesh harmonics ``m*Z`` up to Nyquist and the mean (the m = 0 harmonic) removed;
        shaft orders and all sidebands kept.
    ``"matlab"`` (MATLAB ``tsaresidual`` defaults, orderList = [Z])
        Shaft orders 1, 2 and mesh orders Z, 2Z removed (NumHarmonics = 2, shaft order 1 always
        included); the mean kept. MATLAB's own implementation is not reproduced bit for bit:
        here the removal is exact bin masking.
    ``"zakrajsek"`` (NA4 residual, NASA TM-102340 / TM-105950)
        Mean, shaft orders 1 and 2 and all mesh harmonics removed; first-order (and all other)
        sidebands kept. "Shaft frequency and harmonics" is read as the low shaft orders
        (1..``shaft_harmonics``); all integer orders would leave nothing.

    Parameters
    ----------
    x : array_like, shape (..., N)
        One revolution (unit u).
    teeth : int
        Z, teeth of the gear on the averaged shaft [-].
    preset : {"paper", "matlab", "zakrajsek"}
        Starting set of removed orders.
    shaft_harmonics : int, optional
        Override: shaft orders 1..S removed.
    mesh_harmonics : int, optional
        Override: mesh harmonics 1..M removed (default of the preset: all or 2).
    remove_dc : bool, optional
        Override: remove the mean.

    Returns
    -------
    ndarray
        Residual signal, unit u.
    """
    ords = residual_orders(teeth, _n_last(x), preset=preset, shaft_harmonics=shaft_harmonics,
                           mesh_harmonics=mesh_harmonics, remove_dc=remove_dc)
    return order_filter(x, ords, keep=False)
