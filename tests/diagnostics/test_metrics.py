"""Statistics and condition metrics against closed forms and published values."""

from __future__ import annotations

import json
import math

import numpy as np
import pytest
from scipy import signal as ss
from scipy import stats

from geardyn.diagnostics import (
    DiagnosticsWarning,
    NA4Tracker,
    condition_metrics,
    difference,
    energy_ratio,
    fm0,
    fm4,
    kurtosis,
    m6a,
    m8a,
    na4,
    na4_star,
    narrowband_demodulation,
    nb4,
    regular,
    signal_statistics,
)
from geardyn.errors import InputError

N = 2048
TH = 2 * np.pi * np.arange(N) / N


def _triangle(periods=4, per_period=1 << 16):
    """Triangle wave, amplitude 1; its sample moments differ from the continuous ones by
    O(1/M^2) with M = per_period samples per period."""
    t = 2 * np.pi * np.arange(periods * per_period) / per_period
    return ss.sawtooth(t, width=0.5)


# ------------------------------------------------------------------------------------------
# statistics of known signals
# ------------------------------------------------------------------------------------------
def test_kurtosis_of_known_waveforms():
    assert kurtosis(np.sin(3 * TH)) == pytest.approx(1.5, abs=1e-12)
    assert kurtosis(ss.square(4 * TH)) == pytest.approx(1.0, abs=1e-12)
    tri = _triangle()
    assert kurtosis(tri) == pytest.approx(1.8, abs=1e-8)  # discretisation O(1/M^2)
    # scipy's Fisher kurtosis + 3 is the same Pearson definition
    assert kurtosis(tri) == pytest.approx(stats.kurtosis(tri, fisher=False), rel=1e-12)


def test_gaussian_moments():
    n = 1 << 20
    g = np.random.default_rng(2024).standard_normal(n)
    assert abs(kurtosis(g) - 3.0) < 4 * math.sqrt(24 / n)
    # sampling spreads of the 6th/8th normalised moments: sqrt((E x^12 - 15^2)/n) / 15 and
    # sqrt((E x^16 - 105^2)/n) / 105, i.e. about 0.7 % and 1.4 % here
    assert m6a(g) == pytest.approx(15.0, rel=4 * math.sqrt((10395 - 225) / n) / 15)
    assert m8a(g) == pytest.approx(105.0, rel=4 * math.sqrt((2027025 - 11025) / n) / 105)


def test_crest_factor_conventions_and_statistics():
    s = signal_statistics(3.0 + np.sin(5 * TH))
    assert s.mean == pytest.approx(3.0)
    assert s.std == pytest.approx(1 / math.sqrt(2), rel=1e-12)  # ddof 0
    assert s.skewness == pytest.approx(0.0, abs=1e-12)
    assert s.kurtosis == pytest.approx(1.5, abs=1e-12)
    assert s.crest_factor == pytest.approx(math.sqrt(2), rel=1e-12)  # max|x - mean| / std
    assert s.crest_factor_rms == pytest.approx(4.0 / math.sqrt(9.5), rel=1e-6)  # max|x| / rms
    assert s.rms == pytest.approx(math.sqrt(9.5), rel=1e-12)
    assert s.peak_to_peak == pytest.approx(2.0, rel=1e-6)
    tri = signal_statistics(_triangle())
    assert tri.crest_factor == pytest.approx(math.sqrt(3), rel=1e-8)
    assert tri.crest_factor_rms == pytest.approx(math.sqrt(3), rel=1e-8)
    # skewness: biased g1, compare with scipy (bias=True)
    x = np.random.default_rng(1).exponential(size=1000)
    assert signal_statistics(x).skewness == pytest.approx(stats.skew(x, bias=True), rel=1e-12)
    assert signal_statistics(x).std == pytest.approx(np.std(x, ddof=0), rel=1e-12)
    json.dumps(s.to_dict())


def test_sinusoid_m6a_m8a():
    assert m6a(np.sin(7 * TH)) == pytest.approx(2.5, abs=1e-12)
    assert m8a(np.sin(7 * TH)) == pytest.approx(4.375, abs=1e-12)
    assert fm4(np.sin(7 * TH)) == pytest.approx(1.5, abs=1e-12)


