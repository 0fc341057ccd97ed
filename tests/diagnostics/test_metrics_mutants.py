"""Condition metrics against closed-form decompositions; degenerate inputs; full messages.

Written against the mutants that survived the first mutation run of
``geardyn.diagnostics.metrics`` (docs/mutation.md). The TSA here is a sum of cosines of known
orders, so its regular, difference and residual signals and its band envelope are sums of
cosines known in closed form; each metric is then computed here from those sums with plain
NumPy moments (an independent second computation, no FFT).
"""

from __future__ import annotations

import math
import warnings

import numpy as np
import pytest

from geardyn.diagnostics import (
    DiagnosticsWarning,
    NA4Tracker,
    condition_metrics,
    energy_ratio,
    fm0,
    fm4,
    kurtosis,
    m6a,
    m8a,
    na4,
    na4_star,
    nb4,
    signal_statistics,
)
from geardyn.diagnostics.metrics import band_envelope, central_moment
from geardyn.errors import InputError

N = 256
TH = 2 * np.pi * np.arange(N) / N
Z = 10
# order -> (amplitude, phase); DC 0.5 is added separately
COMP = {1: (0.8, 0.1), 2: (0.4, 0.2), 3: (0.3, 0.3), 5: (0.25, 0.4), 8: (0.15, 1.1),
        9: (0.2, 0.5), 10: (2.0, 0.6), 11: (0.1, 0.7), 12: (0.12, 1.3), 15: (0.05, 0.8),
        17: (0.09, 0.35), 19: (0.07, 0.9), 20: (1.0, 1.0), 21: (0.06, 1.2), 30: (0.5, 1.4), 40: (0.3, 1.5)}
DC = 0.5


def _sum(orders, dc=0.0):
    """The cosines of ``orders`` (closed form), plus ``dc``."""
    return dc + sum(COMP[k][0] * np.cos(k * TH + COMP[k][1]) for k in orders if k in COMP)


def _env(lo, hi):
    """Envelope |sum A_k exp(i(k theta + phi_k))| over the orders lo..hi (closed form)."""
    return np.abs(sum(COMP[k][0] * np.exp(1j * (k * TH + COMP[k][1]))
                      for k in range(lo, hi + 1) if k in COMP))


def _m(v, k):
    return np.mean((v - v.mean()) ** k)


X = _sum(COMP, DC)
MESH = [10, 20, 30, 40, 50, 60, 70, 80, 90, 100, 110, 120]


def test_condition_metrics_defaults_against_closed_forms():
    cm = condition_metrics(X, teeth=Z)
    # y: shaft orders 1, 2 and every mesh harmonic; d: also the mean and first sidebands removed
    y = _sum([1, 2] + MESH)
    d = _sum([k for k in COMP if k not in (1, 2, 9, 11, 19, 21, 29, 31, 39, 41) + tuple(MESH)])
    # zakrajsek residual: mean, shaft orders 1, 2 and the mesh harmonics removed
    r = _sum([k for k in COMP if k not in (1, 2) + tuple(MESH)])
    env = _env(6, 14)  # NB4 band: Z +/- (Z - 1) // 2 = 10 +/- 4
    assert cm.RMS == pytest.approx(math.sqrt(np.mean(X**2)), rel=1e-12)
    assert cm.Kurtosis == pytest.approx(_m(X, 4) / _m(X, 2) ** 2, rel=1e-12)
    assert cm.CrestFactor == pytest.approx(np.max(np.abs(X)) / cm.RMS, rel=1e-12)
    assert cm.FM4 == pytest.approx(_m(d, 4) / _m(d, 2) ** 2, rel=1e-10)
    assert cm.M6A == pytest.approx(_m(d, 6) / _m(d, 2) ** 3, rel=1e-10)
    assert cm.M8A == pytest.approx(_m(d, 8) / _m(d, 2) ** 4, rel=1e-10)
    assert cm.FM0 == pytest.approx(np.ptp(X) / (2.0 + 1.0 + 0.5 + 0.3), rel=1e-12)
    assert cm.EnergyRatio == pytest.approx(math.sqrt(np.mean(d**2) / np.mean(y**2)), rel=1e-10)
    assert cm.NA4 == pytest.approx(_m(r, 4) / _m(r, 2) ** 2, rel=1e-10)
    assert math.isnan(cm.NA4star)
    assert cm.NB4 == pytest.approx(_m(env, 4) / _m(env, 2) ** 2, rel=1e-10)


