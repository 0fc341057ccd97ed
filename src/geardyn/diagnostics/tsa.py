"""Angle-domain resampling and time synchronous averaging (TSA).

The time synchronous average of a signal :math:`x` with respect to a shaft is the mean of the
signal over whole shaft revolutions, sampled on an equispaced grid of shaft angle:

.. math::

    \\bar x(\\theta_n) = \\frac{1}{R} \\sum_{r=0}^{R-1} x(\\theta_0 + 2\\pi r + \\theta_n),
    \\qquad \\theta_n = 2\\pi n / N, \\quad n = 0, \\dots, N-1,

where :math:`x(\\theta)` is the signal as a function of the (unwrapped) shaft angle, :math:`R` the
number of averages (whole revolutions) and :math:`N` the number of samples per revolution.
Components synchronous with the shaft (integer orders) pass unchanged; a component of
non-integer order :math:`q` is scaled by the comb-filter response
:math:`|\\sin(\\pi R q) / (R \\sin(\\pi q))|` and uncorrelated noise falls as
:math:`1/\\sqrt{R}` (McFadden 1987; Braun 1975).

Two ways of knowing the angle are supported:

* the **exact angle** of every sample (a simulation, or an encoder already converted to angle):
  the signal is interpolated against that angle with a local Lagrange interpolant (6 points
  by default: quintic), so no constant-speed assumption is made within a revolution;
* **tachometer pulse times**: a global cubic spline of angle through the pulses (McFadden 1989,
  "Interpolation techniques for time domain averaging of gear vibration") gives the angle of
  every sample, and the same resampling follows. The pulse times must be known to a small
  fraction of a sample: a random timing error of RMS d samples lowers an order at f cycles
  per sample by about (2 pi f d)^2 / 2 in the average. A band-limited (anti-alias filtered) pulse edge is
  located to about 0.05 sample by :func:`tach_pulse_times`; a square pulse sampled without a
  filter only to +/- half a sample (about -1.3 % at 0.1 fs), which that function warns about.

Anti-aliasing is done in the angle domain: the signal is first resampled onto a grid of
``L * N`` points per revolution, with ``L`` chosen so that this grid is at least as dense as the
raw samples at the slowest speed (no aliasing by the resampling itself); the synchronous
average of that grid is then low-passed by an ideal order-domain filter (orders ``|k| < N/2``
kept, FFT bin masking, exact because the averaged record is one period of a periodic signal)
and decimated by ``L``.

References
----------
McFadden, P. D. (1987). A revised model for the extraction of periodic waveforms by time domain
averaging. Mechanical Systems and Signal Processing, 1(1), 83-95.

McFadden, P. D. (1989). Interpolation techniques for time domain averaging of gear vibration.
Mechanical Systems and Signal Processing, 3(1), 87-97.

Braun, S. (1975). The extraction of periodic waveforms by time domain averaging. Acustica,
32(2), 69-77.
"""

from __future__ import annotations

import functools
import math
import warnings
from dataclasses import dataclass
from typing import Any

import numpy as np
from scipy import fft as sfft

from geardyn.errors import InputError

__all__ = [
    "DiagnosticsWarning",
    "TSAResult",
    "tsa",
    "tach_pulse_times",
    "tach_threshold",
    "angle_from_tach",
]

TWO_PI = 2.0 * np.pi


class DiagnosticsWarning(UserWarning):
    """Suspicious but usable input to a :mod:`geardyn.diagnostics` function."""


class ShortRecordError(InputError):
    """:func:`tsa` found no whole revolution to average in the record.

    An :class:`~geardyn.errors.InputError` on ``x`` that also keeps the numbers, so that a caller
    who knows where the record came from (e.g. :func:`~geardyn.diagnostics.diagnose_file`) can
    say it in the user's terms.

    Attributes
    ----------
    revolutions : float
        Shaft revolutions the record spans [-] (from the first to the last usable sample).
    skip : int
        Revolutions asked to be skipped at the start [-].
    """

    def __init__(self, revolutions: float, skip: int = 0):
        self.revolutions = float(revolutions)
        self.skip = int(skip)
        super().__init__(
            "x",
            f"a record spanning {self.revolutions:.3g} revolutions"
            + (f" after skipping {self.skip}" if self.skip else ""),
            "at least one whole revolution (starting at angle_origin + 2*pi*k)",
        )


