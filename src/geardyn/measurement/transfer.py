r"""Transfer path from the bearing forces to the acceleration at a housing sensor.

Two kinds of path, both linear and time-invariant, both giving a frequency response function
(FRF) per bearing in (m/s^2)/N (an *accelerance*):

* :class:`ModalPath`, a sum of modes. Mode ``k`` with natural frequency ``f_k`` [Hz], damping
  ratio ``zeta_k`` [-] and gain ``g_kb`` [(m/s^2)/N] per bearing ``b`` contributes

  .. math:: A_{kb}(\omega) = g_{kb} \frac{-\omega^2}{\omega_k^2 - \omega^2
            + 2 j \zeta_k \omega_k \omega}, \qquad \omega_k = 2\pi f_k,

  the accelerance of a viscously damped single-degree-of-freedom mode in modal coordinates:
  ``q'' + 2 zeta w_k q' + w_k^2 q = g F``, ``a = q''`` (derived here, not quoted; the tests
  check it against a time-domain integration of that equation). The receptance is
  ``phi_s phi_b / (m_k (w_k^2 - w^2 + 2 j zeta w_k w))`` and the accelerance ``-w^2`` times
  it, so the gain is ``phi_sensor phi_bearing / m_k`` (mode shapes over modal mass) and is
  the accelerance far above the mode; at ``omega_k`` it is
  ``g / (2 zeta)`` with phase +90 deg. ``f_k = 0`` is a rigid-body (mass-line) mode, ``A = g``
  at every frequency: ``g = 1/m`` for a rigid housing of mass ``m`` on soft mounts. The static
  force (DC) gives no acceleration.
* :class:`FRFTable`, a measured FRF per bearing (complex values at increasing frequencies,
  linearly interpolated in real and imaginary parts, zero outside the table).

The acceleration is ``a(t) = sum_b (A_b * F_b)(t)`` (``*`` the convolution); the caller
applies it with :func:`geardyn.measurement.sensor.apply_frf` in the frequency domain.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from ..errors import InputError

__all__ = ["Mode", "ModalPath", "FRFTable", "mode_accelerance", "SETTLING_DECAYS"]

#: Time constants waited for a transient to decay below exp(-18.4) = 1e-8 of its start.
SETTLING_DECAYS = math.log(1e8)


def mode_accelerance(f, frequency: float, damping_ratio: float) -> np.ndarray:
    r"""Normalised accelerance of one mode, ``-w^2 / (w_k^2 - w^2 + 2 j zeta w_k w)`` [-].

    Parameters
    ----------
    f : array_like
        Frequencies [Hz] (any sign: the result is Hermitian, ``A(-f) = conj(A(f))``).
    frequency : float
        Natural frequency ``f_k`` [Hz], >= 0 (0: rigid-body mode, result 1).
    damping_ratio : float
        ``zeta_k`` [-], in [0, 1).

    Returns
    -------
    ndarray of complex
        Multiply by the gain [(m/s^2)/N] for the accelerance.
    """
    w = 2.0 * np.pi * np.asarray(f, dtype=float)
    if frequency == 0.0:
        return np.ones(w.shape, dtype=complex)
    wk = 2.0 * np.pi * frequency
    return -w * w / (wk * wk - w * w + 2j * damping_ratio * wk * w)


@dataclass(frozen=True)
class Mode:
    """One structural mode of the housing path.

    Attributes
    ----------
    frequency : float
        Natural frequency [Hz], >= 0 (0 = rigid-body mode).
    damping_ratio : float
        Viscous damping ratio [-], in [0, 1).
    gains : tuple of float
        Gain per bearing [(m/s^2)/N], the accelerance far above the mode (mode shape at the sensor
        times mode shape at the bearing over the modal mass). Order: pinion, gear.
    """

    frequency: float
    damping_ratio: float
    gains: tuple[float, ...]

    def __post_init__(self) -> None:
        if not (math.isfinite(self.frequency) and self.frequency >= 0):
            raise InputError("measurement.mode_frequencies", self.frequency,
                             "natural frequencies in Hz, >= 0 (0 = rigid-body mode)")
        if not (0.0 <= self.damping_ratio < 1.0):
            raise InputError("measurement.mode_damping_ratios", self.damping_ratio,
                             "damping ratios in [0, 1)")
        if self.frequency > 0 and self.damping_ratio == 0.0:
            raise InputError("measurement.mode_damping_ratios", self.damping_ratio,
                             "a positive damping ratio for a flexible mode (an undamped mode "
                             "never settles and has an infinite FRF at resonance)")
        if not all(math.isfinite(g) for g in self.gains):
            raise InputError("measurement.mode_gains", self.gains, "finite gains in (m/s^2)/N")


@dataclass(frozen=True)
class ModalPath:
    """A transfer path as a sum of modes (see the module docstring).

    Attributes
    ----------
    modes : tuple of Mode
        The modes; each has one gain per input (bearing).
    """

    modes: tuple[Mode, ...]

    def __post_init__(self) -> None:
        if not self.modes:
            raise InputError("measurement.mode_frequencies", [], "at least one mode")
        n = {len(m.gains) for m in self.modes}
        if len(n) != 1 or 0 in n:
            raise InputError("measurement.mode_gains", [m.gains for m in self.modes],
                             "the same number (>= 1) of gains, one per bearing, for every mode")

    @classmethod
    def single(cls, frequency: float, damping_ratio: float, gains) -> ModalPath:
        """A path with one mode."""
        return cls((Mode(float(frequency), float(damping_ratio), tuple(float(g) for g in gains)),))

    @property
    def n_inputs(self) -> int:
        """Number of force inputs (bearings)."""
        return len(self.modes[0].gains)

    @property
    def highest_frequency(self) -> float:
        """Highest natural frequency [Hz]."""
        return max(m.frequency for m in self.modes)

    def frf(self, f) -> np.ndarray:
        """Accelerance per input [(m/s^2)/N] at frequencies ``f`` [Hz]; shape ``(n_inputs, len(f))``."""
        f = np.asarray(f, dtype=float)
        out = np.zeros((self.n_inputs, f.size), dtype=complex)
        for m in self.modes:
            shape = mode_accelerance(f.ravel(), m.frequency, m.damping_ratio)
            for b, g in enumerate(m.gains):
                if g != 0.0:
                    out[b] += g * shape
        return out

    def settling_time(self) -> float:
        """Time for the slowest flexible mode's free response to decay by 1e-8 [s]."""
        taus = [1.0 / (m.damping_ratio * 2.0 * math.pi * m.frequency)
                for m in self.modes if m.frequency > 0]
        return SETTLING_DECAYS * max(taus, default=0.0)

    def describe(self) -> str:
        """One line per mode (for record attributes)."""
        return "; ".join(f"{m.frequency:.6g} Hz, zeta {m.damping_ratio:.4g}, gains "
                         + ", ".join(f"{g:.6g}" for g in m.gains) + " (m/s^2)/N"
                         for m in self.modes)


