"""Signal statistics and gear condition metrics (FM0, FM4, M6A, M8A, NA4, NA4*, NB4, ER).

Conventions (those the paper's Table 2 implies): with :math:`\\mu` the mean and
:math:`m_k = \\frac1N\\sum (x_n - \\mu)^k` the biased central moments,

* standard deviation :math:`\\sigma = \\sqrt{m_2}` (ddof 0);
* skewness :math:`g_1 = m_3 / m_2^{3/2}` (biased Fisher-Pearson);
* kurtosis :math:`m_4 / m_2^2` (**Pearson**: 3 for a Gaussian, 1.5 for a sinusoid);
* crest factor :math:`\\max|x - \\mu| / \\sigma` (the paper's; 5.99 for Table 2's pinion speed of
  mean 114.14) and, as a second field, :math:`\\max|x| / \\mathrm{RMS}(x)` (the usual
  peak-to-RMS ratio, MATLAB's ``CrestFactor``); both are sqrt(2) for a zero-mean sinusoid.

Condition metrics (x = TSA, y = regular, d = difference, r = residual, see
:mod:`geardyn.diagnostics.spectra`; Lebold et al. 2000 review them all):

* FM0 = (max x - min x) / sum of the peak amplitudes of the mesh harmonics (Stewart 1977);
* FM4 = m4(d)/m2(d)^2, M6A = m6(d)/m2(d)^3, M8A = m8(d)/m2(d)^4 (Stewart 1977; Martin 1989);
  Gaussian d: 3, 15, 105;
* NA4 = m4(r_M) / ( (1/M) sum_{i=1..M} m2(r_i) )^2 over the residuals of the records 1..M of a
  run (current one last) (Zakrajsek 1993); M = 1 gives the kurtosis of r;
* NA4* = m4(r) / m2_healthy^2 with a fixed healthy-baseline variance (Decker et al. 1994);
* NB4 = NA4 applied to the envelope of the band about a mesh harmonic (Zakrajsek 1993);
* ER = RMS(d) / RMS(y) (Swansson 1980).

References
----------
Stewart, R. M. (1977). Some useful data analysis techniques for gearbox diagnostics. ISVR
report MHM/R/10/77.

Martin, H. R. (1989). Statistical moment analysis as a means of surface damage detection.
Proc. 7th International Modal Analysis Conference, 1016-1021.

Swansson, N. S. (1980). Application of vibration signal analysis techniques to signal
monitoring. Conference on Friction and Wear in Engineering, Inst. of Engineers Australia.

Zakrajsek, J. J. (1989). An investigation of gear mesh failure prediction techniques. NASA
TM-102340. Zakrajsek, J. J., Townsend, D. P., Decker, H. J. (1993). NASA TM-105950.

Decker, H. J., Handschuh, R. F., Zakrajsek, J. J. (1994). An enhancement to the NA4 gear
vibration diagnostic parameter. NASA TM-106553.

Lebold, M. et al. (2000). Review of vibration analysis methods for gearbox diagnostics and
prognostics. Proc. 54th MFPT meeting, 623-634.

MathWorks, ``gearConditionMetrics`` (Predictive Maintenance Toolbox): column names RMS, Kurtosis,
CrestFactor, FM4, M6A, M8A, FM0, EnergyRatio, NA4.
"""

from __future__ import annotations

import math
import warnings
from collections.abc import Iterable, Sequence
from dataclasses import asdict, dataclass

import numpy as np
from scipy import fft as sfft

from geardyn.errors import InputError

from ..io import json_safe
from .demodulation import band_analytic_signal
from .spectra import difference, mesh_orders, regular, residual
from .tsa import DiagnosticsWarning, _as_float_array, _check_int

__all__ = [
    "SignalStatistics",
    "ConditionMetrics",
    "NA4Tracker",
    "central_moment",
    "kurtosis",
    "signal_statistics",
    "condition_metrics",
    "fm0",
    "fm4",
    "m6a",
    "m8a",
    "na4",
    "na4_star",
    "nb4",
    "band_envelope",
    "energy_ratio",
    "is_constant",
    "CONSTANT_TOLERANCE",
]