def test_constant_signal_warns_and_gives_nan():
    with pytest.warns(DiagnosticsWarning, match="zero variance"):
        s = signal_statistics(np.full(16, 2.0))
    assert math.isnan(s.kurtosis) and s.std == 0.0
    assert s.to_dict()["kurtosis"] is None
    with pytest.warns(DiagnosticsWarning):
        assert math.isnan(fm4(np.ones(8)))


# ------------------------------------------------------------------------------------------
# condition metrics
# ------------------------------------------------------------------------------------------
def test_fm0_of_a_single_mesh_tone_is_two():
    n = 46 * 40  # the crests and troughs of order 23 fall on samples
    th = 2 * np.pi * np.arange(n) / n
    assert fm0(np.cos(23 * th), teeth=23) == pytest.approx(2.0, abs=1e-12)
    # peak-to-peak over the sum of the mesh-harmonic peak amplitudes
    x = np.cos(23 * th) + 0.5 * np.cos(46 * th + 0.3) + 0.1 * np.cos(5 * th)
    assert fm0(x, teeth=23) == pytest.approx(np.ptp(x) / 1.5, rel=1e-12)
    assert fm0(x, teeth=23, mesh_harmonics=1) == pytest.approx(np.ptp(x), rel=1e-12)


def test_na4_history_values():
    expected = [1.5, 3.84, 5.579, 6.827, 7.748, 8.451, 9.004, 9.449, 9.814, 10.12]
    residuals = [(k / 3) * np.sin(10 * TH) for k in range(1, 11)]
    tracker = NA4Tracker()
    running = [tracker.update(r) for r in residuals]
    np.testing.assert_allclose(running, expected, atol=6e-3)
    # closed form: m4 = (3/8) a_M^4, mean m2 = mean(a_i^2)/2
    a = np.arange(1, 11) / 3
    closed = [(3 / 8) * a[m] ** 4 / (np.mean(a[: m + 1] ** 2) / 2) ** 2 for m in range(10)]
    np.testing.assert_allclose(running, closed, rtol=1e-12)
    # function form with the list of previous records
    assert na4(residuals[4], residuals[:4]) == pytest.approx(closed[4], rel=1e-12)
    assert na4(residuals[0]) == pytest.approx(kurtosis(residuals[0]), rel=1e-12)
    assert tracker.n_records == 10


def test_na4_star_uses_fixed_baseline():
    r = 2.0 * np.sin(10 * TH)
    # healthy variance 0.5 (amplitude 1): m4 = 3/8 * 16 = 6 -> 6 / 0.25
    assert na4_star(r, 0.5) == pytest.approx(24.0, rel=1e-12)
    with pytest.raises(InputError, match="baseline_variance"):
        na4_star(r, 0.0)


def test_energy_ratio_gaussian_over_sinusoid():
    rng = np.random.default_rng(8)
    sigma, amp = 0.3, 2.0
    d = sigma * rng.standard_normal(1 << 16)
    y = amp * np.sin(2 * np.pi * 23 * np.arange(1 << 16) / (1 << 16))
    expected = sigma / (amp / math.sqrt(2))
    # sampling error of the RMS of n Gaussian samples: 1/sqrt(2n) = 0.28 %
    assert energy_ratio(d, y) == pytest.approx(expected, rel=0.012)
    assert energy_ratio(d, y) == pytest.approx(np.std(d) / np.std(y), rel=2e-3)


def test_condition_metrics_consistency_and_names():
    rng = np.random.default_rng(3)
    x = (0.2 + np.cos(23 * TH) + 0.3 * np.cos(46 * TH + 1) + 0.1 * np.cos(TH)
         + 0.05 * np.cos(24 * TH) + 0.02 * rng.standard_normal(N))
    cm = condition_metrics(x, teeth=23)
    d = difference(x, teeth=23)
    y = regular(x, teeth=23)
    assert cm.FM4 == pytest.approx(kurtosis(d), rel=1e-12)
    assert cm.EnergyRatio == pytest.approx(np.sqrt(np.mean(d**2)) / np.sqrt(np.mean(y**2)))
    assert cm.RMS == pytest.approx(np.sqrt(np.mean(x**2)))
    assert cm.CrestFactor == pytest.approx(np.max(np.abs(x)) / cm.RMS)
    assert cm.Kurtosis == pytest.approx(kurtosis(x))
    assert math.isnan(cm.NA4star)
    keys = list(cm.to_dict())
    assert keys == ["RMS", "Kurtosis", "CrestFactor", "FM4", "M6A", "M8A", "FM0",
                    "EnergyRatio", "NA4", "NA4star", "NB4"]
    assert json.loads(json.dumps(cm.to_dict()))["NA4star"] is None
    # the difference of a Gaussian-noise-plus-regular TSA is Gaussian: FM4 ~ 3, M6A ~ 15
    assert cm.FM4 == pytest.approx(3.0, abs=0.5)
    cm2 = condition_metrics(x, teeth=23, na4_baseline_variance=1e-3)
    assert cm2.NA4star > 0
    # NB4 with one record = kurtosis of the band envelope
    assert cm.NB4 == pytest.approx(nb4(x, teeth=23), rel=1e-12)


