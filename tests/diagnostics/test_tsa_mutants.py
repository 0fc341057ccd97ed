"""TSA: input checks with their full texts, bounds at the bound, kernels against closed forms.

Written against the mutants that survived the first mutation run of
``geardyn.diagnostics.tsa`` (docs/mutation.md). Errors are compared field by field with their
full texts; bounds are tried at the bound (accepted) and just beyond (refused); the resampling
and the anti-alias filter are compared with polynomials and tones whose averages are known in
closed form.
"""

from __future__ import annotations

import math
import warnings

import numpy as np
import pytest

from geardyn.diagnostics import DiagnosticsWarning, angle_from_tach, tach_pulse_times, tsa
from geardyn.diagnostics.tsa import (
    _as_float_array,
    _check_angle,
    _check_int,
    _lowpass_decimate,
    _resample,
    _resample_numpy,
    _sample_times,
    _short,
)
from geardyn.errors import InputError

TWO_PI = 2 * np.pi


def _err(func, *args, **kwargs) -> InputError:
    with pytest.raises(InputError) as exc:
        func(*args, **kwargs)
    return exc.value


def _theta(n_rev, per_rev, extra=3, start=0.0):
    n = int(round(n_rev * per_rev)) + extra
    return start + TWO_PI * np.arange(n) / per_rev


# ------------------------------------------------------------------------------------------
# shared validation helpers
# ------------------------------------------------------------------------------------------
def test_as_float_array_texts():
    e = _err(_as_float_array, ["a", "b"], "sig")
    assert (e.field, e.value, e.allowed) == ("sig", "['a', 'b']", "a real numeric array")
    e = _err(_as_float_array, np.ones((2, 3)), "sig")
    assert (e.field, e.value, e.allowed) == ("sig", "array of shape (2, 3)",
                                             "an array with 1 dimension(s)")
    e = _err(_as_float_array, np.ones((2, 2, 2)), "sig", ndim=(1, 2))
    assert e.allowed == "an array with 1 or 2 dimension(s)"
    e = _err(_as_float_array, 3.0, "sig", ndim=(0, 1))
    assert (e.field, e.value, e.allowed) == ("sig", "array of shape ()",
                                             "at least 1 samples along the last axis")
    e = _err(_as_float_array, [1.0, 2.0], "sig", min_size=3)
    assert (e.field, e.value, e.allowed) == ("sig", "array of shape (2,)",
                                             "at least 3 samples along the last axis")
    # the size checked is the last axis
    e = _err(_as_float_array, np.ones((5, 2)), "sig", ndim=(2,), min_size=3)
    assert e.value == "array of shape (5, 2)"
    out = _as_float_array(np.ones((2, 3), dtype=np.int32), "sig", ndim=(2,), min_size=3)
    assert out.dtype == np.float64 and out.shape == (2, 3)
    assert _as_float_array([7], "sig").tolist() == [7.0]  # default min_size 1
    e = _err(_as_float_array, [], "sig")
    assert e.allowed == "at least 1 samples along the last axis"


def test_non_finite_texts_1d_and_2d():
    e = _err(_as_float_array, [1.0, 2.0, np.inf, np.nan], "sig")
    assert (e.field, e.value) == ("sig", "non-finite value inf at index 2")
    assert e.allowed == "finite numbers only (no NaN or inf); trim or repair the record"
    e = _err(_as_float_array, [[1.0, 2.0], [np.nan, 3.0]], "sig", ndim=(2,))
    assert e.value == "non-finite value nan at index (1, 0)"


def test_short_repr_cut_at_60_characters():
    assert _short("a" * 58) == repr("a" * 58)  # 60 characters with the quotes
    assert _short("a" * 59) == repr("a" * 59)[:57] + "..."
    assert len(_short("a" * 59)) == 60


def test_check_int_bound_and_types():
    assert _check_int(8, "n", 8) == 8
    assert type(_check_int(np.int64(9), "n", 8)) is int
    for bad in (7, True, 8.0, "8"):
        e = _err(_check_int, bad, "n", 8)
        assert (e.field, e.value, e.allowed) == ("n", bad, "an integer >= 8")
    assert _err(_check_int, 0, "n", 1, "a count").allowed == "a count"


def test_check_angle_texts():
    e = _err(_check_angle, np.array([1.0]), "ang", False)
    assert (e.field, e.value, e.allowed) == ("ang", "a single sample", "at least 4 samples")
    ang, d = _check_angle(np.array([0.0, 1e-3, 2.0, 2.5]), "ang", False)
    np.testing.assert_allclose(d, [1e-3, 1.999, 0.5])
    e = _err(_check_angle, np.array([0.0, 1.0, 3.0, 2.0, 1.5]), "ang", False)
    assert e.value == "non-monotonic angle: angle[3] - angle[2] = -1 rad"
    assert e.allowed == "a strictly increasing (unwrapped) shaft angle"
    e = _err(_check_angle, -np.arange(5.0), "ang", False)
    assert e.value == "non-monotonic angle: angle[1] - angle[0] = -1 rad"
    assert e.allowed == ("a strictly increasing shaft angle; for reverse rotation pass -angle "
                         "(and expect orders to be mirrored)")
    # a zero step is not "all decreasing": the plain text
    e = _err(_check_angle, np.array([0.0, 0.0, 1.0, 2.0]), "ang", False)
    assert e.value == "non-monotonic angle: angle[1] - angle[0] = 0 rad"
    assert e.allowed == "a strictly increasing (unwrapped) shaft angle"
    # a wrapped angle: a jump within 0.5 rad of -2 pi
    wrapped = np.mod(np.arange(30) * 0.3, TWO_PI)  # jumps by 0.3 - 2 pi once
    e = _err(_check_angle, wrapped, "ang", False)
    assert e.allowed == ("a strictly increasing (unwrapped) shaft angle; this one jumps by "
                         "about -2*pi: it looks wrapped (unwrap it: tsa(unwrap=True), "
                         "diagnose_file(unwrap_angle=True), geardyn diagnose --unwrap-angle)")
    # a jump of -(2 pi - 0.6) is not taken for a wrap; -(2 pi - 0.4) is
    e = _err(_check_angle, np.array([0.0, 1.0, 1.0 - (TWO_PI - 0.6), 3.0]), "ang", False)
    assert e.allowed == "a strictly increasing (unwrapped) shaft angle"
    e = _err(_check_angle, np.array([0.0, 1.0, 1.0 - (TWO_PI - 0.4), 3.0]), "ang", False)
    assert e.allowed.endswith("geardyn diagnose --unwrap-angle)")
    # unwrap=True repairs the wrap; a small backward step after unwrapping gets the plain text
    ang, _ = _check_angle(wrapped, "ang", True)
    np.testing.assert_allclose(ang, np.arange(30) * 0.3, atol=1e-12)
    e = _err(_check_angle, np.array([0.0, 1.0, 0.8, 3.0]), "ang", True)
    assert e.allowed == "a strictly increasing (unwrapped) shaft angle"


