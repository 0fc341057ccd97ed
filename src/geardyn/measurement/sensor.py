r"""The sensor and the data acquisition: accelerometer, anti-alias filter, sampling, noise, ADC.

Plain functions, each usable alone on any signal, and :class:`Sensor`, which holds one
configuration. The linear parts (transfer path, accelerometer, anti-alias filter) are applied
together in the frequency domain on the simulation's time grid by :func:`apply_frf`; the result is
then sampled at ``fs`` by :func:`sample_at` (exact sampling of the band-limited interpolant, with
aliasing), noise is added (:func:`add_noise`) and the ADC quantises and clips (:func:`quantise`).

Models
------
Accelerometer (seismic, base-excited single-degree-of-freedom sensor; output proportional to the
relative displacement of its seismic mass, calibrated to 1 at low frequency):

.. math:: H_{acc}(\omega) = \frac{\omega_n^2}{\omega_n^2 - \omega^2 + 2 j \zeta_n \omega_n \omega}

(derived here from ``z'' + 2 zeta w_n z' + w_n^2 z = -a_base``, output ``-w_n^2 z``).

Anti-alias filter: the magnitude of an n-th order Butterworth low-pass,
``|H| = 1 / sqrt(1 + (f/f_c)^(2n))``, with zero phase. This stands for a DAQ whose decimation
filter is linear-phase and whose constant delay is removed by the acquisition software, so all
channels (acceleration and tachometer) stay aligned in time. It is an assumption of geardyn, not
the model of a particular instrument; an analog filter with phase is not modelled.

Noise: white Gaussian, added after sampling, either at a level (RMS [m/s^2]) or at a stated
signal-to-noise ratio ``SNR = 10 log10(P_signal / P_noise)`` [dB] with ``P_signal`` the variance
(AC power) of the noise-free sampled channel.

ADC: mid-tread quantiser with ``bits`` bits over ``[-full_scale, full_scale)``: step
``q = 2 full_scale / 2^bits``, codes ``round(x/q)`` limited to ``[-2^(bits-1), 2^(bits-1) - 1]``;
limited samples are *clipped* and counted.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from ..errors import InputError
from .transfer import SETTLING_DECAYS

__all__ = ["Sensor", "accelerometer_frf", "antialias_gain", "apply_frf", "sample_at",
           "add_noise", "noise_rms_for_snr", "quantise", "snr_db"]

G_N = 9.80665
"""Standard gravity [m/s^2] (CGPM 1901), for outputs in g."""


def accelerometer_frf(f, resonance: float, damping_ratio: float) -> np.ndarray:
    """Accelerometer response ``w_n^2 / (w_n^2 - w^2 + 2 j zeta w_n w)`` [-] at ``f`` [Hz]."""
    w = 2.0 * np.pi * np.asarray(f, dtype=float)
    wn = 2.0 * np.pi * resonance
    return wn * wn / (wn * wn - w * w + 2j * damping_ratio * wn * w)


def antialias_gain(f, cutoff: float, order: int) -> np.ndarray:
    """Zero-phase Butterworth magnitude ``1 / sqrt(1 + (f/f_c)^(2 order))`` [-] at ``f`` [Hz]."""
    r = np.abs(np.asarray(f, dtype=float)) / cutoff
    return 1.0 / np.sqrt(1.0 + r ** (2 * order))


def apply_frf(x, fs: float, frf) -> np.ndarray:
    """Filter real signals with FRFs in the frequency domain and sum them (circular).

    Parameters
    ----------
    x : array_like, shape (n_inputs, n)
        Input signals sampled at ``fs`` (e.g. bearing forces [N]).
    fs : float
        Sample rate [Hz].
    frf : callable
        ``frf(f)`` -> complex array of shape ``(n_inputs, len(f))`` at ``f >= 0`` [Hz].

    Returns
    -------
    ndarray of complex, shape (n // 2 + 1,)
        The one-sided spectrum ``sum_b H_b X_b`` (``numpy.fft.rfft`` convention). The
        convolution is circular: the start of the output holds the wrapped end of the input
        for as long as the filters' memory; callers discard that lead-in.
    """
    x = np.atleast_2d(np.asarray(x, dtype=float))
    n = x.shape[1]
    f = np.fft.rfftfreq(n, 1.0 / fs)
    h = np.atleast_2d(frf(f))
    if h.shape != (x.shape[0], f.size):
        raise InputError("frf", f"shape {h.shape}", f"shape ({x.shape[0]}, {f.size})")
    return np.einsum("bk,bk->k", h, np.fft.rfft(x, axis=1))


def sample_at(spectrum, n: int, n_out: int) -> np.ndarray:
    r"""Sample the periodic band-limited interpolant of a signal at ``n_out`` equal steps.

    The signal of length ``n`` (one-sided spectrum ``spectrum``, :func:`numpy.fft.rfft` of it)
    is the trigonometric interpolant ``x(t) = (1/n) sum_k X_k exp(2 pi j k t / T)`` over its
    period ``T``; sampled at ``t_j = j T / n_out`` its spectrum is folded modulo ``n_out``
    (aliasing included). ``n_out = n`` returns the signal; ``n_out = n / r`` with an integer
    ``r`` equals taking every r-th sample.

    Returns
    -------
    ndarray, shape (n_out,)
    """
    spec = np.asarray(spectrum, dtype=complex)
    k = np.arange(spec.size)
    if n % n_out == 0:  # plain decimation: every r-th sample of the signal
        return np.fft.irfft(spec, n)[::n // n_out].copy()
    # signed frequencies: X_k at +k and conj(X_k) at -k; the Nyquist bin (n even) is split
    w = np.ones(spec.size)
    neg = (k > 0) & ~((n % 2 == 0) & (k == n // 2))
    nyq = (n % 2 == 0) & (k == n // 2)
    w[nyq] = 0.5
    idx_pos = k % n_out
    idx_neg = (-k[neg | nyq]) % n_out
    vals_neg = np.conj(spec[neg | nyq]) * w[neg | nyq]
    vals_pos = spec * w
    z = (np.bincount(idx_pos, vals_pos.real, n_out) + np.bincount(idx_neg, vals_neg.real, n_out)
         + 1j * (np.bincount(idx_pos, vals_pos.imag, n_out)
                 + np.bincount(idx_neg, vals_neg.imag, n_out)))
    return np.fft.ifft(z).real * (n_out / n)


def noise_rms_for_snr(x, snr: float) -> float:
    """Noise RMS giving ``snr`` dB over the variance of ``x`` (unit of ``x``)."""
    x = np.asarray(x, dtype=float)
    if snr == math.inf:
        return 0.0
    return math.sqrt(float(np.var(x)) / 10.0 ** (snr / 10.0))


def snr_db(signal, noise) -> float:
    """``10 log10(var(signal) / var(noise))`` [dB]."""
    return 10.0 * math.log10(float(np.var(signal)) / float(np.var(noise)))


def add_noise(x, rms: float, rng: np.random.Generator) -> np.ndarray:
    """``x`` plus white Gaussian noise of standard deviation ``rms`` (unit of ``x``)."""
    x = np.asarray(x, dtype=float)
    if rms == 0.0:
        return x.copy()
    return x + rms * rng.standard_normal(x.shape)


def quantise(x, bits: int, full_scale: float) -> tuple[np.ndarray, np.ndarray]:
    """Mid-tread ADC: returns the quantised values (unit of ``x``) and a clipped-sample mask."""
    q = 2.0 * full_scale / 2.0 ** bits
    codes = np.rint(np.asarray(x, dtype=float) / q)
    lo, hi = -(2.0 ** (bits - 1)), 2.0 ** (bits - 1) - 1
    clipped = (codes < lo) | (codes > hi)
    return np.clip(codes, lo, hi) * q, clipped


@dataclass(frozen=True)
class Sensor:
    """Accelerometer and data acquisition settings (SI).

    Attributes
    ----------
    fs : float
        Sample rate [Hz].
    resonance : float or None
        Mounted resonance of the accelerometer [Hz]; ``None``: ideal (flat) sensor.
    resonance_damping : float
        Its damping ratio [-].
    antialias_cutoff : float or None
        Anti-alias filter cutoff (-3 dB) [Hz], below ``fs / 2``; ``None``: no filter.
    antialias_order : int
        Butterworth order of the anti-alias magnitude [-].
    adc_bits : int or None
        ADC resolution [bits]; ``None``: no quantisation.
    adc_full_scale : float
        ADC range ``+/- full_scale`` [m/s^2].
    snr : float or None
        Signal-to-noise ratio [dB], >= 0 (``inf``: no noise).
    noise_level : float or None
        Noise RMS [m/s^2] (instead of ``snr``).
    """

    fs: float = 50_000.0
    resonance: float | None = None
    resonance_damping: float = 0.02
    antialias_cutoff: float | None = None
    antialias_order: int = 8
    adc_bits: int | None = None
    adc_full_scale: float = 50.0 * G_N
    snr: float | None = None
    noise_level: float | None = None

    def __post_init__(self) -> None:
        f = "measurement."
        if not (math.isfinite(self.fs) and self.fs > 0):
            raise InputError(f + "fs", self.fs, "a positive sample rate in Hz")
        if self.resonance is not None and not (math.isfinite(self.resonance)
                                               and self.resonance > 0):
            raise InputError(f + "accelerometer_resonance", self.resonance,
                             "a positive frequency in Hz, or omit it for an ideal sensor")
        if not 0.0 < self.resonance_damping < 1.0:
            raise InputError(f + "accelerometer_damping_ratio", self.resonance_damping,
                             "a damping ratio in (0, 1)")
        if self.antialias_cutoff is not None and not 0.0 < self.antialias_cutoff < self.fs / 2:
            raise InputError(f + "antialias_cutoff", self.antialias_cutoff,
                             f"a cutoff in Hz below fs / 2 = {self.fs / 2:.6g} Hz")
        if not 1 <= int(self.antialias_order) <= 64:
            raise InputError(f + "antialias_order", self.antialias_order, "an order in 1..64")
        if self.adc_bits is not None and not 2 <= int(self.adc_bits) <= 32:
            raise InputError(f + "adc_bits", self.adc_bits, "a resolution of 2..32 bits")
        if not (math.isfinite(self.adc_full_scale) and self.adc_full_scale > 0):
            raise InputError(f + "adc_range", self.adc_full_scale, "a positive range in m/s^2")
        if self.snr is not None and self.snr != math.inf and self.noise_level is not None:
            raise InputError(f + "snr", self.snr, "either snr (dB) or noise_level (m/s^2), "
                                                  "not both: set snr = inf to use noise_level")
        if self.snr is not None and not self.snr >= 0:  # inf: no noise; NaN refused
            raise InputError(f + "snr", self.snr,
                             "an SNR in dB >= 0, 10 log10 of the signal power over the noise "
                             "power (a negative SNR would make the noise stronger than the "
                             "signal; to model that, give measurement.noise_level in m/s^2)")
        if self.noise_level is not None and not (math.isfinite(self.noise_level)
                                                 and self.noise_level >= 0):
            raise InputError(f + "noise_level", self.noise_level, "a noise RMS >= 0 in m/s^2")

    def frf(self, f) -> np.ndarray:
        """Accelerometer times anti-alias response [-] at ``f`` [Hz]."""
        h = np.ones(np.shape(f), dtype=complex)
        if self.resonance is not None:
            h = h * accelerometer_frf(f, self.resonance, self.resonance_damping)
        if self.antialias_cutoff is not None:
            h = h * antialias_gain(f, self.antialias_cutoff, self.antialias_order)
        return h

    def settling_time(self) -> float:
        """Memory of the accelerometer and the filter (1e-8 decay) [s]."""
        t = 0.0
        if self.resonance is not None:
            t = max(t, SETTLING_DECAYS / (self.resonance_damping * 2 * math.pi * self.resonance))
        if self.antialias_cutoff is not None:
            t = max(t, self.antialias_tail())
        return t

    def antialias_tail(self) -> float:
        """Half-length of the zero-phase anti-alias impulse response (1e-8 decay) [s]: the least
        damped Butterworth pole has damping ratio sin(pi / (2 order))."""
        if self.antialias_cutoff is None:
            return 0.0
        zeta = math.sin(math.pi / (2 * self.antialias_order))
        return SETTLING_DECAYS / (zeta * 2 * math.pi * self.antialias_cutoff)