def test_condition_metrics_options_are_passed_on():
    hist_r = [0.5 * np.sin(3 * TH), 0.7 * np.cos(5 * TH)]
    hist_e = [1.0 + 0.2 * np.cos(TH), 1.0 + 0.1 * np.sin(2 * TH)]
    cm = condition_metrics(X, teeth=Z, shaft_harmonics=3, mesh_harmonics=1, sidebands=2,
                           residual_preset="paper", residual_history=hist_r,
                           na4_baseline_variance=0.04, nb4_harmonic=2, nb4_bandwidth=2,
                           nb4_history=hist_e)
    y = _sum([1, 2, 3, 10])
    d = _sum([k for k in COMP if k not in (1, 2, 3, 8, 9, 10, 11, 12)])
    r = _sum([k for k in COMP if k not in MESH])  # paper: mean and mesh harmonics removed
    env = _env(18, 22)
    assert cm.FM4 == pytest.approx(_m(d, 4) / _m(d, 2) ** 2, rel=1e-10)
    assert cm.EnergyRatio == pytest.approx(math.sqrt(np.mean(d**2) / np.mean(y**2)), rel=1e-10)
    assert cm.FM0 == pytest.approx(np.ptp(X) / 2.0, rel=1e-12)
    m2 = np.mean([_m(h, 2) for h in hist_r] + [_m(r, 2)])
    assert cm.NA4 == pytest.approx(_m(r, 4) / m2**2, rel=1e-10)
    assert cm.NA4star == pytest.approx(_m(r, 4) / 0.04**2, rel=1e-10)
    m2e = np.mean([_m(h, 2) for h in hist_e] + [_m(env, 2)])
    assert cm.NB4 == pytest.approx(_m(env, 4) / m2e**2, rel=1e-10)


def test_condition_metrics_of_a_zero_record():
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", DiagnosticsWarning)
        cm = condition_metrics(np.zeros(64), teeth=4)
    assert cm.RMS == 0.0 and math.isnan(cm.CrestFactor)
    for name in ("Kurtosis", "FM4", "M6A", "M8A", "FM0", "EnergyRatio", "NA4", "NB4"):
        assert math.isnan(getattr(cm, name)), name


def test_condition_metrics_input_checks():
    with pytest.raises(InputError) as exc:
        condition_metrics(np.cos(TH), teeth=0)
    assert (exc.value.field, exc.value.value, exc.value.allowed) == (
        "teeth", 0, "a positive integer number of teeth")
    with pytest.raises(InputError) as exc:
        condition_metrics(np.cos(TH[:7]), teeth=1)
    assert exc.value.allowed == "at least 8 samples along the last axis"


# ------------------------------------------------------------------------------------------
# FM0
# ------------------------------------------------------------------------------------------
def test_fm0_mesh_harmonic_at_the_nyquist_order():
    # N = 20, Z = 10: the mesh order is N/2, whose amplitude is |X_k| / N (not 2 |X_k| / N)
    x = np.cos(np.pi * np.arange(20)) + 0.3 * np.cos(2 * np.pi * 3 * np.arange(20) / 20)
    assert fm0(x, teeth=10) == pytest.approx(np.ptp(x) / 1.0, rel=1e-12)
    # odd N = 21: order 10 is below N/2, amplitude 2 |X_k| / N
    k = np.arange(21)
    x = np.cos(2 * np.pi * 10 * k / 21)
    assert fm0(x, teeth=10) == pytest.approx(np.ptp(x), rel=1e-12)
    # DC does not count: it is not a mesh order
    assert fm0(x + 5.0, teeth=10) == pytest.approx(np.ptp(x), rel=1e-12)


