r"""Fatigue crack growth: direction (maximum tangential stress) and rate (Paris law).

Pure functions of the stress intensity factors (:mod:`geardyn.stiffness.fe.sif` computes them
from the FE model); :func:`grow_tooth_crack` (in :mod:`geardyn.faults.tooth_growth`) strings them
together on a gear tooth.

Direction: maximum tangential stress (Erdogan & Sih 1963)
---------------------------------------------------------
The crack kinks at the polar angle ``theta_c`` (measured from the current crack direction,
positive towards the crack-tip ``x_2`` axis) where the singular hoop stress
``sigma_theta_theta = K_theta / sqrt(2 pi r)`` with

.. math:: K_\theta(\theta) = \cos\frac\theta2\left[K_I\cos^2\frac\theta2
          - \frac32 K_{II}\sin\theta\right]

is largest; ``d sigma_theta_theta / d theta = 0`` gives
``K_I sin(theta) + K_II (3 cos(theta) - 1) = 0`` and

.. math:: \theta_c = 2\arctan\frac{K_I - \sqrt{K_I^2 + 8K_{II}^2}}{4K_{II}}
          = 2\arctan\frac{-2K_{II}}{K_I + \sqrt{K_I^2 + 8K_{II}^2}},

the second form (the first multiplied above and below by ``K_I + sqrt(...)``) being regular at
``K_II = 0``. Sources read: the second form is the one in MSolve's
``MaximumCircumferentialTensileStressCriterion.cs`` (SerafeimBakalakos/MSolve); ``K_theta``
follows from Williams' near-tip stresses of :mod:`geardyn.stiffness.fe.sif` (the tests check
``theta_c`` against a numerical maximisation of the hoop stress built from those fields). The
original paper (Erdogan, F. & Sih, G. C. (1963), J. Basic Eng. 85:519-527) was not read.

The equivalent mode-I factor driving growth is ``K_eq = K_theta(theta_c)`` (the hoop stress
factor in the growth direction; ``K_eq = K_I`` for ``K_II = 0``).

Rate: Paris law (Paris & Erdogan 1963)
--------------------------------------
``da/dN = C (Delta K)^m`` for ``Delta K > Delta K_th`` (zero below), with ``C`` in
``m/cycle/(Pa m^0.5)^m`` and ``m`` dimensionless. geardyn ships no default material constants:
they must come from the user with their source (a ``C`` quoted per ``MPa m^0.5`` is converted by
``C_SI = C_MPa * 1e-6 ** m``; see :func:`paris_c_from_mpa`). One load cycle per mesh of the
cracked tooth with the load going from zero to its peak gives ``Delta K = K_eq,max``
(``R = 0``).
"""

from __future__ import annotations

import math

import numpy as np

from ..errors import InputError

__all__ = ["mts_angle", "hoop_factor", "equivalent_k", "paris_rate", "paris_cycles",
           "paris_c_from_mpa"]


def mts_angle(K_I, K_II):
    """Kink angle of the maximum tangential stress criterion [rad] (module docstring).

    Parameters
    ----------
    K_I, K_II : float or ndarray
        Stress intensity factors [Pa m^0.5] (any consistent unit).

    Returns
    -------
    float or ndarray
        ``theta_c`` in ``(-arccos(1/3), arccos(1/3))`` (``+-70.5 deg`` in pure mode II), of the
        opposite sign to ``K_II``.

    Raises
    ------
    InputError
        ``K_I <= 0`` with ``K_II = 0`` (a closed crack has no growth direction).
    """
    k1 = np.asarray(K_I, float)
    k2 = np.asarray(K_II, float)
    s = np.sqrt(k1 * k1 + 8 * k2 * k2)
    den = k1 + s
    if np.any(den <= 0):
        raise InputError("K_I", K_I, "K_I > 0 or K_II != 0 (a closed crack, K_I <= 0 and "
                         "K_II = 0, has no growth direction)")
    out = 2 * np.arctan(-2 * k2 / den)
    return float(out) if out.ndim == 0 else out