# --------------------------------------------------------------------------------------------
# small validation helpers shared by the diagnostics modules
# --------------------------------------------------------------------------------------------
def _as_float_array(value: Any, name: str, *, ndim: tuple[int, ...] = (1,),
                    min_size: int = 1) -> np.ndarray:
    """Convert to a float64 array and check its dimensionality, size and finiteness."""
    try:
        arr = np.asarray(value, dtype=np.float64)
    except (TypeError, ValueError) as exc:
        raise InputError(name, _short(value), "a real numeric array") from exc
    if arr.ndim not in ndim:
        raise InputError(name, f"array of shape {arr.shape}",
                         f"an array with {' or '.join(str(d) for d in ndim)} dimension(s)")
    if arr.ndim == 0 or arr.shape[-1] < min_size:
        raise InputError(name, f"array of shape {arr.shape}",
                         f"at least {min_size} samples along the last axis")
    _check_finite(arr, name)
    return arr


def _check_finite(arr: np.ndarray, name: str) -> None:
    finite = np.isfinite(arr)
    if not finite.all():
        bad = np.argwhere(~finite)[0]
        idx = tuple(int(i) for i in bad)
        where = idx[0] if len(idx) == 1 else idx
        raise InputError(name, f"non-finite value {float(arr[tuple(bad)])!r} at index {where}",
                         "finite numbers only (no NaN or inf); trim or repair the record")


def _short(value: Any) -> str:
    text = repr(value)
    return text if len(text) <= 60 else text[:57] + "..."


def _check_int(value: Any, name: str, minimum: int, allowed: str | None = None) -> int:
    if isinstance(value, bool) or not isinstance(value, (int, np.integer)) or value < minimum:
        raise InputError(name, value, allowed or f"an integer >= {minimum}")
    return int(value)


# --------------------------------------------------------------------------------------------
# result type
# --------------------------------------------------------------------------------------------
@dataclass(frozen=True)
class TSAResult:
    """Time synchronous average of one or several signals.

    Attributes
    ----------
    average : ndarray, shape (N,) or (C, N)
        The synchronous average over one revolution, in the units of the input signal.
    angle : ndarray, shape (N,)
        Shaft angle of each sample relative to the start of a revolution [rad],
        ``2*pi*n/N``.
    n_averages : int
        Number of whole revolutions averaged, R [-].
    samples_per_rev : int
        Samples per revolution of the result, N [-].
    start_angle : float
        Absolute shaft angle at which the first averaged revolution starts [rad].
    oversampling : int
        Angle-domain oversampling factor L used before the anti-alias filter [-]
        (1 means no anti-alias filtering was needed or it was switched off).
    method : str
        ``"angle"`` (exact angle given) or ``"tach"`` (angle from tachometer pulses).
    records : ndarray or None, shape (R, N) or (C, R, N)
        The resampled (and anti-alias filtered) individual revolutions, in the units of the
        input, when ``keep_records=True``; otherwise None.
    """

    average: np.ndarray
    angle: np.ndarray
    n_averages: int
    samples_per_rev: int
    start_angle: float
    oversampling: int
    method: str
    records: np.ndarray | None = None

    @property
    def angle_deg(self) -> np.ndarray:
        """Shaft angle of each sample [deg]."""
        return np.degrees(self.angle)