def test_fm0_without_mesh_energy_and_bad_teeth():
    x = np.cos(3 * TH[:32 * 8:8])  # N = 32
    with pytest.warns(DiagnosticsWarning) as rec:
        assert math.isnan(fm0(np.zeros(32), teeth=10))  # no energy at orders 10, 20
    assert str(rec[0].message) == "fm0: no energy at the mesh harmonics; returning NaN"
    with pytest.raises(InputError) as exc:
        fm0(x, teeth=17)
    assert (exc.value.field, exc.value.value, exc.value.allowed) == (
        "teeth", 17, "a tooth count with its mesh order <= N/2 = 16")
    assert fm0(np.cos(16 * TH[:32 * 8:8]), teeth=16) == pytest.approx(2.0, rel=1e-12)
    with pytest.raises(InputError) as exc:
        fm0([1.0, 2.0, 3.0], teeth=1)
    assert exc.value.allowed == "at least 4 samples along the last axis"


# ------------------------------------------------------------------------------------------
# moments, statistics, constant records
# ------------------------------------------------------------------------------------------
def test_central_moment_and_kurtosis_closed_forms():
    v = np.array([1.0, 2.0, 4.0, 9.0])  # mean 4, deviations -3, -2, 0, 5
    assert central_moment(v, 2) == pytest.approx((9 + 4 + 0 + 25) / 4, rel=1e-15)
    assert central_moment(v, 3) == pytest.approx((-27 - 8 + 0 + 125) / 4, rel=1e-15)
    assert central_moment([7.0], 2) == 0.0
    assert kurtosis(v) == pytest.approx((81 + 16 + 625) / 4 / 9.5**2, rel=1e-14)
    assert fm4(v) == kurtosis(v)
    assert m6a(v) == pytest.approx((729 + 64 + 15625) / 4 / 9.5**3, rel=1e-14)
    assert m8a(v) == pytest.approx((6561 + 256 + 390625) / 4 / 9.5**4, rel=1e-14)
    with pytest.raises(InputError) as exc:
        kurtosis([1.0])
    assert exc.value.allowed == "at least 2 samples along the last axis"
    with pytest.raises(InputError) as exc:
        central_moment([], 2)
    assert exc.value.allowed == "at least 1 samples along the last axis"


@pytest.mark.parametrize(("func", "name"), [(kurtosis, "kurtosis"), (fm4, "fm4"),
                                            (m6a, "m6a"), (m8a, "m8a")])
def test_constant_record_message_names_the_metric(func, name):
    with pytest.warns(DiagnosticsWarning) as rec:
        assert math.isnan(func(np.full(8, 3.0)))
    assert [str(w.message) for w in rec] == [
        f"{name}: constant signal (zero variance, or a variation at the round-off of its "
        "values); returning NaN"]


def test_kurtosis_can_be_silent_for_a_constant_record():
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        assert math.isnan(kurtosis(np.zeros(8), warn_constant=False))
        assert math.isnan(kurtosis(np.full(8, -2.0), warn_constant=False))


def test_signal_statistics_closed_form():
    v = np.array([1.0, 2.0, 4.0, 9.0])
    s = signal_statistics(v)
    assert s.mean == pytest.approx(4.0, rel=1e-15)
    assert s.std == pytest.approx(math.sqrt(9.5), rel=1e-15)
    assert s.skewness == pytest.approx(22.5 / 9.5**1.5, rel=1e-14)
    assert s.kurtosis == pytest.approx(180.5 / 9.5**2, rel=1e-14)
    assert s.crest_factor == pytest.approx(5 / math.sqrt(9.5), rel=1e-14)
    assert s.crest_factor_rms == pytest.approx(9 / math.sqrt(25.5), rel=1e-14)
    assert s.rms == pytest.approx(math.sqrt(25.5), rel=1e-15)
    assert s.peak_to_peak == 8.0 and s.n == 4
    neg = signal_statistics(-v)  # max|x| from the negative side
    assert neg.mean == pytest.approx(-4.0) and neg.skewness == pytest.approx(-s.skewness)
    assert neg.crest_factor_rms == pytest.approx(s.crest_factor_rms, rel=1e-14)
    assert neg.std == pytest.approx(s.std, rel=1e-14)
    assert s.to_dict() == {"mean": s.mean, "std": s.std, "skewness": s.skewness,
                           "kurtosis": s.kurtosis, "crest_factor": s.crest_factor,
                           "crest_factor_rms": s.crest_factor_rms, "rms": s.rms,
                           "peak_to_peak": 8.0, "n": 4}


