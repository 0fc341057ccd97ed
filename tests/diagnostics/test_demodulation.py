"""Narrowband demodulation (McFadden 1986): AM/PM recovery oracle and band checks."""

from __future__ import annotations

import numpy as np
import pytest

from geardyn.diagnostics import DiagnosticsWarning, band_limits, narrowband_demodulation
from geardyn.errors import InputError

N = 2048
T = 2 * np.pi * np.arange(N) / N
AM_TRUE = 1.7 * (1 + 0.3 * np.cos(2 * T))
PM_TRUE = 0.5 * np.sin(T) + np.radians(40.0)
X = AM_TRUE * np.cos(115 * T + PM_TRUE) + 0.8 * np.cos(46 * T + 0.3) + 0.2 * np.cos(3 * T)


def test_am_pm_recovery_oracle():
    dem = narrowband_demodulation(X, teeth=23, harmonic=5, bandwidth=11)
    assert dem.carrier_order == 115
    assert dem.band == (104, 126)
    assert np.max(np.abs(dem.am - AM_TRUE)) < 1e-12  # oracle: about 1e-13
    assert np.max(np.abs(dem.pm - PM_TRUE)) < 1e-11  # oracle: about 1e-12 rad
    assert np.degrees(dem.pm.mean()) == pytest.approx(40.000, abs=1e-9)
    assert np.degrees(np.angle(dem.baseband.mean())) == pytest.approx(40.0, abs=1e-6)
    np.testing.assert_allclose(dem.am_relative, AM_TRUE / AM_TRUE.mean() - 1, atol=1e-12)
    # baseband = z exp(-i K theta); radius AM, angle PM
    np.testing.assert_allclose(dem.baseband, dem.analytic * np.exp(-115j * T), atol=1e-12)
    np.testing.assert_allclose(np.abs(dem.baseband), dem.am, atol=1e-12)
    # the real part of the analytic signal is the band-passed TSA (the carrier component)
    np.testing.assert_allclose(dem.analytic.real, AM_TRUE * np.cos(115 * T + PM_TRUE),
                               atol=1e-12)


def test_remove_mean_phase():
    dem = narrowband_demodulation(X, teeth=23, remove_mean_phase=True)
    assert abs(dem.pm.mean()) < 1e-14
    np.testing.assert_allclose(dem.pm, PM_TRUE - PM_TRUE.mean(), atol=1e-11)
    assert dem.mean_phase_removed


def test_narrowband_envelope_with_and_without_carrier():
    # pure AM: 1.7 (1 + 0.3 cos 2t) cos(115 t): carrier bin 1.7, sidebands 0.255 at +/-2
    x = AM_TRUE * np.cos(115 * T)
    kept = narrowband_demodulation(x, teeth=23, envelope_excludes_carrier=False)
    np.testing.assert_allclose(kept.envelope, kept.am, atol=0)
    removed = narrowband_demodulation(x, teeth=23)
    # without the carrier only the sidebands remain: |0.255 (e^{2it} + e^{-2it})| = 0.51|cos 2t|
    np.testing.assert_allclose(removed.envelope, 0.51 * np.abs(np.cos(2 * T)), atol=1e-12)
    assert removed.envelope_excludes_carrier


def test_pm_unwraps_large_phase_excursions():
    pm = 3.0 * np.sin(T)  # peaks beyond pi: needs unwrapping; Bessel sidebands J_k(3)
    x = np.cos(115 * T + pm)
    dem = narrowband_demodulation(x, teeth=23, bandwidth=11)
    # J_12(3) ~ 5e-7: the truncated band recovers the phase to that order
    assert np.max(np.abs(dem.pm - pm)) < 1e-5


def test_band_checks():
    assert band_limits(23, 5, 11, 2048) == (104, 126)
    with pytest.raises(InputError, match="neighbouring mesh harmonic"):
        narrowband_demodulation(X, teeth=23, bandwidth=23)
    with pytest.warns(DiagnosticsWarning, match="overlaps the band of the neighbouring"):
        narrowband_demodulation(X, teeth=23, bandwidth=12)
    with pytest.raises(InputError, match="Nyquist"):
        narrowband_demodulation(X[::16], teeth=23, harmonic=5, bandwidth=11)  # N = 128
    with pytest.raises(InputError, match="bandwidth"):
        narrowband_demodulation(X, teeth=23, harmonic=1, bandwidth=0)
    with pytest.raises(InputError, match="harmonic"):
        narrowband_demodulation(X, teeth=23, harmonic=0)
    with pytest.raises(InputError, match="x: .*index 3"):
        narrowband_demodulation(np.r_[X[:3], np.nan, X[4:]], teeth=23)
