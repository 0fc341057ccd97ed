r"""The whole measurement chain: bearing forces and shaft angle in, DAQ channels out.

:class:`MeasurementChain` composes the transfer path (:mod:`.transfer`), the sensor and DAQ
(:mod:`.sensor`) and the tachometer (:mod:`.tach`). :meth:`MeasurementChain.measure` takes
arrays on the simulation's uniform time grid and never runs the dynamics.

Order of operations (each step documented in its module):

1. ``Y(f) = H_acc(f) H_aa(f) sum_b A_b(f) F_b(f)`` on the simulation grid (one real FFT per
   force, so the input is treated as periodic). To keep the wrap-around out of the record, the
   forces' fluctuation about their mean is tapered to zero over the chain's memory at both
   ends (half Hann windows; the mean passes with the DC response) and zero-padded to a fast
   FFT length, and the first and last
   ``2 memory()`` seconds (taper plus decay) are discarded: the record starts
   :meth:`~MeasurementChain.lead_in` after the input;
2. sampling at ``fs`` (exact sampling of the band-limited interpolant, aliasing included);
3. additive white Gaussian noise (level or SNR) from a seeded generator;
4. ADC quantisation and clipping;
5. the tachometer: pulse times from the shaft angle, trigger jitter (second seeded stream), the
   sampled pulse train at the same instants.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from fractions import Fraction

import numpy as np

from ..errors import InputError
from .sensor import Sensor, add_noise, apply_frf, noise_rms_for_snr, quantise, sample_at
from .tach import Tachometer, pulse_times, pulse_train
from .transfer import FRFTable, ModalPath

__all__ = ["MeasurementChain", "Measured", "bearing_forces"]


def bearing_forces(y, v, stiffness: float, damping: float) -> np.ndarray:
    r"""Force a bearing transmits to the housing [N] from the gear centre's motion.

    The bearing term of the paper's eqs. 10 and 12, ``m y'' = ... - k_y y - q_y y'``, is the
    force of the bearing on the gear; the housing takes the reaction

    .. math:: F = k_y y + q_y \dot y.

    Parameters
    ----------
    y : array_like
        Gear centre displacement along the line of action [m].
    v : array_like
        Its velocity [m/s].
    stiffness : float
        ``k_y`` [N/m].
    damping : float
        ``q_y`` [N s/m].
    """
    return stiffness * np.asarray(y, dtype=float) + damping * np.asarray(v, dtype=float)


@dataclass
class Measured:
    """What :meth:`MeasurementChain.measure` returns (arrays, SI).

    Attributes
    ----------
    fs : float
        Sample rate [Hz].
    start_time : float
        Input time of sample 0 [s].
    acc : ndarray
        Recorded acceleration [m/s^2] (noise and ADC included).
    acc_clean : ndarray
        The same before noise and ADC [m/s^2].
    noise : ndarray
        The noise added [m/s^2].
    tach : ndarray
        Recorded tachometer channel [V].
    pulse_times : ndarray
        Pulse times including jitter, relative to sample 0 [s].
    noise_rms : float
        Standard deviation of the noise requested [m/s^2].
    clipped : int
        Samples the ADC clipped.
    info : dict
        Settings and derived figures for the record attributes.
    """

    fs: float
    start_time: float
    acc: np.ndarray
    acc_clean: np.ndarray
    noise: np.ndarray
    tach: np.ndarray
    pulse_times: np.ndarray
    noise_rms: float
    clipped: int
    info: dict = field(default_factory=dict)

    @property
    def time(self) -> np.ndarray:
        """Sample times from 0 [s]."""
        return np.arange(self.acc.size) / self.fs


@dataclass(frozen=True)
class MeasurementChain:
    """Transfer path, sensor/DAQ and tachometer.

    Attributes
    ----------
    path : ModalPath or FRFTable
        Bearing forces -> acceleration at the sensor.
    sensor : Sensor
    tach : Tachometer
    seed : int
        Seed of the noise and jitter generators (``numpy.random.SeedSequence(seed).spawn(2)``).
    """

    path: ModalPath | FRFTable
    sensor: Sensor = field(default_factory=Sensor)
    tach: Tachometer = field(default_factory=Tachometer)
    seed: int = 0

    def __post_init__(self) -> None:
        top = self.path.highest_frequency
        if isinstance(self.path, ModalPath) and not self.sensor.fs > 2.0 * top:
            raise InputError("measurement.fs", self.sensor.fs,
                             f"a sample rate above twice the highest transfer-path mode "
                             f"(2 x {top:.6g} Hz = {2 * top:.6g} Hz)")

    def memory(self) -> float:
        """How long the chain remembers its input (1e-8 decay of the slowest part) [s]."""
        return self.path.settling_time() + self.sensor.settling_time()

    def lead_in(self) -> float:
        """Input time consumed before the first output sample [s]: ``2 memory()``. The input is
        tapered to its mean over the first ``memory()`` (a half Hann window, so that its
        periodic extension has no jump that would ring through the FFT), then the chain
        forgets the taper during the second."""
        return 2.0 * self.memory()

    def tail(self) -> float:
        """Input time consumed after the last output sample [s]: ``2 memory()``, the taper at
        the end and the zero-phase filter's reach back from it."""
        return 2.0 * self.memory()

    def is_static(self) -> bool:
        """Whether the chain is frequency independent (rigid-body modes only, flat sensor, no
        anti-alias filter): then it is applied sample by sample, without an FFT."""
        return (isinstance(self.path, ModalPath) and self.path.highest_frequency == 0.0
                and self.sensor.resonance is None and self.sensor.antialias_cutoff is None)

    def _filtered(self, x: np.ndarray, n: int, p: int, q: int, fs_in: float) -> np.ndarray:
        """Transfer path, accelerometer and filter on ``x[:, :n]``, sampled at ``p/q`` of the
        input rate (module docstring, step 1-2)."""
        from scipy.fft import next_fast_len

        def frf(f):
            return self.path.frf(f) * self.sensor.frf(f)[None, :]

        # the force fluctuation about its mean, tapered over the chain's memory at both ends,
        # then zero-padded to a fast FFT length that keeps n_pad * p / q whole
        n_pad = q * next_fast_len(n // q, real=True)
        mean = x[:, :n].mean(axis=1)
        fluct = np.zeros((x.shape[0], n_pad))
        fluct[:, :n] = x[:, :n] - mean[:, None]
        mem = min(int(math.ceil(self.memory() * fs_in)), n // 2)
        if mem > 0:
            ramp = 0.5 - 0.5 * np.cos(np.pi * np.arange(mem) / mem)
            fluct[:, :mem] *= ramp
            fluct[:, n - mem:n] *= ramp[::-1]
        spec = apply_frf(fluct, fs_in, frf)
        dc = float(np.sum(frf(np.zeros(1))[:, 0].real * mean))
        return sample_at(spec, n_pad, n_pad * p // q) + dc

    def check_input_rate(self, fs_in: float) -> Fraction:
        """``fs`` over the input (simulation) rate ``fs_in`` [Hz] as a fraction ``p/q``.

        Checked before a simulation by :func:`geardyn.case_checks.check_measurement` (with
        ``fs_in = 1/(dt decimation)``) and by :meth:`measure` on the input's time grid.

        Raises
        ------
        InputError
            On ``measurement.fs``: above ``fs_in``, or not a fraction of it with a denominator
            <= 10000.
        """
        fs = self.sensor.fs
        if fs > fs_in * (1 + 1e-9):
            raise InputError("measurement.fs", fs, f"at most the simulation's sample rate "
                             f"1/(dt decimation) = {fs_in:.6g} Hz")
        ratio = Fraction(fs / fs_in).limit_denominator(10_000)
        if abs(float(ratio) - fs / fs_in) > 1e-9 * fs / fs_in:
            raise InputError("measurement.fs", fs, f"a rate whose ratio to the simulation's "
                             f"sample rate {fs_in:.6g} Hz is a fraction with denominator <= 10000")
        return ratio

    def input_duration(self, record_time: float, dt: float) -> float:
        """Input length [s] needed for ``record_time`` of output at input step ``dt`` [s]."""
        q = Fraction(self.sensor.fs * dt).limit_denominator(10_000).denominator
        return record_time + self.lead_in() + self.tail() + 4.0 / self.sensor.fs + (q + 2) * dt

    def measure(self, time, forces, angle, omega, *, record_time: float | None = None
                ) -> Measured:
        """Run the chain.

        Parameters
        ----------
        time : array_like, shape (n,)
            Uniform input times [s].
        forces : array_like, shape (n_bearings, n)
            Bearing forces on the housing [N] (pinion, gear).
        angle, omega : array_like, shape (n,)
            Angle [rad] and angular velocity [rad/s] of the tachometer's shaft.
        record_time : float, optional
            Output length [s] (``round(record_time fs)`` samples); default all that the input
            allows after the lead-in and tail.

        Returns
        -------
        Measured

        Raises
        ------
        InputError
            Non-uniform times, ``fs`` above the input rate or not a simple fraction of it, an
            input too short for the lead-in, tail and record.
        """
        t = np.asarray(time, dtype=float)
        x = np.atleast_2d(np.asarray(forces, dtype=float))
        if x.shape != (self.path.n_inputs, t.size) or t.size < 4:
            raise InputError("forces", f"shape {x.shape}",
                             f"({self.path.n_inputs}, {t.size}): one row per bearing")
        dts = np.diff(t)
        dt = float(np.mean(dts))
        if not np.allclose(dts, dt, rtol=1e-6, atol=0.0):
            raise InputError("time", "non-uniform sample times", "a uniform time grid")
        fs_in = 1.0 / dt
        fs = self.sensor.fs
        ratio = self.check_input_rate(fs_in)
        p, q = ratio.numerator, ratio.denominator
        n = (t.size // q) * q
        n_out_all = n * p // q
        j0 = math.ceil(self.lead_in() * fs - 1e-9)
        j1 = n_out_all - math.ceil(self.tail() * fs - 1e-9)
        if record_time is not None:
            want = int(round(record_time * fs))
            if j0 + want > j1:
                raise InputError("record_time", record_time,
                                 f"at most {(j1 - j0) / fs:.6g} s from {t.size} input samples "
                                 f"after the lead-in {self.lead_in():.4g} s and tail "
                                 f"{self.tail():.4g} s")
            j1 = j0 + want
        if j1 - j0 < 2:
            raise InputError("time", f"{t.size * dt:.4g} s of input",
                             f"more than the lead-in {self.lead_in():.4g} s plus the tail "
                             f"{self.tail():.4g} s")

        if self.is_static() and p == 1:
            # frequency-independent chain, decimation by an integer: sum of gains in the time
            # domain, exactly (no FFT round-off)
            gains = self.path.frf(np.zeros(1))[:, 0].real
            acc = gains[0] * x[0, :n]
            for b in range(1, gains.size):
                acc = acc + gains[b] * x[b, :n]
            clean = np.ascontiguousarray(acc[::q][j0:j1])
        else:
            clean = self._filtered(x, n, p, q, fs_in)[j0:j1]
        noise_seq, jitter_seq = np.random.SeedSequence(self.seed).spawn(2)
        s = self.sensor
        if s.snr is not None and s.snr != math.inf:
            rms = noise_rms_for_snr(clean, s.snr)
        else:
            rms = float(s.noise_level or 0.0)
        noisy = add_noise(clean, rms, np.random.default_rng(noise_seq))
        clipped = 0
        acc = noisy
        if s.adc_bits is not None:
            acc, mask = quantise(noisy, int(s.adc_bits), s.adc_full_scale)
            clipped = int(mask.sum())
        start = float(t[0] + j0 / fs)
        tp = pulse_times(t, angle, omega, pulses_per_rev=int(self.tach.pulses_per_rev),
                         offset=self.tach.offset)
        if self.tach.jitter > 0:
            tp = np.sort(tp + self.tach.jitter
                         * np.random.default_rng(jitter_seq).standard_normal(tp.size))
        tach = pulse_train(tp - start, clean.size, fs, amplitude=self.tach.amplitude,
                           rise_time=self.tach.rise_time, duty=self.tach.duty)
        end = clean.size / fs
        rel = tp - start
        info = {
            "input_sample_rate": fs_in, "lead_in": self.lead_in(), "tail": self.tail(),
            "noise_rms": rms, "clipped_samples": clipped,
            "clipped_fraction": clipped / max(clean.size, 1),
        }
        return Measured(fs=fs, start_time=start, acc=acc, acc_clean=clean, noise=noisy - clean,
                        tach=tach, pulse_times=rel[(rel >= 0) & (rel < end)], noise_rms=rms,
                        clipped=clipped, info=info)