# --------------------------------------------------------------------------------------------
# resampling kernels: a NumPy implementation and a numba twin (same arithmetic)
# --------------------------------------------------------------------------------------------
def _resample_numpy(angle: np.ndarray, x: np.ndarray, theta0: float, dtheta: float,
                    n_points: int, period: int, accumulate: bool,
                    out: np.ndarray, chunk: int = 1 << 18, taps: int = 6) -> None:
    """Local Lagrange interpolation (``taps`` points, even) of ``x`` against ``angle``.

    Evaluates at ``theta0 + j*dtheta`` for ``j < n_points``; with ``accumulate`` the values are
    added into ``out[:, j % period]``, otherwise written to ``out[:, j]``. The stencil is the
    ``taps`` samples centred on the interval holding the evaluation point (shifted inwards at
    the ends of the record), at angles :math:`\\theta_m` (non-uniform). The Lagrange basis
    polynomials are evaluated in the first barycentric form (Berrut & Trefethen 2004,
    "Barycentric Lagrange interpolation", SIAM Review 46(3) 501-517; as written here, Driscoll &
    Braun, *Fundamentals of Numerical Computation*, section 9.2, eqs. 9.2.1 and 9.2.3):

    .. math:: \\ell_q(\\theta) = b_q \\prod_{m \\ne q} (\\theta - \\theta_m), \\qquad
              b_q = 1 \\Big/ \\prod_{m \\ne q} (\\theta_q - \\theta_m),

    the products over :math:`m \\ne q` taken as (product over :math:`m < q`) times (product
    over :math:`m > q`), so that no division by :math:`\\theta - \\theta_q` is made and the
    interpolant is exact at a sample. The weights :math:`b_q` depend on the stencil only: the
    compiled twin (:func:`_numba_kernel`) computes them once per stencil rather than once per
    output point, which takes the divisions out of the inner loop (the anti-aliased TSA of 1e7
    samples of ``benchmarks/run.py diagnostics``: 1.35 s before, 0.56 s after, same-time A/B on
    2026-11-28, the average the same to 5e-16 of its largest value). Angles are taken
    relative to the stencil's first sample. This twin computes the same operations in the same
    order, vectorised over a chunk of output points.
    """
    n = angle.shape[0]
    for start in range(0, n_points, chunk):
        j = np.arange(start, min(start + chunk, n_points))
        th = theta0 + j * dtheta
        i = np.searchsorted(angle, th, side="right") - 1
        s = np.clip(i - (taps // 2 - 1), 0, n - taps)
        a0 = angle[s]
        e = [angle[s + m] - a0 for m in range(taps)]
        b = []
        for q in range(taps):
            p = np.ones_like(th)
            for m in range(taps):
                if m != q:
                    p = p * (e[q] - e[m])
            b.append(1.0 / p)
        t = th - a0
        d = [t - e[m] for m in range(taps)]
        pre = []
        acc = np.ones_like(t)
        for q in range(taps):
            pre.append(acc)
            acc = acc * d[q]
        v = np.zeros((x.shape[0], j.shape[0]))
        w = [None] * taps
        acc = np.ones_like(t)
        for q in range(taps - 1, -1, -1):
            w[q] = b[q] * pre[q] * acc
            acc = acc * d[q]
        for q in range(taps):
            v += w[q] * x[:, s + q]
        if accumulate:
            pos = j % period
            # j runs over consecutive integers: fold the chunk into the period with bincount
            for c in range(x.shape[0]):
                out[c] += np.bincount(pos, weights=v[c], minlength=period)
        else:
            out[:, j] = v


@functools.cache
def _numba_kernel(taps: int = 6):
    """Compile (once per process and stencil size) the numba twin of :func:`_resample_numpy`
    for ``taps``-point stencils; None if numba is absent.

    ``taps`` is a constant of the compiled code: numba freezes a closure's variables, and its
    disk cache keys a closure on their values. With the stencil's length known, the loops over
    it are unrolled: the kernel of the anti-aliased TSA of 1e7 samples took 0.52 s against
    0.80 s with ``taps`` an argument (2026-11-28, this host).
    """
    try:
        import numba
    except ImportError:  # pragma: no cover - numba is a declared dependency
        return None

    @numba.njit(cache=True, fastmath=False, nogil=True)
    def kernel(angle, x, theta0, dtheta, n_points, period, accumulate,
               out):  # pragma: no cover
        n = angle.shape[0]
        nc = x.shape[0]
        half = taps // 2
        e = np.empty(taps)
        b = np.empty(taps)  # barycentric weights of the stencil starting at s_now
        d = np.empty(taps)
        pre = np.empty(taps)
        w = np.empty(taps)
        i = 0
        pos = 0
        s_now = -1
        a0 = 0.0
        for j in range(n_points):
            th = theta0 + j * dtheta
            while i < n - 2 and angle[i + 1] <= th:
                i += 1
            s = i - (half - 1)
            if s < 0:
                s = 0
            if s > n - taps:
                s = n - taps
            if s != s_now:  # a new stencil: its barycentric weights
                s_now = s
                a0 = angle[s]
                for m in range(taps):
                    e[m] = angle[s + m] - a0
                for q in range(taps):  # m ascending, m != q, as in the twin
                    p = 1.0
                    for m in range(q):
                        p = p * (e[q] - e[m])
                    for m in range(q + 1, taps):
                        p = p * (e[q] - e[m])
                    b[q] = 1.0 / p
            t = th - a0
            for m in range(taps):
                d[m] = t - e[m]
            acc = 1.0
            for q in range(taps):
                pre[q] = acc
                acc = acc * d[q]
            acc = 1.0
            for q in range(taps - 1, -1, -1):
                w[q] = b[q] * pre[q] * acc
                acc = acc * d[q]
            for c in range(nc):
                v = 0.0
                for q in range(taps):
                    v += w[q] * x[c, s + q]
                if accumulate:
                    out[c, pos] += v
                else:
                    out[c, j] = v
            pos += 1
            if pos == period:
                pos = 0

    return kernel


def _resample(angle, x2d, theta0, dtheta, n_points, period, accumulate, engine, taps=6):
    nc = x2d.shape[0]
    out = np.zeros((nc, period if accumulate else n_points), dtype=np.float64)
    taps = min(int(taps), 2 * (angle.shape[0] // 2))
    kernel = _numba_kernel(taps) if engine in ("auto", "numba") else None
    if engine == "numba" and kernel is None:  # pragma: no cover
        raise InputError("engine", engine, "'numpy' (numba is not installed)")
    if kernel is not None:
        kernel(angle, x2d, float(theta0), float(dtheta), int(n_points), int(period),
               bool(accumulate), out)
    else:
        _resample_numpy(angle, x2d, float(theta0), float(dtheta), int(n_points), int(period),
                        bool(accumulate), out, taps=taps)
    return out


def _lowpass_decimate(y: np.ndarray, n_out: int) -> np.ndarray:
    """Ideal order-domain low-pass (orders ``|k| < n_out/2`` kept) and decimation.

    ``y`` holds whole revolutions of ``M = L*n_out`` samples along the last axis. Exact for a
    periodic record: bins ``k < n_out/2`` are copied, the rest (including the order
    ``n_out/2`` itself for even ``n_out``) are zeroed, and the inverse FFT has ``n_out`` points.
    """
    m = y.shape[-1]
    if m == n_out:
        return y
    spec = sfft.rfft(y, axis=-1)
    kmax = (n_out - 1) // 2  # highest order strictly below n_out / 2
    keep = np.zeros(spec.shape[:-1] + (n_out // 2 + 1,), dtype=np.complex128)
    keep[..., : kmax + 1] = spec[..., : kmax + 1]
    return sfft.irfft(keep, n=n_out, axis=-1) * (n_out / m)


# --------------------------------------------------------------------------------------------
# angle checks
# --------------------------------------------------------------------------------------------
def _check_angle(angle: np.ndarray, name: str, unwrap: bool
                 ) -> tuple[np.ndarray, np.ndarray]:
    """Unwrap if asked, check strict increase; return the angle and its differences."""
    if unwrap:
        angle = np.unwrap(angle)
    d = np.diff(angle)
    if d.size == 0:
        raise InputError(name, "a single sample", "at least 4 samples")
    if not np.all(d > 0):
        bad = int(np.flatnonzero(~(d > 0))[0])
        if np.all(d < 0):
            allowed = ("a strictly increasing shaft angle; for reverse rotation pass -angle "
                       "(and expect orders to be mirrored)")
        elif np.any(np.abs(d + TWO_PI) < 0.5) and not unwrap:
            allowed = ("a strictly increasing (unwrapped) shaft angle; this one jumps by about "
                       "-2*pi: it looks wrapped (unwrap it: tsa(unwrap=True), "
                       "diagnose_file(unwrap_angle=True), geardyn diagnose --unwrap-angle)")
        else:
            allowed = "a strictly increasing (unwrapped) shaft angle"
        raise InputError(
            name,
            f"non-monotonic angle: angle[{bad + 1}] - angle[{bad}] = {d[bad]:.6g} rad",
            allowed,
        )
    return angle, d


# --------------------------------------------------------------------------------------------
# tachometer
# --------------------------------------------------------------------------------------------
def tach_threshold(signal, threshold: float | None = None) -> float:
    """The edge level of a tachometer pulse train: ``threshold``, else midway between the
    signal's minimum and maximum (unit of the signal)."""
    if threshold is not None:
        return float(threshold)
    s = np.asarray(signal, dtype=np.float64)
    return 0.5 * (float(s.min()) + float(s.max()))


def tach_pulse_times(signal, *, fs: float | None = None, time=None,
                     threshold: float | None = None,
                     min_interval: float | None = None, edge: str = "rising") -> np.ndarray:
    """Times of the rising (or falling) edges of a sampled tachometer pulse train.

    A rising edge is a crossing of ``threshold`` from below between samples ``i-1`` and ``i``
    (a falling edge, ``edge="falling"``, from above: the leading edge of an active-low pulse);
    its time is located by linear interpolation between the two samples (sub-sample accuracy):

    .. math:: t_e = t_{i-1} + (t_i - t_{i-1}) (c - s_{i-1}) / (s_i - s_{i-1}).

    Parameters
    ----------
    signal : array_like, shape (n,)
        Sampled tachometer channel (any unit, e.g. V).
    fs : float, optional
        Sample rate [Hz]; sample ``i`` is at time ``i / fs`` [s]. Give ``fs`` or ``time``.
    time : array_like, shape (n,), optional
        Sample times [s], strictly increasing.
    threshold : float, optional
        Crossing level c, in the unit of ``signal``. Default: midway between the minimum and the
        maximum of the signal.
    min_interval : float, optional
        Minimum time between accepted edges [s]; later edges closer than this to the previous
        accepted edge (noise chatter) are discarded. Default: no filtering.
    edge : {"rising", "falling"}
        Which edge marks the pulse: ``"rising"`` (an active-high pulse) or ``"falling"`` (an
        active-low one). The pulse's *leading* edge is the one to give: a pulse of fixed
        duration (a one-shot sensor output) puts its trailing edge at an angle that moves with
        the speed, which smears a run-up's TSA.

    Returns
    -------
    ndarray
        Edge times [s], increasing.

    Warns
    -----
    DiagnosticsWarning
        When the edges are not resolved by the sampling: the pulse jumps from its low to its
        high level between two samples (a square pulse sampled without an anti-alias filter).
        Then each edge is located only to within one sample interval, whatever the
        interpolation; averaged over revolutions this timing jitter (uniform, +/- half a
        sample) scales an order at f cycles per raw sample by down to sinc(f) =
        sin(pi f)/(pi f) in the TSA (-0.8 % at f = 0.07, -1.6 % at f = 0.1; measured -0.55 %
        and -1.3 % with 1 pulse per revolution, where the angle spline between pulses
        averages neighbouring errors). Record the tachometer through the
        anti-alias filter (a band-limited edge is located to a few hundredths of a sample by
        the linear crossing) or give counter time stamps of the pulses.
    """
    s = _as_float_array(signal, "tach", min_size=2)
    if edge not in ("rising", "falling"):
        raise InputError("edge", edge, "'rising' or 'falling'")
    t = _sample_times(s.shape[0], fs, time)
    if threshold is None and not s.max() > s.min():  # a flat channel has no pulses to find
        raise InputError("tach", f"a constant channel ({s.min():.6g} throughout)",
                         "a tachometer channel with pulses: is it connected, or is it another "
                         "column?")
    c = tach_threshold(s, threshold)
    if not s.min() < c <= s.max():
        raise InputError("threshold", c, f"a level between the tach minimum {s.min():.6g} and "
                         f"maximum {s.max():.6g}")
    if edge == "falling":  # the falling edges of s are the rising edges of -s at -c
        s, c = -s, -c
    i = np.flatnonzero((s[:-1] < c) & (s[1:] >= c)) + 1
    frac = (c - s[i - 1]) / (s[i] - s[i - 1])
    edges = t[i - 1] + frac * (t[i] - t[i - 1])
    _warn_unresolved_edges(s, i, edge)
    if min_interval is not None and edges.size > 1:
        if not min_interval > 0:
            raise InputError("min_interval", min_interval, "a positive time in s")
        kept = [edges[0]]
        for e in edges[1:]:
            if e - kept[-1] >= min_interval:
                kept.append(e)
        edges = np.asarray(kept)
    return edges


def _warn_unresolved_edges(s: np.ndarray, i: np.ndarray, edge: str = "rising") -> None:
    """Warn when most edges jump from one level to the other in one sample (``s`` as searched:
    a falling edge's signal negated)."""
    if i.size == 0:
        return
    lo, hi = float(s.min()), float(s.max())
    tol = 0.02 * (hi - lo)
    # the samples just before and just after the crossing: on a resolved (band-limited) edge
    # at least one of them is part-way up; on an unresolved one both sit at the extremes
    before = s[np.maximum(i - 1, 0)]
    after = s[i]
    jumps = (before <= lo + tol) & (after >= hi - tol)
    if np.count_nonzero(jumps) > 0.5 * i.size:
        warnings.warn(
            f"tach edges are not resolved by the sampling ({np.count_nonzero(jumps)} of "
            f"{i.size} {edge} edges jump from one level to the other between two samples): "
            "each pulse time is known only to +/- half a sample, which lowers the TSA "
            "amplitude of an order at f cycles per sample by about 1 - sinc(f) (0.8 % at "
            "0.07 fs, 1.6 % at 0.1 fs) when the pulses fall anywhere within the sample "
            "intervals, and by more when the speed is locked to the sample rate (a whole "
            "number of samples per pulse repeats the same error in every revolution). Record "
            "the tach through the anti-alias filter, or give counter time stamps of the "
            "pulses.",
            DiagnosticsWarning,
            stacklevel=3,
        )


#: Largest step between two sample times, in the larger of its two neighbouring steps, that
#: is not a gap in the record: one dropped sample (a step of 2) passes, so does a DAQ's
#: timestamp jitter; a lost DAQ buffer does not.
MAX_STEP_RATIO = 2.5


def _check_no_gap(x: np.ndarray, dx: np.ndarray, name: str, unit: str) -> None:
    """Refuse samples with a gap: a step of ``x`` (sample times [s]) above
    :data:`MAX_STEP_RATIO` times both its neighbouring steps. (Not applied to a shaft angle
    alone: synthetic angles may step unevenly on purpose.)

    The TSA interpolates each signal onto equal angle steps; across a gap it would draw a line
    where the record has nothing. A line through the 7.8 ms of 200 samples cut out of a
    25.6 kHz record (a user audit of 2026-11-27) averaged into a dip of seven times the
    signal's amplitude at a wrong angle, with nothing said: a fault that is not there."""
    if dx.size < 3:
        return
    near = np.maximum(np.r_[dx[1], dx[:-1]], np.r_[dx[1:], dx[-2]])  # the larger neighbour
    gaps = np.flatnonzero(dx > MAX_STEP_RATIO * near)
    if gaps.size == 0:
        return
    worst = int(gaps[np.argmax(dx[gaps] / near[gaps])])
    raise InputError(
        name, f"a gap of {dx[worst]:.4g} {unit} after {name} = {x[worst]:.6g} {unit}",
        f"samples without gaps (about {dx[worst] / near[worst] - 1:.0f} samples are missing "
        f"there at the neighbouring steps of {near[worst]:.4g} {unit}"
        + (f"; {gaps.size} gaps in all" if gaps.size > 1 else "")
        + f"; a step may be at most {MAX_STEP_RATIO:g} times its neighbours): the TSA would "
        "interpolate across the gap; diagnose the parts before and after it as records of "
        "their own")


def _sample_times(n: int, fs: float | None, time) -> np.ndarray:
    if time is not None:
        t = _as_float_array(time, "time", min_size=2)
        if t.shape[0] != n:
            raise InputError("time", f"{t.shape[0]} samples", f"{n} samples, like the signal")
        dt = np.diff(t)
        if not np.all(dt > 0):
            raise InputError("time", "non-increasing sample times", "strictly increasing times")
        _check_no_gap(t, dt, "time", "s")
        return t
    if fs is None:
        raise InputError("fs", None, "a sample rate in Hz (or pass time=)")
    if not (isinstance(fs, (int, float, np.integer, np.floating)) and np.isfinite(fs)
            and fs > 0):
        raise InputError("fs", fs, "a positive finite sample rate in Hz")
    return np.arange(n, dtype=np.float64) / float(fs)


def angle_from_tach(tach_times, sample_times, *, pulses_per_rev: int = 1) -> np.ndarray:
    """Shaft angle of each sample from tachometer pulse times (global cubic spline).

    Pulse ``k`` is taken to mark the shaft angle :math:`\\phi_k = 2\\pi k / P` (P =
    ``pulses_per_rev``, pulses assumed equally spaced on the shaft). A not-a-knot cubic spline
    :math:`\\phi(t)` through :math:`(t_k, \\phi_k)` gives the angle at the sample times. Samples
    more than two sample intervals outside the first/last pulse are returned as NaN.

    Parameters
    ----------
    tach_times : array_like, shape (P_total,)
        Pulse times [s], strictly increasing, at least 2.
    sample_times : array_like, shape (n,)
        Sample times [s].
    pulses_per_rev : int
        Tachometer pulses per shaft revolution P [-].

    Returns
    -------
    ndarray, shape (n,)
        Shaft angle [rad]; 0 at the first pulse.
    """
    tp = _as_float_array(tach_times, "tach_times", min_size=2)
    ppr = _check_int(pulses_per_rev, "pulses_per_rev", 1)
    if not np.all(np.diff(tp) > 0):
        raise InputError("tach_times", "non-increasing pulse times",
                         "strictly increasing pulse times in s")
    _check_pulse_regularity(tp)
    t = np.asarray(sample_times, dtype=np.float64)
    phi = TWO_PI * np.arange(tp.shape[0]) / ppr
    from scipy.interpolate import CubicSpline  # here: 0.25 s of CLI start-up otherwise

    spline = CubicSpline(tp, phi, bc_type="not-a-knot", extrapolate=True)
    dt = np.median(np.diff(t)) if t.shape[0] > 1 else 0.0
    inside = (t >= tp[0] - 2 * dt) & (t <= tp[-1] + 2 * dt)
    out = np.full(t.shape, np.nan)
    out[inside] = spline(t[inside])
    return out


def _check_pulse_regularity(tp: np.ndarray) -> None:
    if tp.shape[0] < 3:
        return
    d = np.diff(tp)
    ratio = d[1:] / d[:-1]
    bad = np.flatnonzero((ratio > 1.5) | (ratio < 1 / 1.5))
    if bad.size:
        k = int(bad[0]) + 1
        warnings.warn(
            f"tach pulse interval changes by a factor {ratio[bad[0]]:.3g} at pulse {k} "
            f"(t = {tp[k]:.6g} s): a missing or spurious pulse? The angle spline assumes one "
            "pulse per 1/pulses_per_rev revolution.",
            DiagnosticsWarning,
            stacklevel=3,
        )


# --------------------------------------------------------------------------------------------
# the TSA
# --------------------------------------------------------------------------------------------
def tsa(
    x,
    *,
    angle=None,
    fs: float | None = None,
    time=None,
    tach_times=None,
    pulses_per_rev: int = 1,
    samples_per_rev: int = 2048,
    n_revolutions: int | None = None,
    skip_revolutions: int = 0,
    angle_origin: float = 0.0,
    unwrap: bool = False,
    antialias: bool = True,
    min_revolutions: int = 2,
    keep_records: bool = False,
    engine: str = "auto",
    interp_points: int = 6,
) -> TSAResult:
    """Time synchronous average over whole shaft revolutions.

    .. math::

        \\bar x(\\theta_n) = \\frac1R \\sum_{r=0}^{R-1} x(\\theta_s + 2\\pi r + 2\\pi n/N)

    with :math:`x(\\theta)` obtained by local Lagrange interpolation (``interp_points``
    samples, quintic by default) of the samples against the shaft angle, :math:`\\theta_s`
    the start of the first whole revolution and N = ``samples_per_rev``. See the module
    docstring for the anti-alias filter.

    Parameters
    ----------
    x : array_like, shape (n,) or (C, n)
        Signal(s) sampled at the same instants (any unit; the average keeps it). Several
        channels share one angle computation.
    angle : array_like, shape (n,), optional
        Exact shaft angle of each sample [rad], strictly increasing (unwrapped). Give either
        ``angle`` or ``tach_times``.
    fs : float, optional
        Sample rate [Hz] (with ``tach_times``); sample ``i`` is at ``i / fs`` [s].
    time : array_like, shape (n,), optional
        Sample times [s] (with ``tach_times``), instead of ``fs``.
    tach_times : array_like, optional
        Tachometer pulse times [s] in the time base of ``x``; the first pulse defines angle 0.
        See :func:`tach_pulse_times` to get them from a sampled pulse train.
    pulses_per_rev : int
        Tachometer pulses per revolution [-] (equally spaced on the shaft).
    samples_per_rev : int
        N, samples per revolution of the average [-], >= 8. Any integer; powers of two are
        fastest.
    n_revolutions : int, optional
        Number of revolutions to average; default all whole revolutions available.
    skip_revolutions : int
        Whole revolutions to skip at the start (e.g. a start-up transient) [-].
    angle_origin : float
        Revolutions start where ``angle`` equals ``angle_origin`` modulo 2*pi [rad] (exact-angle
        path); so the average is aligned to the absolute shaft angle.
    unwrap : bool
        Unwrap a wrapped angle (values jumping by -2*pi) before use.
    antialias : bool
        Apply the angle-domain anti-alias filter (orders >= N/2 removed before decimation).
    min_revolutions : int
        Fewer whole revolutions than this gives a :class:`DiagnosticsWarning` (an average of one
        revolution is just a resampled revolution: no noise or non-synchronous rejection).
        Fewer than one whole revolution is an error.
    keep_records : bool
        Also return the individual resampled revolutions (``records``).
    engine : {"auto", "numba", "numpy"}
        Resampling kernel: the compiled numba kernel (default when numba is installed) or its
        vectorised NumPy twin (same arithmetic).
    interp_points : {4, 6, 8}
        Points of the local Lagrange interpolant [-]. Its mean amplitude response for a tone at
        f cycles per raw sample (uniform sampling, averaged over sub-sample positions) is
        1 - 5.6e-4 / 1 - 2.2e-5 / 1 - 9e-7 at f = 0.07 and 1 - 2.3e-3 / 1 - 1.8e-4 / 1 - 1.5e-5
        at f = 0.1 for 4 / 6 / 8 points (computed from the Lagrange weights); 6 keeps
        orders up to 0.1 fs within 0.02 %.

    Returns
    -------
    TSAResult
        The average (unit of ``x``), the angle grid [rad] and the number of averages R.

    Raises
    ------
    InputError
        NaN/inf in the inputs, non-monotonic angle, mismatched lengths, fewer than one whole
        revolution, bad options.

    Notes
    -----
    The local P-point Lagrange interpolant has error :math:`O(h^P x^{(P)})` with h the raw
    angle step; with the exact angle the average of a smooth signal under 5 % speed
    fluctuation is accurate to about 1e-7 of its amplitude at a few thousand raw samples per
    revolution. The interpolant is not an ideal low-pass: it attenuates content near the raw
    Nyquist frequency (see ``interp_points``) and leaves small images of it that the anti-alias
    filter cannot remove once they fall below N/2; sample the raw signal at several times its
    highest significant order.
    With tachometer pulses the error is dominated by the angle spline between pulses; the
    first and last revolutions carry the spline's end effects (about ten times the interior
    error in a test with 5 % speed fluctuation and one pulse per revolution): pass
    ``skip_revolutions=1`` and ``n_revolutions=R - 2`` to leave them out.

    References
    ----------
    McFadden (1987, 1989); Braun (1975); see the module docstring.
    """
    xa = _as_float_array(x, "x", ndim=(1, 2), min_size=4)
    squeeze = xa.ndim == 1
    x2d = np.ascontiguousarray(xa.reshape(1, -1) if squeeze else xa)
    n = x2d.shape[1]
    nper = _check_int(samples_per_rev, "samples_per_rev", 8)
    skip = _check_int(skip_revolutions, "skip_revolutions", 0)
    minrev = _check_int(min_revolutions, "min_revolutions", 1)
    if engine not in ("auto", "numba", "numpy"):
        raise InputError("engine", engine, "'auto', 'numba' or 'numpy'")
    if n_revolutions is not None:
        n_revolutions = _check_int(n_revolutions, "n_revolutions", 1)
    if interp_points not in (4, 6, 8) or isinstance(interp_points, bool):
        raise InputError("interp_points", interp_points, "4, 6 or 8")
    taps = int(interp_points)

    if (angle is None) == (tach_times is None):
        raise InputError("angle/tach_times", "both" if angle is not None else "neither",
                         "exactly one of angle= (exact shaft angle) or tach_times=")
    if angle is not None:
        ang = _as_float_array(angle, "angle", min_size=4)
        if ang.shape[0] != n:
            raise InputError("angle", f"{ang.shape[0]} samples",
                             f"{n} samples, like the signal(s) (x)")
        ang, d = _check_angle(ang, "angle", unwrap)
        if time is not None:  # the sample times beside the angle: a gap in them is one here
            _sample_times(n, fs, time)
        method = "angle"
        origin = float(angle_origin)
    else:
        t = _sample_times(n, fs, time)
        ppr = _check_int(pulses_per_rev, "pulses_per_rev", 1)
        full = angle_from_tach(tach_times, t, pulses_per_rev=ppr)
        inside = np.flatnonzero(np.isfinite(full))
        if inside.size < 4:
            raise InputError("tach_times", "pulses spanning fewer than 4 samples",
                             "pulses spanning at least one revolution of the record")
        sl = slice(inside[0], inside[-1] + 1)
        ang, d = _check_angle(full[sl], "tach_times (spline angle)", False)
        x2d = np.ascontiguousarray(x2d[:, sl])
        method = "tach"
        origin = 0.0

    # oversampling factor so that the resampling grid is as dense as the raw samples at the
    # slowest speed (capped at 4x the mean raw density to bound the cost for jittery angles)
    mean_per_rev = TWO_PI * (ang.shape[0] - 1) / (ang[-1] - ang[0])
    raw_per_rev = min(TWO_PI / float(d.min()), 4.0 * mean_per_rev)
    over = max(1, math.ceil(raw_per_rev / nper - 1e-9)) if antialias else 1
    m = over * nper
    dtheta = TWO_PI / m

    # a revolution may start/end up to half a raw sample outside the record (the end cubic
    # extrapolates that little accurately): avoids losing a revolution to rounding, e.g. when
    # the first tach pulse falls a hair before the first sample
    slack = 0.5 * min(float(d[0]), float(d[-1]))
    k0 = math.ceil((ang[0] - slack - origin) / TWO_PI)
    theta_s = origin + TWO_PI * (k0 + skip)
    available = math.floor((ang[-1] + slack - theta_s + dtheta) / TWO_PI)
    if available < 1:
        raise ShortRecordError((ang[-1] - ang[0]) / TWO_PI, skip)
    n_rev = available if n_revolutions is None else n_revolutions
    if n_rev > available:
        raise InputError("n_revolutions", n_revolutions,
                         f"at most {available} (whole revolutions in the record)")
    if n_rev < minrev:
        warnings.warn(
            f"TSA over only {n_rev} whole revolution(s) (min_revolutions={minrev}): no "
            "averaging of noise or non-synchronous components takes place.",
            DiagnosticsWarning,
            stacklevel=2,
        )

    n_points = n_rev * m
    acc = _resample(ang, x2d, theta_s, dtheta, n_points, m, not keep_records, engine, taps)
    if keep_records:
        recs = acc.reshape(x2d.shape[0], n_rev, m)
        recs = _lowpass_decimate(recs, nper) if over > 1 else recs
        avg = recs.mean(axis=1)
    else:
        avg = _lowpass_decimate(acc / n_rev, nper) if over > 1 else acc / n_rev
        recs = None
    if squeeze:
        avg = avg[0]
        recs = None if recs is None else recs[0]
    return TSAResult(
        average=avg,
        angle=TWO_PI * np.arange(nper) / nper,
        n_averages=int(n_rev),
        samples_per_rev=nper,
        start_angle=float(theta_s),
        oversampling=int(over),
        method=method,
        records=recs,
    )