# ------------------------------------------------------------------------------------------
# sample times and tachometer
# ------------------------------------------------------------------------------------------
def test_sample_times_texts_and_types():
    np.testing.assert_allclose(_sample_times(4, 2.0, None), [0.0, 0.5, 1.0, 1.5], atol=0)
    np.testing.assert_allclose(_sample_times(3, np.int64(4), None), [0.0, 0.25, 0.5], atol=0)
    np.testing.assert_allclose(_sample_times(3, np.float32(4.0), None), [0.0, 0.25, 0.5])
    t = np.array([0.0, 0.1, 0.3])
    assert _sample_times(3, 99.0, t).tolist() == t.tolist()  # time wins over fs
    e = _err(_sample_times, 4, None, t)
    assert (e.field, e.value, e.allowed) == ("time", "3 samples", "4 samples, like the signal")
    e = _err(_sample_times, 3, None, [0.0, 0.2, 0.2])
    assert (e.field, e.value, e.allowed) == ("time", "non-increasing sample times",
                                             "strictly increasing times")
    e = _err(_sample_times, 3, None, [0.0])
    assert e.allowed == "at least 2 samples along the last axis"
    e = _err(_sample_times, 3, None, None)
    assert (e.field, e.value, e.allowed) == ("fs", None, "a sample rate in Hz (or pass time=)")
    for bad in (0.0, -1.0, math.inf, math.nan, "100"):
        e = _err(_sample_times, 3, bad, None)
        assert e.field == "fs" and e.allowed == "a positive finite sample rate in Hz"


def test_tach_pulse_times_threshold_bounds_and_texts():
    s = np.array([0.0, 0.0, 1.0, 1.0, 0.0, 0.5, 1.0, 0.0])
    t = tach_pulse_times(s, fs=10.0, threshold=1.0)  # c = max: accepted, crossings reach it
    np.testing.assert_allclose(t, [0.2, 0.6], atol=1e-15)
    e = _err(tach_pulse_times, s, fs=10.0, threshold=0.0)  # c = min: refused
    assert (e.field, e.value) == ("threshold", 0.0)
    assert e.allowed == "a level between the tach minimum 0 and maximum 1"
    assert _err(tach_pulse_times, s, fs=10.0, threshold=1.5).field == "threshold"
    # linear interpolation between the two samples around the crossing
    np.testing.assert_allclose(tach_pulse_times(s, fs=10.0, threshold=0.25), [0.125, 0.45],
                               atol=1e-15)
    # default threshold midway between min and max (here 1.5 .. 3.5: c = 2.5)
    s2 = np.array([1.5, 2.0, 3.0, 3.5, 1.5, 3.5])
    np.testing.assert_allclose(tach_pulse_times(s2, time=[0, 1, 2, 3, 4, 5]), [1.5, 4.5])
    e = _err(tach_pulse_times, [1.0], fs=1.0)
    assert (e.field, e.allowed) == ("tach", "at least 2 samples along the last axis")


def test_tach_min_interval_keeps_edges_at_exactly_the_interval():
    s = np.tile([0.0, 0.5, 1.0, 0.5], 4)  # resolved edges, crossing of 0.5 at 1, 5, 9, 13
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        np.testing.assert_allclose(tach_pulse_times(s, fs=1.0, threshold=0.5), [1, 5, 9, 13])
        np.testing.assert_allclose(tach_pulse_times(s, fs=1.0, threshold=0.5,
                                                    min_interval=4.0), [1, 5, 9, 13])
        np.testing.assert_allclose(tach_pulse_times(s, fs=1.0, threshold=0.5,
                                                    min_interval=4.5), [1, 9])
        # a single edge: min_interval is not even checked
        assert tach_pulse_times(s[:4], fs=1.0, threshold=0.5, min_interval=-1.0).size == 1
    for bad in (0.0, -1.0, math.nan):
        e = _err(tach_pulse_times, s, fs=1.0, threshold=0.5, min_interval=bad)
        assert e.field == "min_interval" and e.allowed == "a positive time in s"


def test_unresolved_edge_warning_majority_rule_and_text():
    # 2 of 3 edges jump from the low to the high level in one sample: warned
    s = np.array([0, 0, 1, 1, 0, 0, 1, 1, 0, 0.5, 1, 1], dtype=float)
    with pytest.warns(DiagnosticsWarning) as rec:
        tach_pulse_times(s, fs=1.0)
    assert str(rec[0].message) == (
        "tach edges are not resolved by the sampling (2 of 3 rising edges jump from one level "
        "to the other between two samples): each pulse time is known only to +/- half a "
        "sample, which lowers the TSA amplitude of an order at f cycles per sample by about "
        "1 - sinc(f) (0.8 % at 0.07 fs, 1.6 % at 0.1 fs) when the pulses fall anywhere within "
        "the sample intervals, and by more when the speed is locked to the sample rate (a "
        "whole number of samples per pulse repeats the same error in every revolution). "
        "Record the tach through the anti-alias filter, or give counter time stamps of the "
        "pulses.")
    # 1 of 2 (not more than half): silent
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        tach_pulse_times(s[4:], fs=1.0)
        # levels within 2 % of the range count as low/high: 0.015 and 0.985 are not "part-way"
        s3 = np.array([0, 0.03, 0.97, 1, 0, 0.03, 0.97, 1])
        tach_pulse_times(s3, fs=1.0)
    s4 = np.array([0, 0.015, 0.985, 1, 0, 0.015, 0.985, 1])
    with pytest.warns(DiagnosticsWarning, match="2 of 2 rising edges"):
        tach_pulse_times(s4, fs=1.0)


def test_no_edges_is_an_empty_result():
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        out = tach_pulse_times(np.array([1.0, 0.5, 0.0, 0.0]), fs=1.0)
    assert out.shape == (0,)


