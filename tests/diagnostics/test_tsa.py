"""TSA: comb-filter and noise-law oracles, speed-fluctuation accuracy, kernels, bad input."""

from __future__ import annotations

import numpy as np
import pytest

from geardyn.diagnostics import (
    DiagnosticsWarning,
    angle_from_tach,
    tach_pulse_times,
    tsa,
)
from geardyn.diagnostics.tsa import _numba_kernel, _resample_numpy
from geardyn.errors import InputError

TWO_PI = 2 * np.pi


def _constant_speed(n_rev: float, per_rev: int, extra: int = 3):
    """Exact angle of a constant-speed record with ``per_rev`` samples per revolution."""
    n = int(round(n_rev * per_rev)) + extra
    return TWO_PI * np.arange(n) / per_rev


def _fit_amplitude(y, theta, q):
    """Least-squares amplitude of order q (cos and sin) in y(theta)."""
    a = np.column_stack([np.cos(q * theta), np.sin(q * theta)])
    coef, *_ = np.linalg.lstsq(a, y, rcond=None)
    return float(np.hypot(*coef))


# ------------------------------------------------------------------------------------------
# comb filter and noise law (McFadden 1987)
# ------------------------------------------------------------------------------------------
@pytest.mark.parametrize(
    ("r", "q", "expected"),
    [(10, 3.5, 0.0), (11, 3.5, 1 / 11), (10, 3.25, 0.1414213562373095)],
)
def test_comb_filter_attenuation(r, q, expected):
    n = 256
    theta = _constant_speed(r + 1, n)
    x = np.cos(q * theta + 0.4)
    res = tsa(x, angle=theta, samples_per_rev=n, n_revolutions=r)
    assert res.n_averages == r
    assert res.oversampling == 1
    closed = abs(np.sin(np.pi * r * q) / (r * np.sin(np.pi * q)))
    assert closed == pytest.approx(expected, abs=1e-12)
    amp = _fit_amplitude(res.average, res.angle, q)
    assert amp == pytest.approx(closed, abs=1e-12)


def test_synchronous_component_passes_unchanged():
    n = 256
    theta = _constant_speed(7, n)
    x = 0.3 + np.cos(5 * theta + 1.0) + 0.2 * np.sin(23 * theta)
    res = tsa(x, angle=theta, samples_per_rev=n)
    truth = 0.3 + np.cos(5 * res.angle + 1.0) + 0.2 * np.sin(23 * res.angle)
    assert np.max(np.abs(res.average - truth)) < 1e-12


def test_noise_falls_as_one_over_sqrt_r():
    n = 1024
    rng = np.random.default_rng(12345)
    rs = np.array([4, 16, 64])
    stds = []
    for r in rs:
        theta = _constant_speed(r, n)
        noise = rng.standard_normal(theta.size)
        res = tsa(noise, angle=theta, samples_per_rev=n, n_revolutions=int(r))
        stds.append(res.average.std())
    stds = np.array(stds)
    # each within ~4.5 sampling standard errors (1/sqrt(2N) = 2.2 %) of 1/sqrt(R)
    np.testing.assert_allclose(stds * np.sqrt(rs), 1.0, atol=0.1)
    slope = np.polyfit(np.log(rs), np.log(stds), 1)[0]
    assert slope == pytest.approx(-0.5, abs=0.05)


# ------------------------------------------------------------------------------------------
# 5 % sinusoidal speed fluctuation: constant speed per rev ~ %, tach spline ~1e-4, exact ~1e-7
# ------------------------------------------------------------------------------------------
F_ROT = 20.0  # mean shaft speed [rev/s]
F_MOD = F_ROT / 20  # speed fluctuation frequency [Hz]: one cycle per 20 revolutions
EPS = 0.05  # 5 % speed fluctuation
FS = 4096 * F_ROT  # 4096 raw samples per mean revolution
W0 = TWO_PI * F_ROT
DELTA = EPS * W0 / (TWO_PI * F_MOD)  # angle perturbation amplitude [rad]


def _theta(t):
    """theta(t) for omega = W0 (1 + EPS sin(2 pi F_MOD t)), theta(0) = 0."""
    return W0 * t + DELTA * (1 - np.cos(TWO_PI * F_MOD * t))


def _pulse_times(n_pulses):
    """Exact times of theta = 2 pi k (Newton iterations from the constant-speed guess)."""
    target = TWO_PI * np.arange(n_pulses)
    t = target / W0
    for _ in range(50):
        f = _theta(t) - target
        t = t - f / (W0 * (1 + EPS * np.sin(TWO_PI * F_MOD * t)))
    assert np.max(np.abs(_theta(t) - target)) < 1e-10
    return t