def test_signal_statistics_of_zero_and_constant_records():
    with pytest.warns(DiagnosticsWarning) as rec:
        s = signal_statistics(np.zeros(5))
    assert str(rec[0].message) == ("signal_statistics: constant signal (zero variance, or a "
                                   "variation at the round-off of its values); normalised "
                                   "statistics are NaN")
    assert (s.mean, s.std, s.rms, s.peak_to_peak, s.n) == (0.0, 0.0, 0.0, 0.0, 5)
    assert math.isnan(s.skewness) and math.isnan(s.kurtosis) and math.isnan(s.crest_factor)
    assert math.isnan(s.crest_factor_rms)
    with pytest.warns(DiagnosticsWarning):
        c = signal_statistics(np.full(3, -2.5))
    assert (c.mean, c.std, c.rms, c.crest_factor_rms) == (-2.5, 0.0, 2.5, 1.0)
    with pytest.raises(InputError) as exc:
        signal_statistics([1.0])
    assert exc.value.allowed == "at least 2 samples along the last axis"


# ------------------------------------------------------------------------------------------
# NA4, NA4*, NB4, energy ratio
# ------------------------------------------------------------------------------------------
def test_na4_with_history_of_other_lengths_and_zero_variance():
    r = np.array([0.0, 1.0, 0.0, -3.0])
    h = [np.array([2.0, -2.0]), np.array([1.0, 1.0, 1.0, 4.0, 1.0, 1.0])]
    m2 = np.mean([_m(r, 2), 4.0, _m(h[1], 2)])
    assert na4(r, h) == pytest.approx(_m(r, 4) / m2**2, rel=1e-14)
    assert na4(r, iter(h)) == pytest.approx(_m(r, 4) / m2**2, rel=1e-14)  # any iterable
    with pytest.warns(DiagnosticsWarning) as rec:
        assert math.isnan(na4(np.ones(4), [np.full(3, 2.0)]))
    assert str(rec[0].message) == "na4: zero residual variance; returning NaN"
    # a zero current residual with a non-zero history is 0, not NaN
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        assert na4(np.zeros(4), [np.array([1.0, -1.0])]) == 0.0
    with pytest.raises(InputError) as exc:
        na4(r, [np.array([1.0])])
    assert exc.value.field == "history"
    assert exc.value.allowed == "at least 2 samples along the last axis"


def test_na4_star_closed_form_and_limits():
    r = np.array([0.0, 1.0, 0.0, -3.0])
    assert na4_star(r, 2.0) == pytest.approx(_m(r, 4) / 4.0, rel=1e-14)
    assert na4_star(np.full(4, 7.0), 2.0) == 0.0  # zero residual
    assert na4_star(1e10 * r, 1e-320) == math.inf  # v0 is 0 in the scaled unit
    for bad in (0.0, -1.0, math.nan, math.inf):
        with pytest.raises(InputError) as exc:
            na4_star(r, bad)
        assert exc.value.field == "baseline_variance"
        assert exc.value.allowed == "a positive variance (u^2)"
    with pytest.raises(InputError) as exc:
        na4_star([1.0], 1.0)
    assert exc.value.field == "r"


def test_na4_star_tiny_scaled_baseline_is_infinite_not_an_error():
    """Found by mutation testing: v**2 underflowed to 0 and raised ZeroDivisionError."""
    # m4(r) / v0^2 = 11.06 / 1e-400 overflows: the float answer is inf
    assert na4_star(np.array([0.0, 1.0, 0.0, -3.0]), 1e-200) == math.inf


