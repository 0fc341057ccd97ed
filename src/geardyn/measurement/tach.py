r"""Tachometer: pulse times from the shaft angle, trigger jitter, and the sampled pulse train.

A tachometer with ``P`` pulses per revolution fires when the shaft angle passes
``offset + 2 pi k / P``. :func:`pulse_times` finds those instants from the simulated angle and
angular velocity by inverting the cubic Hermite interpolant of the angle on each time step (angle
and its derivative match at both ends of the step: local error O(dt^4)). Trigger jitter adds an
independent Gaussian time error of standard deviation ``jitter`` [s] to each pulse.

The channel a DAQ records (:func:`pulse_train`) is a pulse of ``amplitude`` volts from each pulse
time to ``duty`` of the way to the next one, with linear edges of duration ``rise_time`` centred
on the pulse time (the edge a signal conditioner and the DAQ's anti-alias filter leave; with a
rise time of at least two sample intervals the mid-level crossing found by linear interpolation
between samples is exactly the pulse time).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from ..errors import InputError

__all__ = ["Tachometer", "pulse_times", "pulse_train"]


def pulse_times(time, angle, omega, *, pulses_per_rev: int = 1, offset: float = 0.0) -> np.ndarray:
    """Instants [s] at which ``angle`` passes ``offset + 2 pi k / pulses_per_rev``.

    Parameters
    ----------
    time : array_like, shape (n,)
        Sample times [s], increasing.
    angle : array_like, shape (n,)
        Shaft angle [rad], increasing (unwrapped).
    omega : array_like, shape (n,)
        Its derivative [rad/s] (used by the cubic Hermite interpolant).
    pulses_per_rev : int
        Pulses per revolution [-].
    offset : float
        Angle of pulse 0 [rad].

    Returns
    -------
    ndarray
        Pulse times [s] inside ``[time[0], time[-1]]``.
    """
    t = np.asarray(time, dtype=float)
    a = np.asarray(angle, dtype=float)
    w = np.asarray(omega, dtype=float)
    if not (t.shape == a.shape == w.shape and t.ndim == 1 and t.size >= 2):
        raise InputError("angle", f"shapes {t.shape}, {a.shape}, {w.shape}",
                         "time, angle and omega of the same length >= 2")
    if not np.all(np.diff(a) > 0):
        raise InputError("angle", "a shaft angle that does not always increase",
                         "a shaft turning forwards (the tachometer model needs rotation)")
    step = 2.0 * math.pi / pulses_per_rev
    k0 = math.ceil((a[0] - offset) / step)
    k1 = math.floor((a[-1] - offset) / step)
    if k1 < k0:
        return np.empty(0)
    levels = offset + step * np.arange(k0, k1 + 1)
    i = np.clip(np.searchsorted(a, levels, side="right") - 1, 0, a.size - 2)
    h = t[i + 1] - t[i]
    a0, a1, m0, m1 = a[i], a[i + 1], w[i] * h, w[i + 1] * h
    s = (levels - a0) / (a1 - a0)  # linear first guess
    for _ in range(6):  # Newton on the Hermite cubic p(s) - level
        s2, s3 = s * s, s * s * s
        p = ((2 * s3 - 3 * s2 + 1) * a0 + (s3 - 2 * s2 + s) * m0 + (-2 * s3 + 3 * s2) * a1
             + (s3 - s2) * m1)
        dp = (6 * s2 - 6 * s) * a0 + (3 * s2 - 4 * s + 1) * m0 + (-6 * s2 + 6 * s) * a1 \
            + (3 * s2 - 2 * s) * m1
        s = np.clip(s - (p - levels) / np.where(dp > 0, dp, a1 - a0), 0.0, 1.0)
    return t[i] + s * h


def pulse_train(times, n: int, fs: float, *, t0: float = 0.0, amplitude: float = 5.0,
                rise_time: float | None = None, duty: float = 0.5) -> np.ndarray:
    """Sampled tachometer channel [V] at ``t0 + j / fs``, ``j = 0..n-1``.

    Parameters
    ----------
    times : array_like
        Pulse times [s], increasing (may extend beyond the record).
    n : int
        Number of samples.
    fs : float
        Sample rate [Hz].
    t0 : float
        Time of sample 0 [s].
    amplitude : float
        High level [V] (low level 0 V).
    rise_time : float, optional
        Edge duration [s]; default three sample intervals.
    duty : float
        High fraction of each pulse interval [-], in (0, 1).
    """
    tp = np.asarray(times, dtype=float)
    ts = t0 + np.arange(n) / fs
    tr = 3.0 / fs if rise_time is None else float(rise_time)
    if tp.size == 0:
        return np.zeros(n)
    gaps = np.diff(tp)
    gap = np.append(gaps, gaps[-1] if gaps.size else 1.0)
    falls = tp + duty * gap
    if gaps.size and tr >= min(duty, 1 - duty) * gaps.min():
        raise InputError("measurement.tach_rise_time", tr,
                         f"an edge shorter than the pulse ({min(duty, 1 - duty) * gaps.min():.3g} "
                         "s): lower the rise time or the pulses per revolution")

    def count(edges):
        # edges started by t (t > e - tr/2), the last one possibly partial
        idx = np.searchsorted(edges, ts + 0.5 * tr, side="left")
        last = edges[np.maximum(idx - 1, 0)]
        frac = np.clip((ts - last) / tr + 0.5, 0.0, 1.0) if tr > 0 else (ts >= last) * 1.0
        return np.where(idx > 0, idx - 1 + frac, 0.0)

    return amplitude * (count(tp) - count(falls))


@dataclass(frozen=True)
class Tachometer:
    """Tachometer settings.

    Attributes
    ----------
    shaft : {"pinion", "gear"}
        The shaft it reads.
    pulses_per_rev : int
        Pulses per revolution [-].
    jitter : float
        Standard deviation of the trigger time error [s].
    offset : float
        Shaft angle of pulse 0 [rad].
    amplitude : float
        Pulse height [V].
    rise_time : float or None
        Edge duration [s]; ``None``: three sample intervals.
    duty : float
        High fraction of a pulse interval [-].
    """

    shaft: str = "pinion"
    pulses_per_rev: int = 1
    jitter: float = 0.0
    offset: float = 0.0
    amplitude: float = 5.0
    rise_time: float | None = None
    duty: float = 0.5

    def __post_init__(self) -> None:
        f = "measurement."
        if self.shaft not in ("pinion", "gear"):
            raise InputError(f + "tach_shaft", self.shaft, "'pinion' or 'gear'")
        if not 1 <= int(self.pulses_per_rev) <= 10_000:
            raise InputError(f + "tach_pulses_per_rev", self.pulses_per_rev, "1..10000")
        if not (math.isfinite(self.jitter) and self.jitter >= 0):
            raise InputError(f + "tach_jitter", self.jitter, "a time >= 0 in s")
        if not (math.isfinite(self.amplitude) and self.amplitude > 0):
            raise InputError(f + "tach_amplitude", self.amplitude, "a positive level in V")
        if self.rise_time is not None and not (math.isfinite(self.rise_time)
                                               and self.rise_time >= 0):
            raise InputError(f + "tach_rise_time", self.rise_time, "a time >= 0 in s")
        if not 0.0 < self.duty < 1.0:
            raise InputError(f + "tach_duty", self.duty, "a fraction in (0, 1)")