def _signal(theta):
    return np.cos(theta) + 0.5 * np.cos(23 * theta + 0.3) + 0.2 * np.cos(46 * theta + 1.0)


def test_speed_fluctuation_accuracy():
    t = np.arange(int(40 / F_ROT * FS)) / FS
    theta = _theta(t)
    x = _signal(theta)
    n = 512
    pulses = _pulse_times(int(theta[-1] / TWO_PI) + 1)

    def rel_err(res):
        truth = _signal(res.angle)
        return np.max(np.abs(res.average - truth)) / np.sqrt(np.mean(truth**2))

    exact = tsa(x, angle=theta, samples_per_rev=n)
    from_tach = tsa(x, fs=FS, tach_times=pulses, samples_per_rev=n)
    # baseline "constant speed within each revolution": angle linear in time between pulses
    inside = (t >= pulses[0]) & (t <= pulses[-1])
    lin = np.interp(t[inside], pulses, TWO_PI * np.arange(pulses.size))
    const = tsa(x[inside], angle=lin, samples_per_rev=n)

    # leaving out the first and last revolution (spline end effects)
    inner = tsa(x, fs=FS, tach_times=pulses, samples_per_rev=n, skip_revolutions=1,
                n_revolutions=from_tach.n_averages - 2)

    e_exact, e_tach, e_const = rel_err(exact), rel_err(from_tach), rel_err(const)
    assert exact.n_averages == 40 and from_tach.n_averages == 39
    # errors relative to the RMS of the signal
    assert e_exact < 5e-7  # oracle: about 2e-7 (measured 1.1e-7)
    assert 2e-5 < e_tach < 5e-4  # oracle: about 1e-4 (measured 2.6e-4)
    assert rel_err(inner) < e_tach / 3  # (measured 2.4e-5)
    assert 1e-2 < e_const < 1e-1  # oracle: about 4 % (measured 3.1 %)


def test_more_pulses_per_rev_and_time_argument():
    t = np.arange(int(12 / F_ROT * FS)) / FS
    theta = _theta(t)
    x = _signal(theta)
    ppr = 8
    target = TWO_PI * np.arange(int(theta[-1] / TWO_PI * ppr) + 1) / ppr
    tp = target / W0
    for _ in range(50):
        tp = tp - (_theta(tp) - target) / (W0 * (1 + EPS * np.sin(TWO_PI * F_MOD * tp)))
    res = tsa(x, time=t, tach_times=tp, pulses_per_rev=ppr, samples_per_rev=256)
    truth = _signal(res.angle)
    assert np.max(np.abs(res.average - truth)) < 1e-5
    assert res.method == "tach"


# ------------------------------------------------------------------------------------------
# kernels: numba twin == NumPy twin; exact on cubic polynomials
# ------------------------------------------------------------------------------------------
@pytest.mark.parametrize("taps", [4, 6, 8])
def test_numba_kernel_matches_numpy_twin(taps):
    kernel = _numba_kernel(taps)
    if kernel is None:  # pragma: no cover
        pytest.skip("numba not installed")
    rng = np.random.default_rng(3)
    n = 5000
    angle = np.cumsum(rng.uniform(0.5, 1.5, n)) * 0.01 + 0.3
    x = rng.standard_normal((2, n))
    # output steps around the mean sample spacing (0.01): stencils kept over several output
    # points and stencils skipped, as at the anti-aliased and the plain TSA's densities
    for dtheta in (0.0123, 0.0041):
        for acc, size in ((True, 97), (False, 3000)):
            a = np.zeros((2, size))
            b = np.zeros_like(a)
            kernel(angle, x, 0.31, dtheta, 3000, 97, acc, a)
            _resample_numpy(angle, x, 0.31, dtheta, 3000, 97, acc, b, chunk=700, taps=taps)
            np.testing.assert_allclose(a, b, rtol=1e-12, atol=1e-12)
    assert _numba_kernel(taps) is kernel  # compiled once per process and stencil size
    assert _numba_kernel(4 if taps != 4 else 6) is not kernel


