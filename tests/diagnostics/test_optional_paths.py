"""Optional paths of the diagnostics exercised against hand computations (issue 20.5).

* NA4 and NB4 with a record history through :func:`condition_metrics` (a mutant that ignores
  the history gave the kurtosis of the current record and survived before);
* NA4* with a healthy baseline variance;
* the TSA anti-alias oversampling at +/-30 % speed (a mutant taking L from the largest angle
  step, i.e. the fastest speed, instead of the smallest survived before).

Definitions (as written in the Lebold et al. (2000) MFPT review of the NASA reports, and in the
project's design note on diagnostics; the NASA TMs themselves were not reachable here, so each
value below is computed twice: by the sums of the definition written out in the test, and in
closed form for sinusoidal records):

    NA4  = m4(r_M) / ( (1/M) sum_{j=1..M} m2(r_j) )^2     (Zakrajsek 1993, NASA TM-105950)
    NA4* = m4(r_M) / v0^2, v0 a fixed healthy residual variance   (Decker et al., TM-106553)
    NB4  = NA4 of the envelope of the band about a mesh harmonic  (Zakrajsek 1993)

with m_k the biased central moment (1/N) sum (r - mean r)^k and r_M the current record.
"""

from __future__ import annotations

import math

import numpy as np
import pytest

from geardyn.diagnostics import condition_metrics, tsa
from geardyn.diagnostics.metrics import NA4Tracker, band_envelope

TWO_PI = 2 * np.pi
Z = 23
N = 512
THETA = TWO_PI * np.arange(N) / N


def _moment_by_sums(r, k):
    """Biased central moment written out as the definition's sums (no library helper)."""
    n = len(r)
    mean = sum(float(v) for v in r) / n
    return sum((float(v) - mean) ** k for v in r) / n


def _na4_by_definition(current, history):
    records = [*history, current]
    mean_m2 = sum(_moment_by_sums(r, 2) for r in records) / len(records)
    return _moment_by_sums(current, 4) / mean_m2**2


def _tsa_with_residual(a):
    """A TSA whose Zakrajsek residual (mean, shaft orders 1-2, mesh harmonics removed) is
    exactly ``a sin(10 theta)``."""
    return (0.7 + np.cos(THETA) + 0.3 * np.sin(2 * THETA) + np.cos(Z * THETA)
            + 0.4 * np.cos(2 * Z * THETA + 0.2) + a * np.sin(10 * THETA))


def test_na4_with_history_through_condition_metrics():
    history = [1.0 * np.sin(10 * THETA), 2.0 * np.sin(10 * THETA)]
    m = condition_metrics(_tsa_with_residual(3.0), teeth=Z, residual_history=history)
    # closed form: m2 = a^2/2 -> mean (1 + 4 + 9)/6 = 7/3; m4 = 3 a^4 / 8 = 30.375
    closed = (3 * 3.0**4 / 8) / (7 / 3) ** 2
    assert closed == pytest.approx(5.579, abs=5e-4)  # design note's running-NA4 oracle
    assert m.NA4 == pytest.approx(closed, rel=1e-12)
    assert m.NA4 == pytest.approx(_na4_by_definition(3.0 * np.sin(10 * THETA), history),
                                  rel=1e-12)
    # without the history it is the kurtosis of the sinusoid, 1.5 (what the mutant returned)
    alone = condition_metrics(_tsa_with_residual(3.0), teeth=Z)
    assert alone.NA4 == pytest.approx(1.5, rel=1e-12)
    assert abs(m.NA4 - alone.NA4) > 4


def test_na4_history_of_unequal_random_records_matches_the_sums():
    rng = np.random.default_rng(11)
    history = [rng.standard_normal(N) * s + 5.0 for s in (0.5, 1.0, 1.7)]  # means differ
    x = _tsa_with_residual(0.0) + 0.0
    noise = rng.standard_normal(N) * 0.8
    # give the current record a residual: remove what the preset removes from the noise
    from geardyn.diagnostics.spectra import residual

    r_now = residual(x + noise, teeth=Z, preset="zakrajsek")
    m = condition_metrics(x + noise, teeth=Z, residual_history=history)
    assert m.NA4 == pytest.approx(_na4_by_definition(r_now, history), rel=1e-10)
    # the running tracker agrees with the one-shot call
    tr = NA4Tracker()
    for h in history:
        tr.update(h)
    assert tr.update(r_now) == pytest.approx(m.NA4, rel=1e-10)