# ------------------------------------------------------------------------------------------
# angle from the tachometer
# ------------------------------------------------------------------------------------------
def test_angle_from_tach_is_exact_for_a_cubic_angle_law():
    # the not-a-knot spline reproduces any cubic phi(t) through the pulses exactly
    def phi(t):
        return 2.0 * t + 0.3 * t**2 + 0.05 * t**3

    t_s = np.linspace(0.0, 6.0, 601)
    tp = []
    for k in range(4):  # pulses at phi = 2 pi k / P, P = 2
        lo, hi = 0.0, 10.0
        for _ in range(200):
            mid = 0.5 * (lo + hi)
            lo, hi = (mid, hi) if phi(mid) < np.pi * k else (lo, mid)
        tp.append(0.5 * (lo + hi))
    tp = np.array(tp)
    ang = angle_from_tach(tp, t_s, pulses_per_rev=2)
    inside = (t_s >= tp[0] - 2 * 0.01) & (t_s <= tp[-1] + 2 * 0.01)
    np.testing.assert_allclose(ang[inside], phi(t_s[inside]), atol=1e-9)
    # two sample intervals of slack after the last pulse, NaN beyond
    assert np.all(np.isnan(ang[~inside])) and np.count_nonzero(~inside) > 10


def test_angle_from_tach_single_sample_and_errors():
    out = angle_from_tach([0.0, 1.0, 2.0], [1.5])
    np.testing.assert_allclose(out, [1.5 * TWO_PI])
    assert np.isnan(angle_from_tach([0.0, 1.0, 2.0], [2.001])[0])  # dt = 0: no slack
    e = _err(angle_from_tach, [0.0, 1.0, 1.0], [0.5])
    assert (e.field, e.value, e.allowed) == ("tach_times", "non-increasing pulse times",
                                             "strictly increasing pulse times in s")
    e = _err(angle_from_tach, [0.0, 1.0], [0.5], pulses_per_rev=0)
    assert (e.field, e.value, e.allowed) == ("pulses_per_rev", 0, "an integer >= 1")
    e = _err(angle_from_tach, [0.0], [0.5])
    assert (e.field, e.allowed) == ("tach_times", "at least 2 samples along the last axis")
    np.testing.assert_allclose(angle_from_tach([0.0, 1.0], [0.5]), [np.pi])  # 2 pulses


def test_pulse_regularity_warning_bounds_and_text():
    t = np.linspace(0.0, 1.0, 11)
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        angle_from_tach([0.0, 1.0, 2.5, 4.0], t)  # ratio 1.5: accepted
        angle_from_tach([0.0, 1.5, 2.5, 3.5], t)  # ratio 1/1.5: accepted
        angle_from_tach([0.0, 3.0], t)  # two pulses: no interval ratio to check
    with pytest.warns(DiagnosticsWarning, match="factor 3 at pulse 1 "):
        angle_from_tach([0.0, 1.0, 4.0], t)  # three pulses are checked
    with pytest.warns(DiagnosticsWarning) as rec:
        angle_from_tach([0.0, 1.0, 2.0, 3.6, 4.6], t)
    assert str(rec[0].message) == (
        "tach pulse interval changes by a factor 1.6 at pulse 2 (t = 2 s): a missing or "
        "spurious pulse? The angle spline assumes one pulse per 1/pulses_per_rev revolution.")
    with pytest.warns(DiagnosticsWarning, match="factor 0.6 at pulse 3 "):
        angle_from_tach([0.0, 1.0, 2.0, 3.0, 3.6], t)


