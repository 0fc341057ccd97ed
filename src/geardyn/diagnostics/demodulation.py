"""Narrowband amplitude and phase demodulation about a mesh harmonic (McFadden 1986).

The TSA ``x`` of one revolution (N samples) is transformed, the bins of the band
``K - B .. K + B`` about the carrier order ``K = h * Z`` (mesh harmonic h of a Z-tooth gear) are
kept, doubled, all other bins (including the negative orders) zeroed, and the inverse transform
is the analytic band signal

.. math:: z(\\theta_n) = \\frac{1}{N} \\sum_{k=K-B}^{K+B} 2 X_k e^{2\\pi i k n / N}
    = a(\\theta_n)\\, e^{i(K\\theta_n + \\phi(\\theta_n))}.

Its modulus is the amplitude modulation (the envelope of the band), and the phase modulation is
the phase of the baseband signal :math:`b = z e^{-iK\\theta}`:

.. math:: a = |z|, \\qquad \\phi = \\operatorname{unwrap}(\\arg b) = \\operatorname{unwrap}(\\arg z)
    - K\\theta \\pmod{2\\pi}.

The carrier phase is kept by default (the paper's PM "stays around 40 deg"); ``remove_mean_phase``
subtracts the mean of :math:`\\phi`. The **narrowband envelope** is by default the envelope of
the band *without* the carrier bin K (McFadden's narrowband envelope; the paper's envelope and
AM kurtoses, 14.65 vs 14.25, differ in this way); ``envelope_excludes_carrier=False`` makes it
equal to the AM.

References
----------
McFadden, P. D. (1986). Detecting fatigue cracks in gears by amplitude and phase demodulation of
the meshing vibration. J. Vib. Acoust. Stress Reliab. Des., 108(2), 165-170.

McFadden, P. D., Smith, J. D. (1985). A signal processing technique for detecting local defects
in a gear from the signal average of the vibration. Proc. Inst. Mech. Eng. C, 199(4), 287-292.

Xue, S., Howard, I. Dynamic modelling of flexibly supported gears using iterative convergence
of tooth mesh stiffness (section 4.2).
"""

from __future__ import annotations

import warnings
from dataclasses import dataclass

import numpy as np
from scipy import fft as sfft

from geardyn.errors import InputError

from .tsa import DiagnosticsWarning, _as_float_array, _check_int

__all__ = ["DemodulationResult", "narrowband_demodulation", "band_limits", "band_analytic_signal"]


@dataclass(frozen=True)
class DemodulationResult:
    """Result of :func:`narrowband_demodulation`.

    Attributes
    ----------
    angle : ndarray, shape (N,)
        Shaft angle of each sample [rad].
    analytic : ndarray of complex, shape (N,)
        Analytic band signal z (unit of the input).
    baseband : ndarray of complex, shape (N,)
        :math:`z e^{-iK\\theta}`: radius = AM, angle = PM (unit of the input).
    am : ndarray, shape (N,)
        Amplitude modulation :math:`|z|` (unit of the input).
    am_relative : ndarray, shape (N,)
        :math:`|z| / \\overline{|z|} - 1` [-].
    pm : ndarray, shape (N,)
        Phase modulation [rad] (carrier phase kept unless ``remove_mean_phase``).
    envelope : ndarray, shape (N,)
        Narrowband envelope (unit of the input): the band envelope without the carrier bin when
        ``envelope_excludes_carrier`` else equal to ``am``.
    carrier_order : int
        K = harmonic * teeth [-].
    bandwidth : int
        B, half-width of the band [orders].
    harmonic : int
        Mesh harmonic h [-].
    teeth : int
        Z [-].
    envelope_excludes_carrier : bool
        How ``envelope`` was formed.
    mean_phase_removed : bool
        Whether the mean PM was subtracted.
    """

    angle: np.ndarray
    analytic: np.ndarray
    baseband: np.ndarray
    am: np.ndarray
    am_relative: np.ndarray
    pm: np.ndarray
    envelope: np.ndarray
    carrier_order: int
    bandwidth: int
    harmonic: int
    teeth: int
    envelope_excludes_carrier: bool
    mean_phase_removed: bool

    @property
    def pm_deg(self) -> np.ndarray:
        """Phase modulation [deg]."""
        return np.degrees(self.pm)

    @property
    def band(self) -> tuple[int, int]:
        """Lowest and highest order of the band [-]."""
        return (self.carrier_order - self.bandwidth, self.carrier_order + self.bandwidth)


def band_limits(teeth: int, harmonic: int, bandwidth: int, samples_per_rev: int) -> tuple[int, int]:
    """Check a demodulation band and return its lowest and highest order.

    Rules (Z teeth, h harmonic, K = h*Z, B bandwidth, N samples per revolution):

    * error if ``K + B > N/2 - 1`` (the band must lie strictly below the Nyquist order) or
      ``K - B < 1`` (it must not reach the mean);
    * error if ``B >= Z``: the band would contain the neighbouring mesh harmonic ``(h +/- 1) Z``
      itself;
    * :class:`DiagnosticsWarning` if ``2B >= Z`` (i.e. ``B > (Z - 1)/2``): the band shares orders
      with the equally wide band of the neighbouring harmonic, so sidebands of two harmonics
      are mixed. B = 11 for Z = 23 (the paper) is the widest band without sharing.

    Returns
    -------
    tuple of int
        ``(K - B, K + B)`` [orders].
    """
    z = _check_int(teeth, "teeth", 1, "a positive integer number of teeth")
    h = _check_int(harmonic, "harmonic", 1, "a mesh harmonic number >= 1")
    b = _check_int(bandwidth, "bandwidth", 1, "a half-bandwidth >= 1 order")
    n = int(samples_per_rev)
    k = h * z
    if k + b > n // 2 - 1 or k - b < 1:
        raise InputError(
            "bandwidth", b,
            f"a band {k}+/-B (mesh harmonic {h} x {z} teeth) inside orders 1..{n // 2 - 1} "
            f"(Nyquist is {n // 2} orders for {n} samples per revolution); use a lower "
            "harmonic, smaller band or more samples (or check the tooth count)",
        )
    if b >= z:
        raise InputError(
            "bandwidth", b,
            f"less than the tooth count {z}: the band {k - b}..{k + b} would contain the "
            f"neighbouring mesh harmonic ({(h - 1) * z} or {(h + 1) * z})",
        )
    if 2 * b >= z:
        warnings.warn(
            f"demodulation band {k}+/-{b} overlaps the band of the neighbouring mesh harmonic "
            f"(2B >= Z = {z}); sidebands of two harmonics are mixed. B <= {(z - 1) // 2} avoids "
            "this.",
            DiagnosticsWarning,
            stacklevel=3,
        )
    return k - b, k + b