#: Relative variation below which a record counts as constant [-]: 1024 machine epsilons of its
#: largest magnitude. Far below any acquisition's resolution (a 24-bit ADC resolves 6e-8 of its
#: range) and above the round-off of averaging and filtering a constant (a stuck sensor's 0.25 g
#: came out of the TSA varying by 2e-18 g, about 40 epsilons, and its kurtosis read 683).
CONSTANT_TOLERANCE = 1024 * float(np.finfo(np.float64).eps)


def is_constant(x) -> bool:
    """Whether ``x`` is constant to round-off: ``max|x - mean| <= CONSTANT_TOLERANCE * max|x|``
    (all zeros included). Its moment ratios (kurtosis, FM4, NA4...) would only measure the
    round-off, so geardyn reports them as NaN."""
    xa = np.asarray(x, dtype=np.float64)
    if xa.size == 0:
        return True
    big = float(np.max(np.abs(xa)))
    if big == 0.0:
        return True
    xs = xa / big  # |xs| <= 1: no overflow near the float limit
    return float(np.max(np.abs(xs - xs.mean()))) <= CONSTANT_TOLERANCE


def central_moment(x, order: int) -> float:
    """Biased central moment :math:`m_k = \\frac1N \\sum_n (x_n - \\bar x)^k` (unit u^k)."""
    xa = _as_float_array(x, "x", min_size=1)
    return float(np.mean((xa - xa.mean()) ** order))


def _deviation_scaled(x: np.ndarray) -> tuple[np.ndarray, float]:
    """``((x - mean) / s, s)`` with ``s = max|x - mean|``: moment ratios computed on the scaled
    deviation are exact and cannot overflow (|x| ~ 1e80 would overflow ``x**4``)."""
    big = float(np.max(np.abs(x))) if x.size else 0.0
    xs = x / big if big > 0 else x
    d = xs - xs.mean()
    s = float(np.max(np.abs(d)))
    return (d / s if s > 0 else d), s * big if big > 0 else s


def _normalised_moment(x: np.ndarray, order: int, name: str, warn: bool = True) -> float:
    z, _ = _deviation_scaled(x)
    m2 = float(np.mean(z * z))
    if not m2 > 0 or is_constant(x):
        if warn:
            warnings.warn(f"{name}: constant signal (zero variance, or a variation at the "
                          "round-off of its values); returning NaN",
                          DiagnosticsWarning, stacklevel=3)
        return math.nan
    return float(np.mean(z**order)) / m2 ** (order / 2)


def kurtosis(x, *, warn_constant: bool = True) -> float:
    """Pearson kurtosis :math:`m_4/m_2^2` [-] (Gaussian 3, sinusoid 1.5, square wave 1).

    The one kurtosis of geardyn (statistics, Table 3 kurtoses, sweeps). A constant record
    gives NaN, with a :class:`DiagnosticsWarning` unless ``warn_constant=False`` (for callers
    that report NaN themselves, e.g. the PM of a pure carrier).
    """
    return _normalised_moment(_as_float_array(x, "x", min_size=2), 4, "kurtosis",
                              warn=warn_constant)


@dataclass(frozen=True)
class SignalStatistics:
    """Statistics of a record (paper's Table 2 conventions).

    Attributes
    ----------
    mean : float
        Mean (unit u).
    std : float
        Standard deviation, ddof 0 (unit u).
    skewness : float
        Biased Fisher-Pearson skewness g1 [-].
    kurtosis : float
        Pearson kurtosis m4/m2^2 [-] (normal = 3).
    crest_factor : float
        max|x - mean| / std [-] (the paper's convention).
    crest_factor_rms : float
        max|x| / RMS [-] (peak-to-RMS convention).
    rms : float
        Root mean square including the mean (unit u).
    peak_to_peak : float
        max - min (unit u).
    n : int
        Number of samples [-].
    """

    mean: float
    std: float
    skewness: float
    kurtosis: float
    crest_factor: float
    crest_factor_rms: float
    rms: float
    peak_to_peak: float
    n: int

    def to_dict(self) -> dict:
        """Plain dict of the fields (NaN as None)."""
        return json_safe(asdict(self))