def test_na4_tracker_empty_and_constant():
    tr = NA4Tracker()
    assert tr.n_records == 0 and math.isnan(tr.mean_variance)
    assert math.isnan(tr.update(np.full(4, 2.0)))  # zero variance so far
    r = np.array([0.0, 1.0, 0.0, -3.0])
    assert tr.update(r) == pytest.approx(_m(r, 4) / (_m(r, 2) / 2) ** 2, rel=1e-14)
    assert tr.mean_variance == pytest.approx(_m(r, 2) / 2, rel=1e-15)
    assert tr.n_records == 2
    with pytest.raises(InputError):
        tr.update([1.0])
    assert tr.n_records == 2


def test_band_envelope_defaults_and_narrow_band():
    # default B = (Z - 1) // 2 = 4 about the first mesh harmonic
    np.testing.assert_allclose(band_envelope(X, teeth=Z), _env(6, 14), atol=1e-12)
    np.testing.assert_allclose(band_envelope(X, teeth=Z, harmonic=3, bandwidth=1),
                               _env(29, 31), atol=1e-12)
    np.testing.assert_allclose(band_envelope(X, teeth=Z, bandwidth=1), _env(9, 11), atol=1e-12)
    # Z = 2: (Z - 1) // 2 = 0 is raised to 1
    x = 1.0 * np.cos(2 * TH) + 0.5 * np.cos(3 * TH) + 0.25 * np.cos(TH)
    with pytest.warns(DiagnosticsWarning):  # 2B >= Z
        env = band_envelope(x, teeth=2)
    np.testing.assert_allclose(env, np.abs(np.exp(2j * TH) + 0.5 * np.exp(3j * TH)
                                           + 0.25 * np.exp(1j * TH)), atol=1e-12)
    assert nb4(X, teeth=Z) == pytest.approx(_m(_env(6, 14), 4) / _m(_env(6, 14), 2) ** 2,
                                            rel=1e-10)


def test_energy_ratio_closed_form_and_zero_regular():
    assert energy_ratio([3.0, -4.0], [1.0, 1.0, -1.0, -1.0]) == pytest.approx(
        math.sqrt(12.5), rel=1e-15)
    assert energy_ratio([2.0], [4.0]) == 0.5  # one sample each is enough
    with pytest.warns(DiagnosticsWarning) as rec:
        assert math.isnan(energy_ratio([1.0, 2.0], [0.0, 0.0]))
    assert str(rec[0].message) == "energy_ratio: zero regular signal; returning NaN"
    with pytest.raises(InputError) as exc:
        energy_ratio([1.0], [])
    assert exc.value.field == "y"


def test_warnings_point_at_the_caller():
    # mutmut's trampoline adds a stack frame, so the caller's line is checked outside mutmut only
    import os

    with warnings.catch_warnings(record=True) as rec:
        warnings.simplefilter("always")
        kurtosis(np.ones(4))
        fm4(np.ones(4))
        m6a(np.ones(4))
        m8a(np.ones(4))
        signal_statistics(np.ones(4))
        fm0(np.zeros(8), teeth=2)
        na4(np.ones(4))
        energy_ratio([1.0], [0.0])
    assert [w.category for w in rec] == [DiagnosticsWarning] * 8
    if "MUTANT_UNDER_TEST" not in os.environ:
        assert [w.filename for w in rec] == [__file__] * 8


# ------------------------------------------------------------------------------------------
# second round: minimum sizes, field names, huge values, odd tooth counts
# ------------------------------------------------------------------------------------------
@pytest.mark.parametrize(("func", "field", "minimum"), [
    (central_moment, "x", 1), (kurtosis, "x", 2), (signal_statistics, "x", 2),
    (fm4, "d", 2), (m6a, "d", 2), (m8a, "d", 2), (na4, "r", 2)])
def test_minimum_sizes_and_fields(func, field, minimum):
    args = (2,) if func is central_moment else ()
    with pytest.raises(InputError) as exc:
        func(np.ones(minimum - 1), *args)
    assert (exc.value.field, exc.value.allowed) == (
        field, f"at least {minimum} samples along the last axis")
    v = np.array([1.0, 3.0])  # the smallest record accepted
    if func is central_moment:
        assert func(v[:1], 2) == 0.0
    elif func is signal_statistics:
        assert func(v).kurtosis == pytest.approx(1.0, rel=1e-15)
    else:  # two points: every even normalised moment is 1
        assert func(v) == pytest.approx(1.0, rel=1e-15)