def hoop_factor(K_I, K_II, theta):
    """``K_theta = sqrt(2 pi r) sigma_theta_theta`` of the singular field at angle ``theta``
    [Pa m^0.5] (module docstring)."""
    c = np.cos(np.asarray(theta, float) / 2)
    return c * (K_I * c * c - 1.5 * K_II * np.sin(theta))


def equivalent_k(K_I, K_II):
    """Equivalent mode-I factor ``K_eq = K_theta(theta_c)`` [Pa m^0.5] (module docstring)."""
    return hoop_factor(K_I, K_II, mts_angle(K_I, K_II))


def paris_c_from_mpa(c_mpa: float, m: float) -> float:
    """Convert a Paris ``C`` given per ``MPa m^0.5`` (da/dN in m/cycle) to SI
    ``m/cycle/(Pa m^0.5)^m``: ``C_SI = C_MPa 1e-6^m``."""
    return float(c_mpa) * 1e-6 ** float(m)


def _check_paris(C: float, m: float, dk_th: float) -> None:
    if not (math.isfinite(C) and C > 0):
        raise InputError("paris.C", C, "a Paris coefficient > 0 [m/cycle/(Pa m^0.5)^m]")
    if not (math.isfinite(m) and 0 < m <= 20):
        raise InputError("paris.m", m, "a Paris exponent in (0, 20]")
    if not (math.isfinite(dk_th) and dk_th >= 0):
        raise InputError("paris.threshold", dk_th, "a threshold Delta K >= 0 [Pa m^0.5]")


def paris_rate(delta_K, C: float, m: float, threshold: float = 0.0):
    """Paris law growth rate ``da/dN = C (Delta K)^m`` [m/cycle], zero for
    ``Delta K <= threshold``.

    Parameters
    ----------
    delta_K : float or ndarray
        Stress intensity range [Pa m^0.5].
    C : float
        [m/cycle/(Pa m^0.5)^m] (no default: a material constant with its source).
    m : float
        Exponent [-].
    threshold : float
        ``Delta K_th`` [Pa m^0.5].
    """
    _check_paris(C, m, threshold)
    dk = np.asarray(delta_K, float)
    out = np.where(dk > threshold, C * np.abs(dk) ** m, 0.0)
    return float(out) if out.ndim == 0 else out


def paris_cycles(a: np.ndarray, delta_K: np.ndarray, C: float, m: float,
                 threshold: float = 0.0) -> np.ndarray:
    """Cycles to grow a crack through lengths ``a`` with ranges ``delta_K(a)``.

    ``N(a_k) = sum_j (a_{j+1} - a_j) / 2 (1/rate_j + 1/rate_{j+1})`` (trapezoidal rule on
    ``dN/da = 1 / (C Delta K^m)``); second-order accurate in the step for smooth ``Delta K(a)``.

    Parameters
    ----------
    a : ndarray, shape (n,)
        Crack lengths along the path, increasing [m].
    delta_K : ndarray, shape (n,)
        Stress intensity ranges at those lengths [Pa m^0.5].
    C, m, threshold
        As in :func:`paris_rate`.

    Returns
    -------
    ndarray, shape (n,)
        Cumulative cycles from ``a[0]`` [-]; ``inf`` from the first step where a range is at or
        below the threshold.
    """
    a = np.asarray(a, float)
    dk = np.asarray(delta_K, float)
    if a.shape != dk.shape or a.ndim != 1 or a.size < 1:
        raise InputError("delta_K", dk.shape, f"one range per crack length {a.shape}")
    if np.any(np.diff(a) <= 0):
        raise InputError("a", "crack lengths", "strictly increasing lengths")
    rate = paris_rate(dk, C, m, threshold)
    with np.errstate(divide="ignore"):
        inv = np.where(rate > 0, 1.0 / np.where(rate > 0, rate, 1.0), np.inf)
    steps = 0.5 * np.diff(a) * (inv[:-1] + inv[1:])
    return np.concatenate([[0.0], np.cumsum(steps)])