def signal_statistics(x) -> SignalStatistics:
    """Mean, STD (ddof 0), skewness g1, Pearson kurtosis, both crest factors, RMS, peak-to-peak.

    .. math::

        \\sigma = \\sqrt{m_2}, \\quad g_1 = \\frac{m_3}{m_2^{3/2}}, \\quad
        \\beta_2 = \\frac{m_4}{m_2^2}, \\quad CF = \\frac{\\max|x-\\mu|}{\\sigma}, \\quad
        CF_{rms} = \\frac{\\max|x|}{\\sqrt{\\overline{x^2}}}

    Parameters
    ----------
    x : array_like, shape (n,)
        The record (unit u), e.g. a one-revolution TSA.

    Returns
    -------
    SignalStatistics
        See the class for units. Constant input (:func:`is_constant`: zero variance, or a
        variation at the round-off of its values) gives NaN for the normalised statistics and
        a :class:`DiagnosticsWarning`.
    """
    xa = _as_float_array(x, "x", min_size=2)
    # everything on x / max|x| (then scaled back), so no power overflows for huge signals
    big = float(np.max(np.abs(xa)))
    xs = xa / big if big > 0 else xa
    scale = big if big > 0 else 1.0
    mu = float(xs.mean()) * scale
    z, _ = _deviation_scaled(xs)
    dmax = float(np.max(np.abs(xs - xs.mean())))
    m2z = float(np.mean(z * z))
    rms_s = float(np.sqrt(np.mean(xs * xs)))
    rms = rms_s * scale
    if m2z > 0 and not is_constant(xs):
        std = math.sqrt(m2z) * dmax * scale
        skew = float(np.mean(z**3)) / m2z**1.5
        kurt = kurtosis(xs, warn_constant=False)
        cf = 1.0 / math.sqrt(m2z)
    else:
        warnings.warn("signal_statistics: constant signal (zero variance, or a variation at the "
                      "round-off of its values); normalised statistics are NaN",
                      DiagnosticsWarning, stacklevel=2)
        # the STD as computed (0, or the round-off's), the ratios of round-off undefined
        std = math.sqrt(m2z) * dmax * scale
        skew, kurt, cf = math.nan, math.nan, math.nan
    cf_rms = float(np.max(np.abs(xs))) / rms_s if rms_s > 0 else math.nan
    return SignalStatistics(mean=mu, std=std, skewness=skew, kurtosis=kurt, crest_factor=cf,
                            crest_factor_rms=cf_rms, rms=rms,
                            peak_to_peak=float(xa.max() - xa.min()), n=int(xa.size))


# --------------------------------------------------------------------------------------------
# individual metrics
# --------------------------------------------------------------------------------------------
def fm0(x, *, teeth: int, mesh_harmonics: int | None = None) -> float:
    """FM0 = peak-to-peak of the TSA / sum of the mesh-harmonic peak amplitudes (Stewart 1977).

    .. math:: FM0 = \\frac{\\max x - \\min x}{\\sum_{m=1}^{M} A_{mZ}}, \\quad
        A_k = 2|X_k|/N \\; (k < N/2), \\; |X_k|/N \\; (k = N/2)

    Parameters
    ----------
    x : array_like, shape (N,)
        One-revolution TSA (unit u).
    teeth : int
        Z [-].
    mesh_harmonics : int, optional
        M, number of mesh harmonics summed; default all below Nyquist.

    Returns
    -------
    float
        FM0 [-]; 2 for a single mesh tone.
    """
    xa = _as_float_array(x, "x", min_size=4)
    n = xa.size
    ords = mesh_orders(teeth, n, harmonics=mesh_harmonics)
    if ords.size == 0:
        raise InputError("teeth", teeth, f"a tooth count with its mesh order <= N/2 = {n // 2}")
    amp = np.abs(sfft.rfft(xa)) / n
    amp[1:] *= 2.0
    if n % 2 == 0:
        amp[-1] /= 2.0
    total = float(amp[ords].sum())
    if not total > 0:
        warnings.warn("fm0: no energy at the mesh harmonics; returning NaN",
                      DiagnosticsWarning, stacklevel=2)
        return math.nan
    return float(xa.max() - xa.min()) / total


def fm4(d) -> float:
    """FM4 = m4(d)/m2(d)^2 of the difference signal d [-] (about 3 when healthy)."""
    return _normalised_moment(_as_float_array(d, "d", min_size=2), 4, "fm4")


