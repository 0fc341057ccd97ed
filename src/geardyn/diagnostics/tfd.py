"""Pseudo Wigner-Ville distribution (PWVD) of a synchronous average, in angle x order.

For the analytic signal z of the mean-removed TSA (N samples per revolution) the pseudo
Wigner-Ville distribution with an odd lag window h of length 2L+1 is

.. math::

    W(n, k) = \\sum_{m=-L}^{L} h(m)\\, z[n+m]\\, z^*[n-m]\\, e^{-2\\pi i k m / N_f},
    \\qquad k = 0, \\dots, N_f - 1.

The lag product at lag m spans 2m samples, so a tone of f cycles/sample peaks at bin
:math:`k = 2 f N_f`: with :math:`N_f = N` bins, **bin k is shaft order k/2** (half-order
resolution, orders 0 .. N/2). The TSA is one period of a periodic signal, so the lags are taken
**circularly** (indices modulo N) by default, which removes the edge effects of a finite record;
``periodic=False`` truncates the lags at the record ends exactly as tftb's
``PseudoWignerVilleDistribution`` does (``|m| <= min(n, N-1-n, L)``).

The smoothed pseudo WVD (SPWVD) also smooths the lag products along angle with a normalised
odd window g of length 2P+1 (circularly for periodic input):

.. math:: W_s(n, k) = \\sum_m h(m) \\Bigl[\\sum_{p=-P}^{P} g(p) z[n-p+m] z^*[n-p-m]\\Bigr]
    e^{-2\\pi i k m/N_f}, \\qquad \\sum_p g(p) = 1,

trading angle resolution for weaker cross terms.

The implementation is vectorised: the (N x (L+1)) lag-product matrix is built with fancy
indexing, the Hermitian symmetry in m is used (:math:`W = 2\\,\\mathrm{Re}\\,\\mathrm{FFT}_m - r_0`)
and one FFT along the lag axis gives all angles at once.

References
----------
Wang, W. J., McFadden, P. D. (1993). Early detection of gear failure by vibration analysis - I.
Calculation of the time-frequency distribution. Mechanical Systems and Signal Processing, 7(3),
193-203.

Forrester, B. D. (1996). Advanced vibration analysis techniques for fault detection and
diagnosis in geared transmission systems. PhD thesis, Swinburne University of Technology.

Claasen, T. A. C. M., Mecklenbrauker, W. F. G. (1980). The Wigner distribution - a tool for
time-frequency signal analysis. Philips J. Res., 35, 217-250, 276-300, 372-389.

Auger, F., Flandrin, P., Goncalves, P., Lemoine, O. (1996). Time-Frequency Toolbox (tftb).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from scipy import fft as sfft

from geardyn.errors import InputError

from .tsa import _as_float_array, _check_int

__all__ = ["PWVDResult", "pwvd", "spwvd", "analytic_signal"]


@dataclass(frozen=True)
class PWVDResult:
    """A (smoothed) pseudo Wigner-Ville distribution over angle and order.

    Attributes
    ----------
    distribution : ndarray, shape (N, K)
        W(angle, order), rows = angle samples, columns = order bins. Unit: u^2 (square of the
        signal's unit; not normalised: an analytic tone of amplitude A gives about
        ``A**2 * sum(h)`` at its order).
    angle : ndarray, shape (N,)
        Shaft angle of each row [rad].
    orders : ndarray, shape (K,)
        Shaft order of each column [-] (bin k = order ``k * samples_per_rev / (2 * n_fbins)``).
    window_length : int
        Length 2L+1 of the lag window [samples].
    time_window_length : int
        Length 2P+1 of the angle-smoothing window [samples]; 1 for the (unsmoothed) PWVD.
    periodic : bool
        Circular lags (True) or truncated at the record ends (False).
    n_fbins : int
        Number of frequency bins N_f of the lag FFT.
    """

    distribution: np.ndarray
    angle: np.ndarray
    orders: np.ndarray
    window_length: int
    time_window_length: int
    periodic: bool
    n_fbins: int

    @property
    def angle_deg(self) -> np.ndarray:
        """Shaft angle of each row [deg]."""
        return np.degrees(self.angle)


def analytic_signal(x, *, remove_mean: bool = True) -> np.ndarray:
    """Analytic signal of a periodic record by the FFT (exact for one-revolution records).

    :math:`Z_0 = 0` (mean removed) or :math:`X_0`, :math:`Z_k = 2X_k` for ``0 < k < N/2``,
    :math:`Z_{N/2} = X_{N/2}` (even N), :math:`Z_k = 0` for negative orders; z = IFFT(Z).

    Parameters
    ----------
    x : array_like, shape (N,)
        Real record (unit u).
    remove_mean : bool
        Drop the mean (order 0).

    Returns
    -------
    ndarray of complex, shape (N,)
        z, with ``z.real`` equal to ``x - mean(x)`` to rounding (unit u).
    """
    xa = _as_float_array(x, "x", min_size=2)
    # Marple (1999), "Computing the discrete-time analytic signal via FFT", IEEE Trans. Signal
    # Process. 47(9), 2600-2603: the weights above, the N/2 bin of an even N kept once. The
    # weights of scipy.signal.hilbert (tests/diagnostics/test_analytic_signal.py compares the
    # two); computed here because importing scipy.signal costs 0.4 s and 24 MB in every process
    # that diagnoses (measured 2026-11-27). The mean is subtracted first, so Z_0 is zero to
    # rounding.
    z = xa - xa.mean() if remove_mean else xa
    n = z.size
    h = np.zeros(n)
    h[0] = 1.0
    h[1:(n + 1) // 2] = 2.0
    if n % 2 == 0:
        h[n // 2] = 1.0
    return sfft.ifft(sfft.fft(z) * h)


def _odd_window(window, length: int, name: str) -> np.ndarray:
    if isinstance(window, np.ndarray):
        w = np.asarray(window, dtype=np.float64)
        if w.ndim != 1 or w.size % 2 == 0:
            raise InputError(name, f"array of shape {w.shape}", "a 1-D window of odd length")
        return w
    if isinstance(window, str) and window == "hamming":
        # the default: numpy's symmetric Hamming window, w(n) = 0.54 - 0.46 cos(2 pi n / (M - 1)),
        # n = 0 ... M - 1 (numpy's documentation of numpy.hamming), which is scipy.signal's
        # "hamming" with fftbins=False to rounding (tests/diagnostics/test_analytic_signal.py),
        # without importing scipy.signal
        return np.hamming(length)
    from scipy.signal.windows import get_window

    try:
        w = get_window(window, length, fftbins=False)
    except (ValueError, TypeError) as exc:
        raise InputError(name, window, "a scipy.signal window name, e.g. 'hamming'") from exc
    return np.asarray(w, dtype=np.float64)


def _default_length(n_fbins: int, divisor: int) -> int:
    h = n_fbins // divisor
    return h + 1 - (h % 2)  # make it odd (tftb's rule)


#: Angles (rows) of a PWVD computed together: each row's FFT is independent, so the blocks give
#: the whole-array result bit for bit while the complex spectrum stays small (the paper's run:
#: 4096 samples per revolution, 268 MB for the whole spectrum, 33 MB for a block).
_PWVD_ROWS = 512


def pwvd(x, *, samples_per_rev: int | None = None, window_length: int | None = None,
         window="hamming", n_fbins: int | None = None, periodic: bool = True,
         analytic: bool = True, remove_mean: bool = True,
         time_window_length: int | None = None, time_window="hamming",
         max_order: float | None = None, distribution: bool = True) -> PWVDResult:
    """Pseudo Wigner-Ville distribution (optionally smoothed) of a TSA.

    See the module docstring for the definition; bin k is order ``k * N / (2 * n_fbins)``, i.e.
    order k/2 with the default ``n_fbins = N``.

    Parameters
    ----------
    x : array_like, shape (N,)
        One-revolution synchronous average (unit u) (or any record; then set
        ``periodic=False``).
    samples_per_rev : int, optional
        Samples per revolution used for the order and angle axes [-]; default ``len(x)``.
    window_length : int, optional
        Odd lag-window length 2L+1 [samples]; default ``N_f//4`` made odd (tftb's rule;
        513 for N_f = 2048). Must not exceed ``n_fbins``.
    window : str or ndarray
        Lag window h: a scipy window name (symmetric) or an odd-length array; normalised to
        h(0) = 1.
    n_fbins : int, optional
        Number of frequency bins N_f [-]; default N.
    periodic : bool
        Circular lags (for a periodic TSA, default) or lags truncated at the ends (tftb).
    analytic : bool
        Use the analytic signal (default). With False the real signal is used (aliasing and
        negative-frequency cross terms: not recommended).
    remove_mean : bool
        Remove the mean before forming the analytic signal.
    time_window_length : int, optional
        Odd length 2P+1 of the angle-smoothing window [samples]; None or 1 = no smoothing
        (PWVD). See :func:`spwvd`.
    time_window : str or ndarray
        Smoothing window g (normalised to unit sum).
    max_order : float, optional
        Keep only the order bins up to this order [-] (saves memory); default all.
    distribution : bool
        Compute the distribution (default). False returns the same axes and settings with an
        empty (0, 0) distribution, after the same checks of the input and options: for a caller
        that keeps the other results of :func:`geardyn.diagnostics.diagnose` but draws no PWVD
        (most of ``diagnose``'s time is the two PWVDs per signal).

    Returns
    -------
    PWVDResult
        Distribution [u^2] with its angle [rad] and order [-] axes.
    """
    xa = _as_float_array(x, "x", min_size=4)
    n = xa.shape[0]
    nrev = n if samples_per_rev is None else _check_int(samples_per_rev, "samples_per_rev", 1)
    nf = n if n_fbins is None else _check_int(n_fbins, "n_fbins", 2)
    wl = _default_length(nf, 4) if window_length is None else _check_int(
        window_length, "window_length", 1)
    if wl % 2 == 0 or wl > nf or wl > 2 * n - 1:
        raise InputError("window_length", wl,
                         f"an odd length <= n_fbins = {nf} and <= 2N-1 = {2 * n - 1}")
    h = _odd_window(window, wl, "window")
    if h.size > nf:
        raise InputError("window", f"length {h.size}", f"an odd length <= n_fbins = {nf}")
    lag = (h.size - 1) // 2
    h = h / h[lag]

    if analytic:
        z = analytic_signal(xa, remove_mean=remove_mean)
    else:
        z = (xa - xa.mean() if remove_mean else xa).astype(np.complex128)

    twl = 1 if time_window_length is None else _check_int(time_window_length,
                                                           "time_window_length", 1)
    if twl > 1 and (twl % 2 == 0 or twl > n):
        raise InputError("time_window_length", twl, f"an odd length <= N = {n}")
    orders = np.arange(nf) * nrev / (2.0 * nf)
    keep = np.ones(nf, dtype=bool) if max_order is None else \
        orders <= float(max_order) + 1e-12
    mm = np.arange(lag + 1)[None, :]

    def lag_products(rows: np.ndarray) -> np.ndarray:
        nn = rows[:, None]
        if periodic:
            return z[(nn + mm) % n] * np.conj(z[(nn - mm) % n])
        ip, im = nn + mm, nn - mm
        ok = (ip < n) & (im >= 0)
        return np.where(ok, z[np.minimum(ip, n - 1)] * np.conj(z[np.maximum(im, 0)]), 0.0)

    def rows_of(r: np.ndarray) -> np.ndarray:
        """Rows of the distribution from their windowed lag products (FFT over the lag)."""
        buf = np.zeros((r.shape[0], nf), dtype=np.complex128)
        buf[:, : lag + 1] = r
        spec = sfft.fft(buf, axis=1, overwrite_x=True)
        return (2.0 * spec.real - r[:, :1].real)[:, keep]

    if not distribution:
        return PWVDResult(distribution=np.zeros((0, 0)), angle=2.0 * np.pi * np.arange(n) / nrev,
                          orders=orders[keep], window_length=int(h.size),
                          time_window_length=int(twl), periodic=bool(periodic),
                          n_fbins=int(nf))
    dist = np.empty((n, int(np.count_nonzero(keep))))
    if twl > 1:  # angle smoothing couples the rows: all lag products at once
        g = _odd_window(time_window, twl, "time_window")
        g = g / g.sum()
        rows = np.arange(n)
        valid = None if periodic else ((rows[:, None] + mm < n) & (rows[:, None] - mm >= 0))
        r = _smooth_rows(lag_products(rows), g, periodic, valid)
        r *= h[lag:][None, :]
        for b0 in range(0, n, _PWVD_ROWS):
            dist[b0:b0 + _PWVD_ROWS] = rows_of(r[b0:b0 + _PWVD_ROWS])
    else:  # a block of angles at a time: the n x n_fbins spectrum is never held whole
        for b0 in range(0, n, _PWVD_ROWS):
            r = lag_products(np.arange(b0, min(b0 + _PWVD_ROWS, n)))
            r *= h[lag:][None, :]
            dist[b0:b0 + _PWVD_ROWS] = rows_of(r)
    orders = orders[keep]
    return PWVDResult(distribution=dist, angle=2.0 * np.pi * np.arange(n) / nrev, orders=orders,
                      window_length=int(h.size), time_window_length=int(twl),
                      periodic=bool(periodic), n_fbins=int(nf))


def _smooth_rows(r: np.ndarray, g: np.ndarray, periodic: bool, valid) -> np.ndarray:
    """Convolve the lag products with g along the angle axis (circular or renormalised)."""
    n = r.shape[0]
    p = (g.size - 1) // 2
    if periodic:
        gc = np.zeros(n)
        gc[: p + 1] = g[p:]
        if p:
            gc[-p:] = g[:p]
        return sfft.ifft(sfft.fft(r, axis=0) * sfft.fft(gc)[:, None], axis=0)
    from scipy.signal import fftconvolve

    num = fftconvolve(r, g[:, None], mode="same", axes=0)
    den = fftconvolve(valid.astype(np.float64), g[:, None], mode="same", axes=0)
    out = np.zeros_like(num)
    ok = den > 1e-12
    out[ok] = num[ok] / den[ok]
    return out


def spwvd(x, *, time_window_length: int | None = None, **kwargs) -> PWVDResult:
    """Smoothed pseudo Wigner-Ville distribution: :func:`pwvd` with angle smoothing.

    Parameters
    ----------
    x : array_like, shape (N,)
        One-revolution TSA (unit u).
    time_window_length : int, optional
        Odd length of the angle-smoothing window [samples]; default ``N_f//10`` made odd
        (tftb's ``smoothed_pseudo_wigner_ville`` rule).
    **kwargs
        Passed to :func:`pwvd`.

    Returns
    -------
    PWVDResult
        As :func:`pwvd`.
    """
    if time_window_length is None:
        n = np.shape(x)[-1]
        nf = kwargs.get("n_fbins") or n
        time_window_length = max(3, _default_length(int(nf), 10))
    return pwvd(x, time_window_length=time_window_length, **kwargs)