def _band_spectrum(xa: np.ndarray, lo: int, hi: int) -> np.ndarray:
    """Spectrum of the analytic band signal: ``2 X_k`` for ``lo <= k <= hi``, zero elsewhere."""
    spec = sfft.fft(xa)
    band = np.zeros(xa.shape[0], dtype=np.complex128)
    band[lo: hi + 1] = 2.0 * spec[lo: hi + 1]
    return band


def band_analytic_signal(x, *, teeth: int, harmonic: int, bandwidth: int) -> np.ndarray:
    """Analytic signal of the band ``K - B .. K + B`` of a one-revolution TSA (K = h Z).

    .. math:: z_n = \\frac1N \\sum_{k=K-B}^{K+B} 2X_k e^{2\\pi i kn/N}

    The same band signal as :func:`narrowband_demodulation` (whose ``analytic`` it equals);
    its modulus is the band envelope of NB4 (:func:`geardyn.diagnostics.band_envelope`).

    Parameters
    ----------
    x : array_like, shape (N,)
        One-revolution TSA (unit u).
    teeth, harmonic, bandwidth : int
        Z [-], h [-] and B [orders]; checked by :func:`band_limits`.

    Returns
    -------
    ndarray of complex, shape (N,)
        z (unit u).
    """
    xa = _as_float_array(x, "x", min_size=8)
    lo, hi = band_limits(teeth, harmonic, bandwidth, xa.shape[0])
    return sfft.ifft(_band_spectrum(xa, lo, hi))


def narrowband_demodulation(x, *, teeth: int, harmonic: int = 5, bandwidth: int = 11,
                            remove_mean_phase: bool = False,
                            envelope_excludes_carrier: bool = True) -> DemodulationResult:
    """Amplitude and phase demodulation of a TSA about a mesh harmonic (McFadden 1986).

    .. math::

        z_n = \\frac1N \\sum_{k=K-B}^{K+B} 2X_k e^{2\\pi i kn/N}, \\quad
        a_n = |z_n|, \\quad \\phi_n = \\operatorname{unwrap}\\arg(z_n e^{-iK\\theta_n})

    Parameters
    ----------
    x : array_like, shape (N,)
        One-revolution TSA (unit u), N samples per revolution.
    teeth : int
        Z, teeth of the gear on the averaged shaft [-] (paper: 23).
    harmonic : int
        Mesh harmonic h used as carrier, K = h*Z [-] (paper: 5, K = 115).
    bandwidth : int
        B, half-width of the band [orders] (paper: 11, i.e. 22 orders). See
        :func:`band_limits` for the checks.
    remove_mean_phase : bool
        Subtract the mean of the phase modulation (default keeps the carrier phase).
    envelope_excludes_carrier : bool
        Form the narrowband envelope without the carrier bin K (default) or equal to the AM.

    Returns
    -------
    DemodulationResult
        Analytic and baseband signals and AM [u], relative AM [-], PM [rad], envelope [u].

    Raises
    ------
    InputError
        Band beyond Nyquist, touching the mean, or containing the neighbouring harmonic.
    """
    xa = _as_float_array(x, "x", min_size=8)
    n = xa.shape[0]
    lo, hi = band_limits(teeth, harmonic, bandwidth, n)
    k = int(harmonic) * int(teeth)
    band = _band_spectrum(xa, lo, hi)
    z = sfft.ifft(band)
    theta = 2.0 * np.pi * np.arange(n) / n
    # exact baseband: shift the band down by K bins (equal to z*exp(-iK theta) up to rounding)
    base_spec = np.zeros(n, dtype=np.complex128)
    base_spec[np.arange(lo, hi + 1) - k] = band[lo: hi + 1]
    baseband = sfft.ifft(base_spec)
    am = np.abs(z)
    mean_am = am.mean()
    am_rel = am / mean_am - 1.0 if mean_am > 0 else np.zeros_like(am)
    pm = np.unwrap(np.angle(baseband))
    # np.unwrap starts from arg(b_0) in (-pi, pi]: the carrier phase is kept
    if remove_mean_phase:
        pm = pm - pm.mean()
    if envelope_excludes_carrier:
        band_nc = band.copy()
        band_nc[k] = 0.0
        envelope = np.abs(sfft.ifft(band_nc))
    else:
        envelope = am.copy()
    return DemodulationResult(
        angle=theta, analytic=z, baseband=baseband, am=am, am_relative=am_rel, pm=pm,
        envelope=envelope, carrier_order=k, bandwidth=int(bandwidth), harmonic=int(harmonic),
        teeth=int(teeth), envelope_excludes_carrier=bool(envelope_excludes_carrier),
        mean_phase_removed=bool(remove_mean_phase),
    )