def m6a(d) -> float:
    """M6A = m6(d)/m2(d)^3 of the difference signal [-] (Martin 1989; Gaussian 15)."""
    return _normalised_moment(_as_float_array(d, "d", min_size=2), 6, "m6a")


def m8a(d) -> float:
    """M8A = m8(d)/m2(d)^4 of the difference signal [-] (Martin 1989; Gaussian 105)."""
    return _normalised_moment(_as_float_array(d, "d", min_size=2), 8, "m8a")


def na4(r, history: Iterable = ()) -> float:
    """NA4 of the current residual with the residuals of earlier records of the run.

    .. math:: NA4 = \\frac{m_4(r_M)}{\\Bigl(\\frac1M \\sum_{i=1}^{M} m_2(r_i)\\Bigr)^2}

    where :math:`r_1 .. r_{M-1}` are ``history`` (oldest first) and :math:`r_M` = ``r``.

    Parameters
    ----------
    r : array_like, shape (N,)
        Residual of the current record (unit u).
    history : iterable of array_like
        Residuals of the previous records of the run (unit u). Empty: NA4 = kurtosis of r.

    Returns
    -------
    float
        NA4 [-].
    """
    ra = _as_float_array(r, "r", min_size=2)
    records = [_as_float_array(h, "history", min_size=2) for h in history] + [ra]
    # one common scale for every record: the ratio is unchanged and no power overflows
    s = max(float(np.max(np.abs(h - h.mean()))) for h in records)
    if not s > 0:
        warnings.warn("na4: zero residual variance; returning NaN", DiagnosticsWarning,
                      stacklevel=2)
        return math.nan
    m2s = [float(np.mean(((h - h.mean()) / s) ** 2)) for h in records]
    return float(np.mean(((ra - ra.mean()) / s) ** 4)) / float(np.mean(m2s)) ** 2


def na4_star(r, baseline_variance: float) -> float:
    """NA4* = m4(r) / v0^2 with a fixed healthy-baseline residual variance v0 (Decker 1994).

    Parameters
    ----------
    r : array_like, shape (N,)
        Current residual (unit u).
    baseline_variance : float
        v0, the variance m2 of the residual of the healthy gearbox (unit u^2).

    Returns
    -------
    float
        NA4* [-].
    """
    if not (np.isfinite(baseline_variance) and baseline_variance > 0):
        raise InputError("baseline_variance", baseline_variance, "a positive variance (u^2)")
    z, s = _deviation_scaled(_as_float_array(r, "r", min_size=2))
    if not s > 0:
        return 0.0
    v = float(baseline_variance) / s / s  # v0 in the scaled unit
    # divided by v twice: v**2 underflows to 0 for v < ~1e-162, the quotient overflows to inf
    return float(np.mean(z**4)) / v / v if v > 0 else math.inf


class NA4Tracker:
    """Running NA4 over the records of one run (the "record history" of Zakrajsek 1993).

    Each :meth:`update` takes the residual of the next record and returns NA4 with the mean
    residual variance of all records so far, :math:`m_4(r_M) / (\\overline{m_2})^2`.

    Examples
    --------
    >>> tr = NA4Tracker()
    >>> [round(tr.update(k / 3 * np.sin(10 * th)), 3) for k in range(1, 4)]  # doctest: +SKIP
    [1.5, 3.84, 5.579]
    """

    def __init__(self) -> None:
        self._m2: list[float] = []

    @property
    def n_records(self) -> int:
        """Number of records seen [-]."""
        return len(self._m2)

    @property
    def mean_variance(self) -> float:
        """Mean residual variance over the records seen (unit u^2)."""
        return float(np.mean(self._m2)) if self._m2 else math.nan

    def update(self, r) -> float:
        """Add the residual of the next record and return its NA4 [-]."""
        ra = _as_float_array(r, "r", min_size=2)
        self._m2.append(central_moment(ra, 2))
        den = self.mean_variance ** 2
        return central_moment(ra, 4) / den if den > 0 else math.nan