@pytest.mark.parametrize("engine", ["numba", "numpy"])
def test_cubic_interpolant_reproduces_cubics(engine):
    rng = np.random.default_rng(7)
    n = 3000
    angle = np.cumsum(rng.uniform(0.2, 1.8, n)) * (TWO_PI * 6 / n)
    # a cubic in angle is reproduced exactly by the 4-point Lagrange interpolant
    poly = np.array([0.2, -0.5, 0.3, 1.0])
    x = np.polyval(poly, angle)
    res = tsa(x, angle=angle, samples_per_rev=64, antialias=False, keep_records=True,
              engine=engine)
    grid = res.start_angle + TWO_PI * np.arange(res.n_averages * 64) / 64
    np.testing.assert_allclose(res.records.ravel(), np.polyval(poly, grid), rtol=1e-10,
                               atol=1e-9)


# ------------------------------------------------------------------------------------------
# options
# ------------------------------------------------------------------------------------------
def test_multichannel_records_and_angle_origin():
    per_rev = 300
    theta = 1.0 + _constant_speed(9, per_rev)  # starts at 1 rad: first whole rev at 2 pi
    x = np.stack([np.cos(3 * theta - 0.7), np.sin(23 * theta)])
    res = tsa(x, angle=theta, samples_per_rev=128, keep_records=True)
    assert res.average.shape == (2, 128)
    assert res.records.shape == (2, res.n_averages, 128)
    assert res.start_angle == pytest.approx(TWO_PI)
    np.testing.assert_allclose(res.records.mean(axis=1), res.average, atol=1e-14)
    # aligned to the absolute angle: the TSA is the signal at theta = 2 pi n / N, within the
    # 4-point Lagrange bound (q h)^4 * 9/16 / 4! = 3.6e-7 at q = 3, h = 2 pi / 300 (the
    # default 6-point interpolant is tighter still)
    np.testing.assert_allclose(res.average[0], np.cos(3 * res.angle - 0.7), atol=1e-6)
    single = tsa(x[1], angle=theta, samples_per_rev=128)
    np.testing.assert_allclose(single.average, res.average[1], atol=1e-14)
    # skip and count revolutions
    part = tsa(x[0], angle=theta, samples_per_rev=128, skip_revolutions=2, n_revolutions=3)
    assert part.n_averages == 3
    assert part.start_angle == pytest.approx(3 * TWO_PI)


def test_antialias_removes_orders_above_half_n():
    per_rev = 1024
    theta = _constant_speed(6, per_rev)
    x = np.cos(5 * theta) + np.cos(200 * theta)  # order 200 aliases to 56 at N = 256
    filtered = tsa(x, angle=theta, samples_per_rev=256)
    raw = tsa(x, angle=theta, samples_per_rev=256, antialias=False)
    assert filtered.oversampling == 4
    np.testing.assert_allclose(filtered.average, np.cos(5 * filtered.angle), atol=1e-9)
    assert _fit_amplitude(raw.average, raw.angle, 56) > 0.9  # aliased without the filter


@pytest.mark.parametrize("nper", [333, 500])
def test_any_samples_per_rev(nper):
    theta = _constant_speed(5, 4000) + 0.37
    x = np.cos(5 * theta) + 0.5 * np.sin(100 * theta) + 0.2 * np.cos(300 * theta)
    res = tsa(x, angle=theta, samples_per_rev=nper)
    assert res.average.shape == (nper,) and res.n_averages == 4
    # order 300 is above N/2 for both N: removed by the anti-alias filter, not aliased;
    # what is left is the interpolation error of orders 100 and 300 at 4000 raw samples per
    # revolution (measured 4.4e-5 and 6.7e-6 with the 4-point interpolant: images of order 300
    # through the interpolant that land below N/2 dominate for N = 333)
    truth = np.cos(5 * res.angle) + 0.5 * np.sin(100 * res.angle)
    np.testing.assert_allclose(res.average, truth, atol=1e-4)
    plain = tsa(x, angle=theta, samples_per_rev=nper, antialias=False)
    assert np.max(np.abs(plain.average - truth)) > 0.1  # aliased without the filter


def test_tach_pulse_times_subsample_accuracy():
    fs = 5000.0
    f = 37.3
    t = np.arange(4000) / fs
    s = 5.0 * np.tanh(4 * np.sin(TWO_PI * f * t - 0.2))  # rising zero crossings known exactly
    edges = tach_pulse_times(s, fs=fs, threshold=0.0)
    truth = (np.arange(edges.size) + 0.2 / TWO_PI) / f
    truth = truth[truth > 0][: edges.size]
    assert edges.size == truth.size
    # linear interpolation of a smooth odd-symmetric edge errs by O(h^3 s'''/s'): here at most
    # about 0.5 % of the sample interval h (measured 0.12 %)
    assert np.max(np.abs(edges - truth)) < 0.01 / fs
    # default threshold (mid-range) gives the same crossings here
    np.testing.assert_allclose(tach_pulse_times(s, fs=fs), edges, atol=1e-12)


