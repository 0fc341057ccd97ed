"""One implementation of each thing (issue 17.7): the analytic signal from scipy.signal.hilbert,
the NB4 band envelope from the demodulation code, one kurtosis helper."""

from __future__ import annotations

import warnings

import numpy as np
import pytest

from geardyn.diagnostics import (
    DiagnosticsWarning,
    analytic_signal,
    band_envelope,
    kurtosis,
    narrowband_demodulation,
    signal_statistics,
)
from geardyn.diagnostics.demodulation import band_analytic_signal


def _analytic_by_fft_weights(x, remove_mean):
    """The textbook FFT construction: Z_0 = 0 or X_0, Z_k = 2 X_k (0 < k < N/2), Z_N/2 = X_N/2,
    zero for negative frequencies."""
    n = len(x)
    h = np.zeros(n)
    h[0] = 0.0 if remove_mean else 1.0
    h[1:(n + 1) // 2] = 2.0
    if n % 2 == 0:
        h[n // 2] = 1.0
    return np.fft.ifft(np.fft.fft(x) * h)


@pytest.mark.parametrize("n", [512, 511, 2048])
@pytest.mark.parametrize("remove_mean", [True, False])
def test_analytic_signal_equals_the_fft_construction(n, remove_mean):
    rng = np.random.default_rng(n)
    x = 3.0 + rng.standard_normal(n) + np.cos(2 * np.pi * 23 * np.arange(n) / n)
    z = analytic_signal(x, remove_mean=remove_mean)
    ref = _analytic_by_fft_weights(x, remove_mean)
    scale = np.max(np.abs(x))
    assert np.max(np.abs(z - ref)) / scale <= 2e-15
    np.testing.assert_allclose(z.real, x - x.mean() if remove_mean else x, atol=2e-15 * scale)


def test_band_envelope_is_the_demodulation_band_signal():
    n = 2048
    th = 2 * np.pi * np.arange(n) / n
    x = (1.7 * (1 + 0.3 * np.cos(2 * th)) * np.cos(115 * th + 0.5 * np.sin(th))
         + 0.8 * np.cos(46 * th + 0.3) + 0.2 * np.cos(3 * th))
    dem = narrowband_demodulation(x, teeth=23, harmonic=5, bandwidth=11)
    z = band_analytic_signal(x, teeth=23, harmonic=5, bandwidth=11)
    np.testing.assert_array_equal(z, dem.analytic)
    np.testing.assert_array_equal(band_envelope(x, teeth=23, harmonic=5, bandwidth=11), dem.am)
    # the envelope of the design-note oracle: 1.7 (1 + 0.3 cos 2 theta) to ~1e-13
    np.testing.assert_allclose(dem.am, 1.7 * (1 + 0.3 * np.cos(2 * th)), atol=1e-12)


def test_one_kurtosis():
    rng = np.random.default_rng(5)
    x = rng.standard_normal(4096) ** 3
    assert signal_statistics(x).kurtosis == pytest.approx(kurtosis(x), rel=1e-14)
    th = 2 * np.pi * np.arange(1000) / 1000
    assert kurtosis(np.sin(3 * th)) == pytest.approx(1.5, rel=1e-12)
    with pytest.warns(DiagnosticsWarning, match="constant"):
        assert np.isnan(kurtosis(np.ones(10)))
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        assert np.isnan(kurtosis(np.ones(10), warn_constant=False))


def test_no_second_kurtosis_in_the_pipeline_or_sweep():
    """The pipeline and the sweep use the metrics kurtosis (no private copies)."""
    import geardyn.diagnostics.pipeline as pipeline
    import geardyn.studies.sweep.evaluate as evaluate

    assert not hasattr(pipeline, "_kurt")
    x = np.sin(np.linspace(0, 20, 500)) ** 3
    assert evaluate._kurt(x) == kurtosis(x)