def band_envelope(x, *, teeth: int, harmonic: int = 1, bandwidth: int | None = None
                  ) -> np.ndarray:
    """Envelope |z| of the band ``h*Z +/- B`` of a TSA (analytic band signal, carrier kept).

    Parameters
    ----------
    x : array_like, shape (N,)
        One-revolution TSA (unit u).
    teeth : int
        Z [-].
    harmonic : int
        Mesh harmonic h [-] (default 1, the primary mesh frequency, as in Zakrajsek's NB4).
    bandwidth : int, optional
        B [orders]; default ``(Z - 1)//2``, the widest band not shared with the neighbouring
        harmonic.

    Returns
    -------
    ndarray
        Envelope (unit u).
    """
    b = (int(teeth) - 1) // 2 if bandwidth is None else bandwidth
    return np.abs(band_analytic_signal(x, teeth=teeth, harmonic=harmonic, bandwidth=max(1, b)))


def nb4(x, *, teeth: int, harmonic: int = 1, bandwidth: int | None = None,
        history: Iterable = ()) -> float:
    """NB4: NA4 of the band envelope (Zakrajsek 1993).

    .. math:: NB4 = \\frac{m_4(s_M)}{\\Bigl(\\frac1M\\sum_{i=1}^M m_2(s_i)\\Bigr)^2}, \\quad
        s = |z_{band}|

    Parameters
    ----------
    x : array_like, shape (N,)
        Current one-revolution TSA (unit u).
    teeth, harmonic, bandwidth
        See :func:`band_envelope`.
    history : iterable of array_like
        Envelopes of the previous records (unit u), oldest first.

    Returns
    -------
    float
        NB4 [-].
    """
    env = band_envelope(x, teeth=teeth, harmonic=harmonic, bandwidth=bandwidth)
    return na4(env, history)


def energy_ratio(d, y) -> float:
    """Energy ratio ER = RMS(d) / RMS(y) (Swansson 1980) [-].

    Parameters
    ----------
    d : array_like
        Difference signal (unit u).
    y : array_like
        Regular signal (unit u), zero mean.

    Returns
    -------
    float
        ER [-]; for Gaussian d of STD sigma and a sinusoid y of amplitude A, sigma/(A/sqrt 2).
    """
    da = _as_float_array(d, "d", min_size=1)
    ya = _as_float_array(y, "y", min_size=1)
    ry = float(np.sqrt(np.mean(ya * ya)))
    if not ry > 0:
        warnings.warn("energy_ratio: zero regular signal; returning NaN", DiagnosticsWarning,
                      stacklevel=2)
        return math.nan
    return float(np.sqrt(np.mean(da * da))) / ry


# --------------------------------------------------------------------------------------------
# all of them
# --------------------------------------------------------------------------------------------
@dataclass(frozen=True)
class ConditionMetrics:
    """Gear condition metrics of one TSA, with MATLAB ``gearConditionMetrics`` column names.

    Attributes
    ----------
    RMS : float
        RMS of the TSA including its mean (unit u).
    Kurtosis : float
        Pearson kurtosis of the TSA [-].
    CrestFactor : float
        max|x| / RMS(x) of the TSA [-] (MATLAB's peak-to-RMS convention; the paper's
        max|x - mean|/std is :attr:`SignalStatistics.crest_factor`).
    FM4 : float
        Kurtosis of the difference signal [-].
    M6A : float
        Sixth normalised moment of the difference signal [-].
    M8A : float
        Eighth normalised moment of the difference signal [-].
    FM0 : float
        Peak-to-peak / sum of mesh harmonic amplitudes [-].
    EnergyRatio : float
        RMS(difference) / RMS(regular) [-].
    NA4 : float
        NA4 with the given residual history [-].
    NA4star : float
        NA4* with the given healthy-baseline variance [-]; NaN when none was given.
    NB4 : float
        NB4 with the given envelope history [-].
    """

    RMS: float
    Kurtosis: float
    CrestFactor: float
    FM4: float
    M6A: float
    M8A: float
    FM0: float
    EnergyRatio: float
    NA4: float
    NA4star: float
    NB4: float

    def to_dict(self) -> dict:
        """Plain dict keyed by the MATLAB column names (NaN as None, JSON-safe)."""
        return json_safe(asdict(self))