def test_localised_pulse_raises_fm4_na4_and_pm_kurtosis_monotonically():
    """A fault on one tooth: a localised amplitude and phase modulation of every mesh harmonic,
    growing in size. FM4, NA4 and the PM kurtosis must all rise with it."""
    z = 23
    rng = np.random.default_rng(1)
    noise = 0.01 * rng.standard_normal(N)
    pulse = np.exp(-0.5 * ((TH - np.radians(170)) / (2 * np.pi / z / 4)) ** 2)  # one tooth
    amps = {1: 1.0, 2: 0.4, 3: 0.2, 4: 0.1, 5: 0.2}
    fm4s, na4s, pmk = [], [], []
    for a in [0.0, 0.02, 0.05, 0.1, 0.2]:
        x = sum(am * (1 + a * pulse) * np.cos(m * z * TH + 0.3 * m + a * pulse)
                for m, am in amps.items()) + 0.05 * np.cos(TH) + noise
        cm = condition_metrics(x, teeth=z, residual_preset="paper")
        fm4s.append(cm.FM4)
        na4s.append(cm.NA4)
        pmk.append(kurtosis(narrowband_demodulation(x, teeth=z).pm))
    for series in (fm4s, na4s, pmk):
        assert np.all(np.diff(series) > 0), series
    assert fm4s[0] == pytest.approx(3.0, abs=0.2)  # healthy: Gaussian difference signal
    assert fm4s[-1] > 10 and na4s[-1] > 5 and pmk[-1] > 5


def test_metric_input_errors():
    with pytest.raises(InputError, match="teeth"):
        condition_metrics(np.cos(TH), teeth=0)
    with pytest.raises(InputError, match="teeth"):
        fm0(np.cos(TH[:32]), teeth=23)
    with pytest.raises(InputError, match="d: .*index 1"):
        fm4([1.0, np.nan, 2.0])


@pytest.mark.parametrize("scale", [1e-200, 1e-9, 4.8e92, 1e300])
def test_moment_ratios_are_scale_invariant_without_overflow(scale):
    """Kurtosis, skewness, crest factor, FM4/M6A/M8A, NA4 and NA4* do not depend on the unit of
    the signal, and huge or tiny signals neither overflow nor underflow."""
    import warnings

    from geardyn.diagnostics import fm4, m6a, m8a, na4, na4_star, signal_statistics

    rng = np.random.default_rng(3)
    x = np.sin(np.linspace(0, 40, 2048)) + 0.3 * rng.standard_normal(2048)
    h = np.sin(np.linspace(0, 40, 2048))
    with warnings.catch_warnings():
        warnings.simplefilter("error")  # no RuntimeWarning (overflow) allowed
        a, b = signal_statistics(x), signal_statistics(scale * x)
        for f in (fm4, m6a, m8a):
            assert f(scale * x) == pytest.approx(f(x), rel=1e-12)
        assert na4(scale * x, [scale * h]) == pytest.approx(na4(x, [h]), rel=1e-12)
        v0 = float(np.var(h))
        if 1e-300 < scale * scale < 1e300:  # the baseline variance itself is representable
            assert na4_star(scale * x, v0 * scale * scale) == pytest.approx(na4_star(x, v0),
                                                                           rel=1e-12)
    for k in ("skewness", "kurtosis", "crest_factor", "crest_factor_rms"):
        assert getattr(b, k) == pytest.approx(getattr(a, k), rel=1e-12)
    assert b.std == pytest.approx(scale * a.std, rel=1e-12)
    assert b.mean == pytest.approx(scale * a.mean, rel=1e-12)