@dataclass(frozen=True)
class FRFTable:
    """A measured transfer path: complex accelerance per bearing at tabulated frequencies.

    Attributes
    ----------
    frequency : ndarray, shape (nf,)
        Frequencies [Hz], >= 0, strictly increasing.
    values : ndarray of complex, shape (n_inputs, nf)
        Accelerance [(m/s^2)/N] per input.
    settling : float
        Memory of the path [s]: how long its impulse response lasts (used as the lead-in
        discarded before the record starts). A table carries no damping, so it is given.
    """

    frequency: np.ndarray
    values: np.ndarray
    settling: float = 0.1

    def __post_init__(self) -> None:
        f = np.asarray(self.frequency, dtype=float)
        v = np.atleast_2d(np.asarray(self.values, dtype=complex))
        if f.ndim != 1 or f.size < 2 or not np.all(np.isfinite(f)) or f[0] < 0 \
                or not np.all(np.diff(f) > 0):
            raise InputError("measurement.frf_table", f"{f.size} frequencies",
                             "at least 2 frequencies in Hz, >= 0, strictly increasing")
        if v.shape[1] != f.size or not np.all(np.isfinite(v)):
            raise InputError("measurement.frf_table", f"values of shape {v.shape}",
                             f"finite complex values of shape (bearings, {f.size})")
        if not (math.isfinite(self.settling) and self.settling >= 0):
            raise InputError("measurement.frf_settling_time", self.settling, "a time >= 0 in s")
        object.__setattr__(self, "frequency", f)
        object.__setattr__(self, "values", v)

    @classmethod
    def from_csv(cls, path, settling: float = 0.1) -> FRFTable:
        """Read a CSV with columns ``frequency`` [Hz] then ``re``, ``im`` per bearing
        [(m/s^2)/N] (header line optional, ``#`` comments allowed)."""
        from ..diagnostics.io import read_table

        table = read_table(path)
        cols = list(table.columns.values())
        if len(cols) < 3 or len(cols) % 2 == 0:
            raise InputError("measurement.frf_table", str(path),
                             "a CSV with a frequency column and a (re, im) pair per bearing")
        vals = np.array([cols[i] + 1j * cols[i + 1] for i in range(1, len(cols), 2)])
        return cls(np.asarray(cols[0]), vals, settling)

    @property
    def n_inputs(self) -> int:
        """Number of force inputs (bearings)."""
        return int(self.values.shape[0])

    @property
    def highest_frequency(self) -> float:
        """Highest tabulated frequency [Hz]."""
        return float(self.frequency[-1])

    def frf(self, f) -> np.ndarray:
        """Accelerance per input [(m/s^2)/N] at ``f`` [Hz] (>= 0): linear interpolation, zero
        outside the table; shape ``(n_inputs, len(f))``."""
        f = np.asarray(f, dtype=float).ravel()
        out = np.empty((self.n_inputs, f.size), dtype=complex)
        for b in range(self.n_inputs):
            re = np.interp(f, self.frequency, self.values[b].real, left=0.0, right=0.0)
            im = np.interp(f, self.frequency, self.values[b].imag, left=0.0, right=0.0)
            out[b] = re + 1j * im
        return out

    def settling_time(self) -> float:
        """The given memory of the path [s]."""
        return float(self.settling)

    def describe(self) -> str:
        """Short description (for record attributes)."""
        return (f"FRF table, {self.frequency.size} frequencies {self.frequency[0]:.6g}.."
                f"{self.frequency[-1]:.6g} Hz, {self.n_inputs} bearings")