def test_tach_min_interval_discards_chatter():
    fs = 1000.0
    s = np.zeros(1000)
    s[100:110] = 1
    s[111:115] = 1  # chatter 1 ms after the first edge
    s[600:610] = 1
    with pytest.warns(DiagnosticsWarning, match="not resolved by the sampling"):
        edges = tach_pulse_times(s, fs=fs, threshold=0.5)
    assert edges.size == 3
    with pytest.warns(DiagnosticsWarning, match="not resolved by the sampling"):
        kept = tach_pulse_times(s, fs=fs, threshold=0.5, min_interval=0.1)
    np.testing.assert_allclose(kept, [0.0995, 0.5995])


# ------------------------------------------------------------------------------------------
# bad input: clear errors or warnings
# ------------------------------------------------------------------------------------------
def test_nan_in_signal_or_angle_is_an_error():
    theta = _constant_speed(4, 64)
    x = np.cos(theta)
    x[77] = np.nan
    with pytest.raises(InputError, match=r"x: .*index 77"):
        tsa(x, angle=theta, samples_per_rev=64)
    ang = theta.copy()
    ang[5] = np.inf
    with pytest.raises(InputError, match=r"angle: .*index 5"):
        tsa(np.cos(theta), angle=ang, samples_per_rev=64)


def test_non_monotonic_and_wrapped_angle():
    theta = _constant_speed(4, 64)
    bad = theta.copy()
    bad[100] = bad[99]
    with pytest.raises(InputError, match="non-monotonic angle"):
        tsa(np.cos(theta), angle=bad, samples_per_rev=64)
    wrapped = np.mod(theta, TWO_PI)
    with pytest.raises(InputError, match="unwrap=True"):
        tsa(np.cos(theta), angle=wrapped, samples_per_rev=64)
    ok = tsa(np.cos(theta), angle=wrapped, samples_per_rev=64, unwrap=True)
    np.testing.assert_allclose(ok.average, np.cos(ok.angle), atol=1e-12)
    with pytest.raises(InputError, match="reverse rotation"):
        tsa(np.cos(theta), angle=-theta, samples_per_rev=64)


def test_too_few_revolutions():
    theta = _constant_speed(0.8, 64)
    with pytest.raises(InputError, match="at least one whole revolution"):
        tsa(np.cos(theta), angle=theta, samples_per_rev=64)
    one = _constant_speed(1.5, 64)
    with pytest.warns(DiagnosticsWarning, match="only 1 whole revolution"):
        res = tsa(np.cos(one), angle=one, samples_per_rev=64)
    assert res.n_averages == 1
    theta = _constant_speed(3, 64)
    with pytest.raises(InputError, match="n_revolutions"):
        tsa(np.cos(theta), angle=theta, samples_per_rev=64, n_revolutions=5)


@pytest.mark.parametrize(
    ("kwargs", "match"),
    [
        ({"samples_per_rev": 4}, "samples_per_rev"),
        ({"samples_per_rev": 64.0}, "samples_per_rev"),
        ({"engine": "gpu"}, "engine"),
        ({"tach_times": [0.0, 1.0]}, "exactly one of"),
    ],
)
def test_bad_options(kwargs, match):
    theta = _constant_speed(4, 64)
    kw = {"angle": theta, "samples_per_rev": 64, **kwargs}
    with pytest.raises(InputError, match=match):
        tsa(np.cos(theta), **kw)


def test_mismatched_lengths_and_missing_angle():
    theta = _constant_speed(4, 64)
    with pytest.raises(InputError, match="angle: .*samples"):
        tsa(np.cos(theta[:-5]), angle=theta, samples_per_rev=64)
    with pytest.raises(InputError, match="exactly one of"):
        tsa(np.cos(theta), samples_per_rev=64)
    with pytest.raises(InputError, match="fs"):
        tsa(np.cos(theta), tach_times=[0.0, 0.1, 0.2], samples_per_rev=64)


def test_missing_tach_pulse_warns():
    t = np.linspace(0, 1, 1001)
    pulses = np.array([0.0, 0.1, 0.2, 0.4, 0.5, 0.6])  # pulse at 0.3 s missing
    with pytest.warns(DiagnosticsWarning, match="missing or spurious pulse"):
        angle_from_tach(pulses, t)
    with pytest.raises(InputError, match="tach_times"):
        angle_from_tach([0.0, 0.2, 0.1], t)