def test_na4_star_with_baseline_variance():
    v0 = 0.8  # healthy residual variance [u^2]
    m = condition_metrics(_tsa_with_residual(2.0), teeth=Z, na4_baseline_variance=v0)
    # m4 of 2 sin(10 theta) = 3 * 16 / 8 = 6
    assert m.NA4star == pytest.approx(6.0 / v0**2, rel=1e-12)
    assert math.isnan(condition_metrics(_tsa_with_residual(2.0), teeth=Z).NA4star)


def test_nb4_with_envelope_history():
    amp, mod = 1.3, 0.4
    x = amp * (1 + mod * np.cos(2 * THETA)) * np.cos(Z * THETA) + 0.5 * np.cos(3 * THETA)
    env = band_envelope(x, teeth=Z)
    # the band 23 +/- 11 holds the carrier and both sidebands: envelope A (1 + m cos 2 theta)
    np.testing.assert_allclose(env, amp * (1 + mod * np.cos(2 * THETA)), atol=1e-12)
    history = [a * (1 + b * np.cos(2 * THETA)) for a, b in ((1.0, 0.1), (1.1, 0.2))]
    m = condition_metrics(x, teeth=Z, nb4_history=history)
    # closed form: m2 = (A m)^2 / 2, m4 = 3 (A m)^4 / 8
    m2s = [(1.0 * 0.1) ** 2 / 2, (1.1 * 0.2) ** 2 / 2, (amp * mod) ** 2 / 2]
    closed = (3 * (amp * mod) ** 4 / 8) / (sum(m2s) / 3) ** 2
    assert m.NB4 == pytest.approx(closed, rel=1e-10)
    assert m.NB4 == pytest.approx(_na4_by_definition(env, history), rel=1e-10)
    alone = condition_metrics(x, teeth=Z)
    assert alone.NB4 == pytest.approx(1.5, rel=1e-10)  # kurtosis of a sinusoidal envelope
    assert m.NB4 > 5 * alone.NB4


# ------------------------------------------------------------------------------------------
# anti-alias oversampling at +/-30 % speed
# ------------------------------------------------------------------------------------------
PER_REV = 1024  # raw samples per revolution at the mean speed
EPS = 0.3  # speed swing
T_MOD = 3.0  # speed period [mean revolutions]


def _angle(n_rev):
    """theta(t) for a speed 1 + EPS sin(2 pi t / T_MOD) (t in mean revolutions)."""
    t = np.arange(n_rev * PER_REV + 8) / PER_REV
    return TWO_PI * t + EPS * T_MOD * (1 - np.cos(TWO_PI * t / T_MOD))


def test_oversampling_follows_the_slowest_speed():
    theta = _angle(12)
    res = tsa(np.cos(5 * theta), angle=theta, samples_per_rev=256)
    # densest raw sampling at the slowest speed: PER_REV / (1 - EPS) = 1463 samples per rev
    d_min = float(np.min(np.diff(theta)))
    assert TWO_PI / d_min == pytest.approx(PER_REV / (1 - EPS), rel=1e-5)
    assert res.oversampling == math.ceil(PER_REV / (1 - EPS) / 256) == 6
    # (from the largest step, the fastest speed, it would be ceil(788 / 256) = 4)
    assert math.ceil(PER_REV / (1 + EPS) / 256) == 4


def test_tone_leakage_at_varying_speed_is_bounded():
    """A tone above N/2 is removed; what leaks is the interpolant's images (measured 4.6e-3
    with L = 6; 1.4e-2 with the mutant's L = 4)."""
    theta = _angle(12)
    x = np.cos(5 * theta) + np.cos(300 * theta + 0.3)
    res = tsa(x, angle=theta, samples_per_rev=256)
    assert np.max(np.abs(res.average - np.cos(5 * res.angle))) < 8e-3