def condition_metrics(
    x,
    *,
    teeth: int,
    shaft_harmonics: int = 2,
    mesh_harmonics: int | None = None,
    sidebands: int = 1,
    residual_preset: str = "zakrajsek",
    residual_history: Sequence = (),
    na4_baseline_variance: float | None = None,
    nb4_harmonic: int = 1,
    nb4_bandwidth: int | None = None,
    nb4_history: Sequence = (),
) -> ConditionMetrics:
    """All condition metrics of a one-revolution TSA.

    The regular signal y keeps DC-free shaft orders 1..S and the mesh harmonics; the difference
    d removes those, the mean and B sidebands (``sidebands``, default 1); the residual r follows
    ``residual_preset`` (:func:`geardyn.diagnostics.residual`).

    Parameters
    ----------
    x : array_like, shape (N,)
        One-revolution TSA (unit u).
    teeth : int
        Z, teeth of the gear on the averaged shaft [-].
    shaft_harmonics : int
        S [-] (regular / difference signals).
    mesh_harmonics : int, optional
        M [-]; default all below Nyquist (regular, difference, FM0).
    sidebands : int
        First-order (B = 1) sidebands removed in the difference signal [-].
    residual_preset : str
        Preset of the NA4 residual ("zakrajsek" default, "paper", "matlab").
    residual_history : sequence of array_like
        Residuals of the earlier records of the run (unit u) for NA4.
    na4_baseline_variance : float, optional
        Healthy residual variance (unit u^2) for NA4*; None gives NaN.
    nb4_harmonic : int
        Mesh harmonic of the NB4 band [-].
    nb4_bandwidth : int, optional
        Half-width of the NB4 band [orders]; default (Z-1)//2.
    nb4_history : sequence of array_like
        Envelopes of earlier records (unit u) for NB4.

    Returns
    -------
    ConditionMetrics
        The metrics, named as MATLAB's ``gearConditionMetrics`` columns (+ NA4star, NB4).
    """
    xa = _as_float_array(x, "x", min_size=8)
    z = _check_int(teeth, "teeth", 1, "a positive integer number of teeth")
    if is_constant(xa):
        # its difference, residual and envelope are round-off, whose moment ratios are any
        # number (683 for a stuck sensor's 0.25 g): none of the metrics is defined
        rms = float(np.sqrt(np.mean(xa * xa)))
        warnings.warn(f"condition metrics: the TSA is constant (to round-off: varies by "
                      f"{float(np.ptp(xa)):.3g} about {float(xa.mean()):.6g}); every metric but "
                      "RMS and CrestFactor is NaN", DiagnosticsWarning, stacklevel=2)
        return ConditionMetrics(
            RMS=rms, Kurtosis=math.nan,
            CrestFactor=float(np.max(np.abs(xa))) / rms if rms > 0 else math.nan,
            FM4=math.nan, M6A=math.nan, M8A=math.nan, FM0=math.nan, EnergyRatio=math.nan,
            NA4=math.nan, NA4star=math.nan, NB4=math.nan)
    y = regular(xa, teeth=z, shaft_harmonics=shaft_harmonics, mesh_harmonics=mesh_harmonics,
                sidebands=0, include_dc=False)
    d = difference(xa, teeth=z, shaft_harmonics=shaft_harmonics, mesh_harmonics=mesh_harmonics,
                   sidebands=sidebands)
    r = residual(xa, teeth=z, preset=residual_preset)
    rms = float(np.sqrt(np.mean(xa * xa)))
    return ConditionMetrics(
        RMS=rms,
        Kurtosis=kurtosis(xa),
        CrestFactor=float(np.max(np.abs(xa))) / rms if rms > 0 else math.nan,
        FM4=fm4(d),
        M6A=m6a(d),
        M8A=m8a(d),
        FM0=fm0(xa, teeth=z, mesh_harmonics=mesh_harmonics),
        EnergyRatio=energy_ratio(d, y),
        NA4=na4(r, residual_history),
        NA4star=(math.nan if na4_baseline_variance is None
                 else na4_star(r, na4_baseline_variance)),
        NB4=nb4(xa, teeth=z, harmonic=nb4_harmonic, bandwidth=nb4_bandwidth,
                history=nb4_history),
    )