# ------------------------------------------------------------------------------------------
# resampling kernel and anti-alias filter
# ------------------------------------------------------------------------------------------
def _lagrange_reference(angle, x, th, taps):
    """Lagrange interpolation of x(angle) at th on the ``taps`` samples centred on the interval
    holding th (shifted inwards at the record ends), by scipy's barycentric interpolator."""
    from scipy.interpolate import BarycentricInterpolator

    n = angle.size
    out = np.empty(th.size)
    for k, t in enumerate(th):
        i = int(np.searchsorted(angle, t, side="right")) - 1
        s = min(max(i - (taps // 2 - 1), 0), n - taps)
        out[k] = BarycentricInterpolator(angle[s:s + taps], x[s:s + taps])(t)
    return out


@pytest.mark.parametrize("taps", [4, 6, 8])
def test_resample_numpy_against_barycentric_lagrange(taps):
    rng = np.random.default_rng(taps)
    n = 40
    angle = np.cumsum(rng.uniform(0.5, 1.5, n)) * 0.1
    x = np.stack([np.sin(3 * angle) + angle, np.cos(5 * angle)])
    theta0, dtheta, n_points = angle[0] - 0.05, 0.0371, 110  # up to beyond both ends
    out = np.zeros((2, n_points))
    _resample_numpy(angle, x, theta0, dtheta, n_points, 7, False, out, chunk=13, taps=taps)
    th = theta0 + np.arange(n_points) * dtheta
    for c in range(2):
        np.testing.assert_allclose(out[c], _lagrange_reference(angle, x[c], th, taps),
                                   rtol=1e-9, atol=1e-9)
    # accumulating into a period of 7 folds j modulo 7, across chunk boundaries, and adds to
    # what is already in ``out``
    acc = np.ones((2, 7))
    _resample_numpy(angle, x, theta0, dtheta, n_points, 7, True, acc, chunk=13, taps=taps)
    folded = np.ones((2, 7))
    for j in range(n_points):
        folded[:, j % 7] += out[:, j]
    np.testing.assert_allclose(acc, folded, rtol=1e-12, atol=1e-12)


def test_resample_numpy_default_is_six_points():
    rng = np.random.default_rng(1)
    angle = np.cumsum(rng.uniform(0.5, 1.5, 30)) * 0.1
    x = np.sin(4 * angle)[None, :]
    out = np.zeros((1, 20))
    _resample_numpy(angle, x, angle[3], 0.11, 20, 20, False, out)
    th = angle[3] + 0.11 * np.arange(20)
    np.testing.assert_allclose(out[0], _lagrange_reference(angle, x[0], th, 6), rtol=1e-10)


@pytest.mark.parametrize("engine", ["numpy", "numba", "auto"])
def test_resample_dispatch_and_short_records(engine):
    # 5 samples: the stencil shrinks to 2 * (5 // 2) = 4 points (a cubic is still exact)
    angle = np.array([0.0, 0.9, 2.1, 3.0, 4.2])
    poly = np.array([0.1, -0.4, 0.7, 2.0])
    x = np.stack([np.polyval(poly, angle), 2 * np.polyval(poly, angle)])
    th = 0.2 + 0.5 * np.arange(7)
    out = _resample(angle, x, 0.2, 0.5, 7, 3, False, engine)
    np.testing.assert_allclose(out, np.stack([np.polyval(poly, th), 2 * np.polyval(poly, th)]),
                               rtol=1e-12)
    acc = _resample(angle, x, 0.2, 0.5, 7, 3, True, engine)
    assert acc.shape == (2, 3) and acc.dtype == np.float64
    np.testing.assert_allclose(acc[0], [np.polyval(poly, th[[0, 3, 6]]).sum(),
                                        np.polyval(poly, th[[1, 4]]).sum(),
                                        np.polyval(poly, th[[2, 5]]).sum()], rtol=1e-12)
    # 6 samples: a quintic is exact with the default 6 points, not with 4
    angle6 = np.r_[angle, 5.1]
    q = np.array([0.01, -0.05, 0.1, 0.1, -0.4, 1.0])
    x6 = np.polyval(q, angle6)[None, :]
    out6 = _resample(angle6, x6, 0.3, 0.6, 8, 8, False, engine)
    np.testing.assert_allclose(out6[0], np.polyval(q, 0.3 + 0.6 * np.arange(8)), rtol=1e-11)
    out4 = _resample(angle6, x6, 0.3, 0.6, 8, 8, False, engine, taps=4)
    assert np.max(np.abs(out4[0] - np.polyval(q, 0.3 + 0.6 * np.arange(8)))) > 1e-3


@pytest.mark.parametrize(("n_out", "kept", "removed"), [(8, [0, 1, 3], [4, 5, 9]),
                                                        (9, [0, 2, 4], [5, 6])])
def test_lowpass_decimate_keeps_orders_strictly_below_half_n(n_out, kept, removed):
    m = 4 * n_out
    th = TWO_PI * np.arange(m) / m
    amps = {k: 1.0 + 0.1 * k for k in kept + removed}
    y = np.stack([sum(a * np.cos(k * th + 0.3 * k) for k, a in amps.items()),
                  sum(a * np.sin(k * th) for k, a in amps.items())])
    out = _lowpass_decimate(y[None, :, :], n_out)  # (1, 2, m): works along the last axis
    th_o = TWO_PI * np.arange(n_out) / n_out
    truth0 = sum(amps[k] * np.cos(k * th_o + 0.3 * k) for k in kept)
    truth1 = sum(amps[k] * np.sin(k * th_o) for k in kept)
    assert out.shape == (1, 2, n_out)
    np.testing.assert_allclose(out[0, 0], truth0, atol=1e-12)
    np.testing.assert_allclose(out[0, 1], truth1, atol=1e-12)
    same = np.arange(float(n_out))[None, :]
    assert _lowpass_decimate(same, n_out) is same


# ------------------------------------------------------------------------------------------
# tsa(): revolution bookkeeping, oversampling, options, texts
# ------------------------------------------------------------------------------------------
def _poly_average(poly, theta_s, n_rev, nper):
    """Closed-form TSA of a polynomial in angle: mean over r of p(theta_s + 2 pi r + 2 pi n/N)."""
    grid = theta_s + TWO_PI * np.arange(n_rev)[:, None] + TWO_PI * np.arange(nper)[None, :] / nper
    return np.polyval(poly, grid).mean(axis=0)


@pytest.mark.parametrize(("taps", "degree"), [(4, 3), (6, 5), (8, 7)])
def test_interpolant_order_is_passed_through(taps, degree):
    rng = np.random.default_rng(degree)
    angle = np.cumsum(rng.uniform(0.6, 1.4, 60)) * (TWO_PI * 3.2 / 60)
    poly = rng.uniform(-1, 1, degree + 1) * 0.2 ** np.arange(degree + 1)[::-1]
    for eng in ("numpy", "numba"):
        res = tsa(np.polyval(poly, angle), angle=angle, samples_per_rev=16, antialias=False,
                  interp_points=taps, engine=eng)
        ref = _poly_average(poly, res.start_angle, res.n_averages, 16)
        np.testing.assert_allclose(res.average, ref, rtol=1e-9, atol=1e-9)
    if taps < 8:  # one degree more is not exact
        higher = np.r_[0.3 * 0.2 ** (degree + 1), poly]
        res = tsa(np.polyval(higher, angle), angle=angle, samples_per_rev=16, antialias=False,
                  interp_points=taps, engine="numpy")
        ref = _poly_average(higher, res.start_angle, res.n_averages, 16)
        assert np.max(np.abs(res.average - ref)) > 1e-9


@pytest.mark.parametrize(("n", "expected"), [(192, 3), (191, 2)])
def test_last_revolution_needs_the_record_within_half_a_sample(n, expected):
    theta = TWO_PI * np.arange(n) / 64  # one raw sample per output sample: no oversampling
    res = tsa(np.cos(theta), angle=theta, samples_per_rev=64, min_revolutions=1)
    assert res.n_averages == expected and res.oversampling == 1
    assert res.start_angle == 0.0


@pytest.mark.parametrize(("shift", "start"), [(-0.4, 0.0), (0.4, 0.0), (0.6, TWO_PI)])
def test_first_revolution_may_start_half_a_sample_before_the_record(shift, start):
    step = TWO_PI / 64
    theta = (np.arange(64 * 4) + shift) * step
    res = tsa(np.cos(3 * theta), angle=theta, samples_per_rev=64)
    assert res.start_angle == pytest.approx(start, abs=1e-12)
    # the first revolution is extrapolated up to half a raw sample: about 1e-5 error
    np.testing.assert_allclose(res.average, np.cos(3 * res.angle), atol=1e-4)


def test_end_slack_uses_the_smaller_of_the_first_and_last_steps():
    step = TWO_PI / 64
    # first step 4 samples wide, last step normal: the start slack is half a *normal* step,
    # so a record starting 0.7 sample after angle 0 starts its first revolution at 2 pi
    theta = np.r_[0.7 * step, (np.arange(4, 64 * 4) + 0.7) * step]
    res = tsa(np.cos(theta), angle=theta, samples_per_rev=64, antialias=False)
    assert res.start_angle == pytest.approx(TWO_PI) and res.n_averages == 3
    # last step 4.3 samples wide: the record ends 1.7 samples before 3 revolutions; with
    # half a normal step of slack only 2 whole revolutions fit
    theta2 = np.r_[np.arange(187) * step, (192 - 1.7) * step]
    res2 = tsa(np.cos(theta2), angle=theta2, samples_per_rev=64, antialias=False)
    assert res2.start_angle == 0.0 and res2.n_averages == 2


@pytest.mark.parametrize(("raw", "nper", "over"), [(1024, 256, 4), (1025, 256, 5),
                                                    (256, 256, 1), (100, 256, 1)])
def test_oversampling_factor(raw, nper, over):
    theta = TWO_PI * np.arange(raw * 3 + 2) / raw
    res = tsa(np.cos(5 * theta), angle=theta, samples_per_rev=nper)
    assert res.oversampling == over
    assert tsa(np.cos(5 * theta), angle=theta, samples_per_rev=nper,
               antialias=False).oversampling == 1


def test_oversampling_follows_the_slowest_speed_capped_at_four_times_the_mean():
    # steps alternate 0.5 h and 1.5 h (mean h = 2 pi / 200): the densest raw spacing is 0.5 h,
    # i.e. 400 samples per revolution at the slowest speed -> L = ceil(400 / 64) = 7
    h = TWO_PI / 200
    steps = np.tile([0.5 * h, 1.5 * h], 400)
    theta = np.r_[0.0, np.cumsum(steps)]
    res = tsa(np.cos(3 * theta), angle=theta, samples_per_rev=64)
    assert res.oversampling == 7
    # one step of 0.01 h: capped at 4 x the mean density (800 per rev) -> L = ceil(800/64) = 13
    steps = np.full(800, h)
    steps[100] = 0.01 * h
    theta = np.r_[0.0, np.cumsum(steps)]
    assert tsa(np.cos(3 * theta), angle=theta, samples_per_rev=64).oversampling == 13


def test_records_average_and_result_fields():
    theta = 0.2 + TWO_PI * np.arange(1000 * 4) / 1000
    x = np.stack([np.cos(3 * theta) + np.cos(100 * theta), np.sin(7 * theta)])
    res = tsa(x, angle=theta, samples_per_rev=128, keep_records=True, engine="numpy")
    assert res.oversampling == 8 and res.records.shape == (2, 3, 128)
    # order 100 is above N/2 = 64: filtered out of every record (up to the interpolant's
    # images of it, 1.8e-4 of its amplitude at 0.1 cycles per raw sample)
    np.testing.assert_allclose(res.records[0], np.tile(np.cos(3 * res.angle), (3, 1)),
                               atol=3e-4)
    np.testing.assert_allclose(res.average, res.records.mean(axis=1), atol=1e-15)
    plain = tsa(x, angle=theta, samples_per_rev=128)
    assert plain.records is None
    np.testing.assert_allclose(plain.average, res.average, atol=1e-12)
    one = tsa(x[1], angle=theta, samples_per_rev=128, keep_records=True)
    assert one.records.shape == (3, 128) and one.average.shape == (128,)
    np.testing.assert_allclose(one.records, res.records[1], atol=1e-14)
    assert tsa(x[1], angle=theta, samples_per_rev=128).records is None
    # field types and values
    assert type(res.n_averages) is int and type(res.oversampling) is int
    assert type(res.start_angle) is float and res.start_angle == pytest.approx(TWO_PI)
    assert res.samples_per_rev == 128 and res.method == "angle"
    np.testing.assert_allclose(res.angle, TWO_PI * np.arange(128) / 128, atol=0)
    np.testing.assert_allclose(res.angle_deg, 360 * np.arange(128) / 128, atol=1e-12)
    # the records without oversampling are the raw resampled revolutions
    low = tsa(x, angle=theta, samples_per_rev=1024, keep_records=True, antialias=False)
    assert low.oversampling == 1 and low.records.shape == (2, 3, 1024)


def test_angle_origin_aligns_the_revolutions():
    theta = TWO_PI * np.arange(500 * 5) / 500
    res = tsa(np.cos(2 * theta), angle=theta, samples_per_rev=100, angle_origin=1.0)
    assert res.start_angle == pytest.approx(1.0)
    np.testing.assert_allclose(res.average, np.cos(2 * (res.angle + 1.0)), atol=1e-9)
    res = tsa(np.cos(2 * theta), angle=theta, samples_per_rev=100, angle_origin=-1.0)
    assert res.start_angle == pytest.approx(TWO_PI - 1.0) and res.n_averages == 4


def test_revolution_count_bounds_and_warning_text():
    theta = TWO_PI * np.arange(64 * 3) / 64
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        assert tsa(np.cos(theta), angle=theta, samples_per_rev=64,
                   n_revolutions=3).n_averages == 3
        assert tsa(np.cos(theta), angle=theta, samples_per_rev=64, n_revolutions=2,
                   min_revolutions=2).n_averages == 2
    with pytest.warns(DiagnosticsWarning) as rec:
        tsa(np.cos(theta), angle=theta, samples_per_rev=64, n_revolutions=2, min_revolutions=3)
    assert str(rec[0].message) == (
        "TSA over only 2 whole revolution(s) (min_revolutions=3): no averaging of noise or "
        "non-synchronous components takes place.")
    e = _err(tsa, np.cos(theta), angle=theta, samples_per_rev=64, n_revolutions=4)
    assert (e.field, e.value, e.allowed) == ("n_revolutions", 4,
                                             "at most 3 (whole revolutions in the record)")
    e = _err(tsa, np.cos(theta), angle=theta, samples_per_rev=64, skip_revolutions=3)
    assert (e.field, e.value, e.allowed) == (
        "x", "a record spanning 2.98 revolutions after skipping 3",
        "at least one whole revolution (starting at angle_origin + 2*pi*k)")
    short = TWO_PI * np.arange(40) / 64
    e = _err(tsa, np.cos(short), angle=short, samples_per_rev=64)
    assert e.value == "a record spanning 0.609 revolutions"
    part = tsa(np.cos(theta), angle=theta, samples_per_rev=64, skip_revolutions=1)
    assert part.n_averages == 2 and part.start_angle == pytest.approx(TWO_PI)


@pytest.mark.parametrize(("kwargs", "field", "value", "allowed"), [
    ({"samples_per_rev": 7}, "samples_per_rev", 7, "an integer >= 8"),
    ({"skip_revolutions": -1}, "skip_revolutions", -1, "an integer >= 0"),
    ({"min_revolutions": 0}, "min_revolutions", 0, "an integer >= 1"),
    ({"n_revolutions": 0}, "n_revolutions", 0, "an integer >= 1"),
    ({"engine": "cuda"}, "engine", "cuda", "'auto', 'numba' or 'numpy'"),
    ({"interp_points": 5}, "interp_points", 5, "4, 6 or 8"),
    ({"interp_points": True}, "interp_points", True, "4, 6 or 8"),
    ({"tach_times": [0.0, 1.0]}, "angle/tach_times", "both",
     "exactly one of angle= (exact shaft angle) or tach_times="),
])
def test_tsa_option_texts(kwargs, field, value, allowed):
    theta = TWO_PI * np.arange(64 * 3) / 64
    e = _err(tsa, np.cos(theta), **{"angle": theta, "samples_per_rev": 64, **kwargs})
    assert (e.field, e.value, e.allowed) == (field, value, allowed)


def test_tsa_input_texts():
    theta = TWO_PI * np.arange(64 * 3) / 64
    e = _err(tsa, np.cos(theta), samples_per_rev=64)
    assert (e.field, e.value) == ("angle/tach_times", "neither")
    e = _err(tsa, np.cos(theta[:-1]), angle=theta, samples_per_rev=64)
    assert (e.field, e.value, e.allowed) == ("angle", "192 samples", "191 samples, like the signal(s) (x)")
    e = _err(tsa, np.cos(theta[:3]), angle=theta[:3], samples_per_rev=64)
    assert (e.field, e.allowed) == ("x", "at least 4 samples along the last axis")
    e = _err(tsa, np.ones((2, 2, 8)), angle=theta[:8], samples_per_rev=64)
    assert e.allowed == "an array with 1 or 2 dimension(s)"
    assert tsa(np.cos(theta), angle=theta, samples_per_rev=8).samples_per_rev == 8
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        res = tsa(np.cos(theta), angle=theta, samples_per_rev=64, interp_points=np.int64(8))
    np.testing.assert_allclose(res.average, np.cos(res.angle), atol=1e-12)


def test_tsa_from_tach_pulses_covering_part_of_the_record():
    fs = 1000.0
    t = np.arange(5000) / fs  # constant speed, 5 revolutions per second
    theta = TWO_PI * 5.0 * t
    x = np.cos(3 * theta) + 0.5 * np.sin(7 * theta)
    pulses = 0.0303 + np.arange(20) / 5.0  # first pulse after the record start
    res = tsa(x, fs=fs, tach_times=pulses, samples_per_rev=64, angle_origin=1.0)
    assert res.method == "tach" and res.start_angle == 0.0 and res.n_averages == 19
    # the angle is 0 at the first pulse: the average is the signal shifted by its angle
    phi0 = TWO_PI * 5.0 * 0.0303
    truth = np.cos(3 * (res.angle + phi0)) + 0.5 * np.sin(7 * (res.angle + phi0))
    np.testing.assert_allclose(res.average, truth, atol=1e-6)
    same = tsa(x, time=t, tach_times=pulses, samples_per_rev=64)
    np.testing.assert_allclose(same.average, res.average, atol=1e-13)
    e = _err(tsa, x, fs=fs, tach_times=pulses, samples_per_rev=64, pulses_per_rev=0)
    assert (e.field, e.value, e.allowed) == ("pulses_per_rev", 0, "an integer >= 1")
    e = _err(tsa, x, fs=fs, tach_times=[0.0001, 0.0003], samples_per_rev=64)
    assert (e.field, e.value, e.allowed) == (
        "tach_times", "pulses spanning fewer than 4 samples",
        "pulses spanning at least one revolution of the record")
    # two pulses per revolution at twice the rate: the same angle law
    two = tsa(x, fs=fs, tach_times=0.0303 + np.arange(39) / 10.0, samples_per_rev=64,
              pulses_per_rev=2)
    assert two.n_averages == 19
    np.testing.assert_allclose(two.average, res.average, atol=1e-6)


def test_tsa_defaults():
    # 2048 samples per revolution, no skipping, origin 0, anti-alias on, 6-point interpolant,
    # no warning at 2 revolutions, no records, one pulse per revolution
    rng = np.random.default_rng(9)
    theta = np.cumsum(rng.uniform(0.6, 1.4, 3 * 1024)) * (TWO_PI / 1024)
    theta -= theta[0] - 0.1
    quintic = np.array([1e-3, -2e-2, 0.1, 0.2, -0.5, 1.0])
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        res = tsa(np.polyval(quintic, theta), angle=theta)
    assert res.samples_per_rev == 2048 and res.start_angle == pytest.approx(TWO_PI)
    # the record spans 0.1 rad .. 3.02 revolutions: two whole revolutions from 2 pi
    assert res.records is None and res.n_averages == 2
    assert res.oversampling == 1  # 2048 >= the densest raw spacing (1024 / 0.6 per rev)
    ref = _poly_average(quintic, res.start_angle, res.n_averages, 2048)
    np.testing.assert_allclose(res.average, ref, rtol=1e-10)
    with pytest.warns(DiagnosticsWarning, match="only 1 whole revolution"):
        tsa(np.cos(theta[:2600]), angle=theta[:2600])  # up to 2.55 revolutions
    t = np.arange(2000) / 1000.0
    one = tsa(np.cos(TWO_PI * 3 * t), fs=1000.0, tach_times=np.arange(7) / 3.0,
              samples_per_rev=64)
    np.testing.assert_allclose(one.average, np.cos(one.angle), atol=1e-6)


@pytest.mark.parametrize("keep", [False, True])
def test_antialias_filter_applies_from_an_oversampling_of_two(keep):
    theta = TWO_PI * np.arange(512 * 4 + 1) / 512  # L = 512 / 256 = 2
    x = np.cos(3 * theta) + np.cos(200 * theta)  # order 200 aliases to 56 at N = 256
    res = tsa(x, angle=theta, samples_per_rev=256, keep_records=keep)
    raw = tsa(x, angle=theta, samples_per_rev=256, keep_records=keep, antialias=False)
    assert res.oversampling == 2 and raw.oversampling == 1
    spec = np.abs(np.fft.rfft(res.average)) * 2 / 256
    spec_raw = np.abs(np.fft.rfft(raw.average)) * 2 / 256
    assert spec_raw[56] > 0.5  # aliased without the filter
    # with it, what is left at 56 is the interpolant's image of order 200 (a few per cent at
    # 0.39 cycles per raw sample); order 3 passes
    assert spec[56] < 0.1 and spec[3] == pytest.approx(1.0, abs=1e-4)


def test_warnings_point_at_the_caller():
    # mutmut's trampoline adds a stack frame, so the caller's line is checked outside mutmut only
    import os

    theta = TWO_PI * np.arange(64 * 3) / 64
    s = np.array([0, 0, 1, 1, 0, 0, 1, 1], dtype=float)
    t = np.linspace(0.0, 1.0, 11)
    with warnings.catch_warnings(record=True) as rec:
        warnings.simplefilter("always")
        tsa(np.cos(theta), angle=theta, samples_per_rev=64, n_revolutions=1)
        tach_pulse_times(s, fs=1.0)
        angle_from_tach([0.0, 1.0, 4.0], t)
    assert [w.category for w in rec] == [DiagnosticsWarning] * 3
    if "MUTANT_UNDER_TEST" not in os.environ:
        assert [w.filename for w in rec] == [__file__] * 3


# ------------------------------------------------------------------------------------------
# further bounds (second round, against the remaining first-pass survivors)
# ------------------------------------------------------------------------------------------
def test_non_increasing_angle_with_a_zero_step_is_not_reverse_rotation():
    e = _err(_check_angle, np.array([3.0, 2.0, 2.0, 1.0]), "ang", False)
    assert e.value == "non-monotonic angle: angle[1] - angle[0] = -1 rad"
    assert e.allowed == "a strictly increasing (unwrapped) shaft angle"
    theta = TWO_PI * np.arange(64 * 3) / 64
    bad = theta.copy()
    bad[10] = bad[9]
    e = _err(tsa, np.cos(theta), angle=bad, samples_per_rev=64)
    assert (e.field, e.value) == ("angle", "non-monotonic angle: angle[10] - angle[9] = 0 rad")


def test_tach_edge_cases():
    with pytest.warns(DiagnosticsWarning, match=r"\(1 of 1 rising edges"):
        np.testing.assert_allclose(tach_pulse_times([0.0, 1.0], fs=2.0), [0.25])
    s = np.tile([0.0, 0.5, 1.0, 0.5], 2)  # two resolved edges, 4 s apart
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        np.testing.assert_allclose(tach_pulse_times(s, fs=1.0, threshold=0.5, min_interval=4.5),
                                   [1.0])
        # a part-way sample before the crossing: resolved, even two samples after a low one
        tach_pulse_times(np.tile([0.0, 0.3, 1.0, 1.0], 2), fs=1.0)
        # 2 % of the range around the extremes, for a range of 5 with an offset of 10
        tach_pulse_times(10 + 5 * np.array([0, 0.03, 0.97, 1, 0, 0.03, 0.97, 1]), fs=1.0)
    with pytest.warns(DiagnosticsWarning, match="2 of 2 rising edges"):
        tach_pulse_times(10 + 5 * np.array([0, 0.015, 0.985, 1, 0, 0.015, 0.985, 1]), fs=1.0)
    with pytest.warns(DiagnosticsWarning, match="2 of 2 rising edges"):  # exactly at 2 %
        tach_pulse_times(np.array([0, 0.02, 0.98, 1, 0, 0.02, 0.98, 1]), fs=1.0)
    with pytest.warns(DiagnosticsWarning, match="2 of 2 rising edges"):  # edge at sample 1
        np.testing.assert_allclose(tach_pulse_times([0.0, 1, 1, 0, 1, 1], fs=1.0), [0.5, 3.5])


def test_sample_time_bounds():
    e = _err(_sample_times, 3, None, [0.0])
    assert (e.field, e.value) == ("time", "array of shape (1,)")
    np.testing.assert_allclose(_sample_times(2, None, [0.0, 1.0]), [0.0, 1.0])
    np.testing.assert_allclose(_sample_times(3, 0.5, None), [0.0, 2.0, 4.0])


def test_angle_from_tach_slack_is_exactly_two_sample_intervals():
    t = np.arange(20) * 0.25  # exact binary fractions
    ang = angle_from_tach([1.0, 2.0, 3.0], t)
    inside = (t >= 0.5) & (t <= 3.5)
    np.testing.assert_allclose(ang[inside], TWO_PI * (t[inside] - 1.0), atol=1e-12)
    assert np.all(np.isnan(ang[~inside])) and np.count_nonzero(~inside) == 7
    # two samples: the median interval is their spacing
    np.testing.assert_allclose(angle_from_tach([0.0, 1.0, 2.0], [2.0004, 2.0009]),
                               TWO_PI * np.array([2.0004, 2.0009]), rtol=1e-12)


def test_pulse_regularity_is_judged_between_neighbouring_intervals():
    t = np.linspace(0.0, 1.0, 11)
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        # intervals growing by 1.2 each: every neighbouring ratio 1.2, overall 1.73
        angle_from_tach(np.cumsum([0.0, 1.0, 1.2, 1.44, 1.728]), t)
        angle_from_tach([0.0, 1.5, 2.5, 3.5], t)  # ratio exactly 1/1.5


def test_tsa_smallest_records():
    # four samples spanning 1.05 revolutions: accepted; the stencil is 4 points (cubic exact)
    angle = np.array([0.0, 2.2, 4.4, 6.6])
    cubic = np.array([0.01, -0.1, 0.3, 1.0])
    res = tsa(np.polyval(cubic, angle), angle=angle, samples_per_rev=8, min_revolutions=1)
    np.testing.assert_allclose(res.average, np.polyval(cubic, res.angle), rtol=1e-12)
    e = _err(tsa, np.ones(4), angle=angle[:3], samples_per_rev=8)
    assert (e.field, e.value, e.allowed) == ("angle", "array of shape (3,)",
                                             "at least 4 samples along the last axis")


def test_tsa_from_sparse_tach_samples():
    # 0.4 revolution per sample, pulses at 0 and 2.5 s: exactly 4 samples inside
    t = np.arange(4.0)
    ang = 0.4 * TWO_PI * t
    cubic = np.array([0.01, -0.1, 0.3, 1.0])
    res = tsa(np.polyval(cubic, ang), fs=1.0, tach_times=[0.0, 2.5], samples_per_rev=8,
              min_revolutions=1)
    np.testing.assert_allclose(res.average, np.polyval(cubic, res.angle), rtol=1e-10)
    # 0.6 revolution per sample (steps > pi): the spline angle must not be unwrapped
    t = np.arange(6.0)
    ang = 0.6 * TWO_PI * t
    res = tsa(np.polyval(cubic, ang), fs=1.0, tach_times=np.arange(3) / 0.6,
              samples_per_rev=8, min_revolutions=1)
    assert res.n_averages == 3
    np.testing.assert_allclose(res.average, _poly_average(cubic, 0.0, 3, 8), rtol=1e-10)


def test_tsa_refuses_a_non_monotonic_spline_angle():
    t = np.linspace(0.0, 3.0, 301)
    with pytest.warns(DiagnosticsWarning, match="missing or spurious pulse"):
        e = _err(tsa, np.cos(t), time=t, tach_times=[0.0, 1.0, 1.01, 2.0, 3.0],
                 samples_per_rev=8)
    assert e.field == "tach_times (spline angle)" and e.value.startswith("non-monotonic")


def test_tsa_tach_record_ending_at_a_revolution_boundary():
    fs = 64.0  # one revolution per second, 64 samples per revolution
    for n, expected in ((192, 3), (191, 2)):
        t = np.arange(n) / fs
        res = tsa(np.cos(TWO_PI * t), fs=fs, tach_times=np.arange(5.0), samples_per_rev=64)
        assert res.n_averages == expected


@pytest.mark.parametrize(("first", "last"), [(0.5, 1.0), (1.0, 0.5)])
def test_start_slack_uses_the_first_and_last_steps_themselves(first, last):
    # the first or the last raw step is half a sample: slack 0.25 sample, so a record
    # starting 0.4 sample after angle 0 starts its first revolution at 2 pi
    step = TWO_PI / 64
    inner = 0.4 + first + np.arange(64 * 4)
    theta = np.r_[0.4, inner, inner[-1] + last] * step
    res = tsa(np.cos(theta), angle=theta, samples_per_rev=64, antialias=False)
    assert res.start_angle == pytest.approx(TWO_PI)


def test_engine_selects_the_kernel(monkeypatch):
    import importlib

    mod = importlib.import_module("geardyn.diagnostics.tsa")  # the module, not the function

    theta = TWO_PI * np.arange(64 * 3) / 64
    calls = []
    real_numba = mod._numba_kernel
    real_numpy = mod._resample_numpy

    def numba_spy(*args):
        calls.append("numba")
        return real_numba(*args)

    def numpy_spy(*args, **kwargs):
        calls.append("numpy")
        return real_numpy(*args, **kwargs)

    monkeypatch.setattr(mod, "_numba_kernel", numba_spy)
    monkeypatch.setattr(mod, "_resample_numpy", numpy_spy)
    for engine, expected in (("numpy", ["numpy"]), ("numba", ["numba"]), ("auto", ["numba"])):
        calls.clear()
        tsa(np.cos(theta), angle=theta, samples_per_rev=64, engine=engine)
        assert calls == expected, engine
    # numba missing: "auto" falls back to NumPy, "numba" is refused
    monkeypatch.setattr(mod, "_numba_kernel", lambda *args: None)
    calls.clear()
    tsa(np.cos(theta), angle=theta, samples_per_rev=64)
    assert calls == ["numpy"]
    e = _err(tsa, np.cos(theta), angle=theta, samples_per_rev=64, engine="numba")
    assert (e.field, e.value, e.allowed) == ("engine", "numba",
                                             "'numpy' (numba is not installed)")


def test_resample_defaults_and_short_accumulation():
    rng = np.random.default_rng(2)
    angle = np.cumsum(rng.uniform(0.5, 1.5, 30)) * 0.1
    x = np.sin(4 * angle)[None, :]
    th = angle[3] + 0.11 * np.arange(20)
    for engine in ("numpy", "numba"):
        out = _resample(angle, x, angle[3], 0.11, 20, 20, False, engine)  # 6 points default
        np.testing.assert_allclose(out[0], _lagrange_reference(angle, x[0], th, 6), rtol=1e-10)
    # fewer points than the period: the fold still has the period's length
    acc = np.zeros((1, 7))
    _resample_numpy(angle, x, angle[3], 0.11, 5, 7, True, acc)
    np.testing.assert_allclose(acc[0, :5], _lagrange_reference(angle, x[0], th[:5], 6),
                               rtol=1e-10)
    assert np.all(acc[0, 5:] == 0.0)


# ------------------------------------------------------------------------------------------
# third round: the last non-equivalent survivors
# ------------------------------------------------------------------------------------------
def test_wrap_detection_bound_is_strict():
    # a backward jump of exactly 2 pi - 0.5 (|d + 2 pi| == 0.5) is not taken for a wrap
    e = _err(_check_angle, np.array([0.0, 1.0, 1.5 - TWO_PI, 3.0]), "ang", False)
    assert e.allowed == "a strictly increasing (unwrapped) shaft angle"
    e = _err(_check_angle, np.array([0.0, 1.0, 1.4999 - TWO_PI, 3.0]), "ang", False)
    assert e.allowed.endswith("geardyn diagnose --unwrap-angle)")


def test_refused_values_are_reported():
    s = np.tile([0.0, 0.5, 1.0, 0.5], 2)
    assert _err(tach_pulse_times, s, fs=1.0, min_interval=-2.0).value == -2.0
    assert _err(_sample_times, 3, -5.0, None).value == -5.0
    theta = 1.0 + TWO_PI * np.arange(40) / 64  # starts at 1 rad, spans 0.609 revolutions
    e = _err(tsa, np.cos(theta), angle=theta, samples_per_rev=64)
    assert e.value == "a record spanning 0.609 revolutions"


@pytest.mark.parametrize(("ratio", "over"), [(13.0, 13), (13.005, 14)])
def test_oversampling_cap_uses_the_mean_density_of_the_whole_record(ratio, over):
    # 800 raw steps, one of them tiny: the cap 4 x (mean raw samples per revolution) sets L;
    # the span is chosen so that the cap is ``ratio`` times N = 64
    span = 4 * TWO_PI * 800 / (64 * ratio)
    steps = np.ones(800)
    steps[100] = 0.01
    steps *= span / steps.sum()
    theta = -0.3 + np.r_[0.0, np.cumsum(steps)]
    res = tsa(np.cos(theta), angle=theta, samples_per_rev=64)
    assert res.oversampling == over