def test_minimum_sizes_of_the_other_metrics():
    assert fm0(np.array([1.0, -1.0, 1.0, -1.0]), teeth=2) == pytest.approx(2.0, rel=1e-15)
    with pytest.raises(InputError) as exc:
        fm0([1.0, 2.0, 3.0], teeth=1)
    assert exc.value.field == "x"
    assert na4_star([1.0, 3.0], 1.0) == pytest.approx(1.0, rel=1e-15)  # m4 = 1, v0 = 1
    tr = NA4Tracker()
    assert tr.update([1.0, 3.0]) == pytest.approx(1.0, rel=1e-15)
    with pytest.raises(InputError) as exc:
        tr.update([1.0])
    assert exc.value.field == "r"
    with pytest.raises(InputError) as exc:
        energy_ratio([], [1.0])
    assert exc.value.field == "d"
    with pytest.raises(InputError) as exc:
        na4_star(np.ones(4), -2.0)
    assert exc.value.value == -2.0


def test_fm0_counts_order_one_at_twice_its_bin():
    th = 2 * np.pi * np.arange(32) / 32
    assert fm0(np.cos(th), teeth=1, mesh_harmonics=1) == pytest.approx(2.0, rel=1e-12)


def test_condition_metrics_smallest_record_and_one_tooth():
    th = 2 * np.pi * np.arange(8) / 8
    x = np.cos(th) + 0.3 * np.cos(2 * th)
    with warnings.catch_warnings(record=True) as rec:  # the difference signal is empty
        warnings.simplefilter("always")
        cm = condition_metrics(x, teeth=2)
    assert any("overlaps" in str(w.message) for w in rec)  # NB4 band 2 +/- 1 (2B >= Z)
    # N = 8, Z = 2: mesh orders 2 and 4 (Nyquist, no energy)
    assert cm.FM0 == pytest.approx(np.ptp(x) / 0.3, rel=1e-12)
    with pytest.raises(InputError) as exc:
        condition_metrics(x[:7], teeth=2)
    assert exc.value.field == "x"
    # refused before any metric is computed (no constant-signal warning first)
    with warnings.catch_warnings(), pytest.raises(InputError) as exc:
        warnings.simplefilter("error")
        condition_metrics(np.ones(7), teeth=2)
    assert exc.value.allowed == "at least 8 samples along the last axis"
    # Z = 1 passes the tooth-count check; it is the NB4 band 1 +/- 1 (touching the mean) that
    # refuses it
    with pytest.raises(InputError) as exc, warnings.catch_warnings():
        warnings.simplefilter("ignore", DiagnosticsWarning)  # difference signal empty
        condition_metrics(np.cos(2 * np.pi * np.arange(16) / 16), teeth=1)
    assert exc.value.field == "bandwidth"
    # reaches order 0
    assert exc.value.allowed.startswith("a band 1+/-B (mesh harmonic 1 x 1 teeth) inside orders "
                                        "1..7")


def test_moments_of_values_near_the_float_limit():
    x = np.sin(np.linspace(0, 7, 512)) + 0.2 * np.cos(np.linspace(0, 31, 512))
    # 1e307 * x: the sum behind a plain mean would overflow; the scaled moments do not
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        assert kurtosis(1e307 * x) == pytest.approx(kurtosis(x), rel=1e-12)
        assert fm4(1e307 * x) == pytest.approx(fm4(x), rel=1e-12)


def test_band_envelope_default_width_for_an_odd_tooth_count():
    z = 11  # default B = (11 - 1) // 2 = 5: orders 6 .. 16
    x = sum(np.cos(k * TH + 0.1 * k) for k in (5, 6, 11, 16, 17))
    np.testing.assert_allclose(band_envelope(x, teeth=z),
                               np.abs(sum(np.exp(1j * (k * TH + 0.1 * k)) for k in (6, 11, 16))),
                               atol=1e-12)
