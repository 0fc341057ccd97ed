"""PWVD/SPWVD: loop references with asymmetric windows, default lengths, bounds, error texts.

Written against the mutants that survived the first mutation run of
``geardyn.diagnostics.tfd`` (docs/mutation.md). The oracles are direct double loops over the
definitions of the module docstring (circular or truncated lags; angle smoothing circular or
renormalised over the valid lag products); asymmetric windows make any index reversal visible.
"""

from __future__ import annotations

import numpy as np
import pytest
from scipy.signal import hilbert
from scipy.signal.windows import hamming, hann

from geardyn.diagnostics import analytic_signal, pwvd, spwvd
from geardyn.errors import InputError


def _reference(z, h, g, nf, periodic):
    """Direct sums of the (smoothed) PWVD: rows = angle samples, columns = the nf bins.

    Lag m (|m| <= L) of row n: h(m) * sum_p g(p) z[n-p+m] z*[n-p-m] over the p whose product
    exists, divided (truncated lags) by the sum of those g(p); with circular lags every product
    exists and sum g = 1.
    """
    n = z.size
    lh = (h.size - 1) // 2
    lg = (g.size - 1) // 2
    g = g / g.sum()
    out = np.zeros((n, nf))
    for i in range(n):
        r = np.zeros(nf, dtype=complex)
        for m in range(-lh, lh + 1):
            num, den = 0.0, 0.0
            for p in range(-lg, lg + 1):
                c = i - p
                if periodic:
                    num += g[lg + p] * z[(c + m) % n] * np.conj(z[(c - m) % n])
                    den += g[lg + p]
                elif 0 <= c < n and 0 <= c + m < n and 0 <= c - m < n:
                    num += g[lg + p] * z[c + m] * np.conj(z[c - m])
                    den += g[lg + p]
            r[m % nf] += h[lh + m] / h[lh] * (num / den if abs(den) > 1e-12 else 0.0)
        out[i] = np.real(np.fft.fft(r))
    return out


RNG = np.random.default_rng(21)
X48 = RNG.standard_normal(48) + np.cos(2 * np.pi * 5 * np.arange(48) / 48)
H_ASYM = np.array([0.1, 0.5, 0.9, 2.0, 0.7, 0.3, 0.2])  # odd, h(0) = 2: normalised to 1
G_ASYM = np.array([0.5, 1.0, 3.0, 0.25, 0.75])


@pytest.mark.parametrize("periodic", [True, False])
def test_pwvd_with_an_asymmetric_lag_window(periodic):
    res = pwvd(X48, window=H_ASYM, periodic=periodic)
    # the lag window enters only through its half m >= 0 (Hermitian symmetry), so the reference
    # uses the symmetrised window h(|m|)
    hs = np.r_[H_ASYM[3:][::-1], H_ASYM[4:]]
    ref = _reference(hilbert(X48 - X48.mean()), hs, np.ones(1), 48, periodic)
    np.testing.assert_allclose(res.distribution, ref, atol=1e-11 * np.abs(ref).max())
    assert res.window_length == 7 and res.time_window_length == 1
    assert res.periodic is periodic and res.n_fbins == 48


@pytest.mark.parametrize("periodic", [True, False])
def test_spwvd_with_an_asymmetric_smoothing_window(periodic):
    h = hamming(9)
    res = spwvd(X48, window_length=9, time_window=G_ASYM, time_window_length=5,
                periodic=periodic)
    ref = _reference(hilbert(X48 - X48.mean()), h, G_ASYM, 48, periodic)
    np.testing.assert_allclose(res.distribution, ref, atol=1e-11 * np.abs(ref).max())
    assert res.time_window_length == 5 and res.window_length == 9


def test_truncated_smoothing_at_the_record_ends_renormalises():
    # a constant analytic amplitude: every valid lag product at lag m is exp(2i w m); the
    # renormalised smoothing must keep them so at the ends, where fewer products exist
    n = 40
    z = np.exp(2j * np.pi * 0.125 * np.arange(n))
    x = z.real
    res = spwvd(x, window_length=11, time_window_length=7, periodic=False, window="boxcar",
                time_window="boxcar")
    ref = _reference(hilbert(x - x.mean()), np.ones(11), np.ones(7), n, False)
    np.testing.assert_allclose(res.distribution, ref, atol=1e-11 * np.abs(ref).max())


def test_named_windows_are_symmetric_scipy_windows():
    a = pwvd(X48, window="hann", window_length=13)
    b = pwvd(X48, window=hann(13, sym=True))
    np.testing.assert_allclose(a.distribution, b.distribution, atol=1e-12)
    c = spwvd(X48, window_length=13, time_window="hann", time_window_length=7)
    d = spwvd(X48, window_length=13, time_window=hann(7, sym=True), time_window_length=7)
    np.testing.assert_allclose(c.distribution, d.distribution, atol=1e-12)


@pytest.mark.parametrize(("nf", "expected"), [(48, 13), (64, 17), (52, 13), (8, 3)])
def test_default_lag_window_is_nf_over_4_made_odd(nf, expected):
    x = np.cos(2 * np.pi * 3 * np.arange(64) / 64)
    res = pwvd(x, n_fbins=nf)
    assert res.window_length == expected
    assert res.distribution.shape == (64, nf)
    ref = pwvd(x, n_fbins=nf, window=hamming(expected))
    np.testing.assert_allclose(res.distribution, ref.distribution, atol=1e-12)


@pytest.mark.parametrize(("n", "nf", "expected"), [(64, None, 7), (200, None, 21),
                                                     (64, 300, 31), (20, None, 3),
                                                     (40, None, 5)])
def test_default_smoothing_length_is_nf_over_10_made_odd_at_least_3(n, nf, expected):
    x = np.cos(2 * np.pi * 3 * np.arange(n) / n) + np.arange(n) % 3
    kw = {} if nf is None else {"n_fbins": nf}
    res = spwvd(x, **kw)
    assert res.time_window_length == expected
    same = pwvd(x, time_window_length=expected, **kw)
    np.testing.assert_allclose(res.distribution, same.distribution, atol=0)


def test_orders_angles_and_samples_per_rev():
    n = 64
    x = np.cos(2 * np.pi * 7 * np.arange(n) / n)
    res = pwvd(x, samples_per_rev=32, n_fbins=128)
    # bin k is order k * N_rev / (2 * N_f)
    np.testing.assert_allclose(res.orders, np.arange(128) * 32 / 256, atol=0)
    np.testing.assert_allclose(res.angle, 2 * np.pi * np.arange(n) / 32, atol=1e-15)
    np.testing.assert_allclose(res.angle_deg, 360.0 * np.arange(n) / 32, atol=1e-12)
    one = pwvd(x, samples_per_rev=1)
    assert one.orders[2] == pytest.approx(1.0 / 64)


def test_max_order_keeps_the_bin_at_the_limit():
    x = np.cos(2 * np.pi * 7 * np.arange(64) / 64)
    full = pwvd(x)
    part = pwvd(x, max_order=10.0)  # bins of half orders: 0 .. 10 inclusive = 21 bins
    assert part.orders.size == 21 and part.orders[-1] == 10.0
    np.testing.assert_allclose(part.distribution, full.distribution[:, :21], atol=0)
    assert part.distribution.flags.c_contiguous
    # a limit a hair below a bin excludes it; within the 1e-12 tolerance includes it
    assert pwvd(x, max_order=10.0 - 1e-9).orders[-1] == 9.5
    assert pwvd(x, max_order=10.0 - 1e-13).orders[-1] == 10.0


def test_real_signal_and_mean_options():
    n = 32
    x = 3.0 + np.cos(2 * np.pi * 4 * np.arange(n) / n)
    real = pwvd(x, analytic=False, periodic=True, window="boxcar", window_length=5)
    ref = _reference((x - x.mean()).astype(complex), np.ones(5), np.ones(1), n, True)
    np.testing.assert_allclose(real.distribution, ref, atol=1e-12 * np.abs(ref).max())
    keep = pwvd(x, analytic=False, remove_mean=False, window="boxcar", window_length=5)
    ref = _reference(x.astype(complex), np.ones(5), np.ones(1), n, True)
    np.testing.assert_allclose(keep.distribution, ref, atol=1e-12 * np.abs(ref).max())
    ana = pwvd(x, remove_mean=False, window="boxcar", window_length=5)
    ref = _reference(hilbert(x), np.ones(5), np.ones(1), n, True)
    np.testing.assert_allclose(ana.distribution, ref, atol=1e-12 * np.abs(ref).max())


def test_analytic_signal_keeps_or_drops_the_mean():
    n = 16
    x = 2.0 + np.cos(2 * np.pi * 3 * np.arange(n) / n) + 0.5 * np.cos(np.pi * np.arange(n))
    z = analytic_signal(x)
    # Z_0 = 0, Z_3 = 2 X_3, Z_8 = X_8 (Nyquist), nothing at negative orders
    np.testing.assert_allclose(z, np.exp(2j * np.pi * 3 * np.arange(n) / n)
                               + 0.5 * np.cos(np.pi * np.arange(n)), atol=1e-14)
    np.testing.assert_allclose(analytic_signal(x, remove_mean=False), z + 2.0, atol=1e-14)
    with pytest.raises(InputError) as exc:
        analytic_signal([1.0])
    assert exc.value.allowed == "at least 2 samples along the last axis"


def test_window_length_bounds_accepted_at_the_bound():
    x = np.cos(2 * np.pi * 3 * np.arange(8) / 8) + np.arange(8)
    # L may reach n_fbins and 2N - 1
    assert pwvd(x, window_length=15, n_fbins=15).window_length == 15
    assert pwvd(x, window_length=1).window_length == 1
    assert pwvd(x[:4], window_length=7, n_fbins=8).window_length == 7
    assert pwvd(x, time_window_length=7).time_window_length == 7
    assert pwvd(x, n_fbins=2, window_length=1).n_fbins == 2


@pytest.mark.parametrize(("kwargs", "field", "value", "allowed"), [
    ({"window_length": 10}, "window_length", 10, "an odd length <= n_fbins = 32 and <= 2N-1 = 63"),
    ({"window_length": 33}, "window_length", 33, "an odd length <= n_fbins = 32 and <= 2N-1 = 63"),
    ({"window_length": 65, "n_fbins": 80}, "window_length", 65,
     "an odd length <= n_fbins = 80 and <= 2N-1 = 63"),
    ({"window_length": 0}, "window_length", 0, "an integer >= 1"),
    ({"n_fbins": 1}, "n_fbins", 1, "an integer >= 2"),
    ({"samples_per_rev": 0}, "samples_per_rev", 0, "an integer >= 1"),
    ({"time_window_length": 4}, "time_window_length", 4, "an odd length <= N = 32"),
    ({"time_window_length": 2}, "time_window_length", 2, "an odd length <= N = 32"),
    ({"time_window_length": 33}, "time_window_length", 33, "an odd length <= N = 32"),
    ({"time_window_length": 0}, "time_window_length", 0, "an integer >= 1"),
    ({"window": np.ones(4)}, "window", "array of shape (4,)", "a 1-D window of odd length"),
    ({"window": np.ones((3, 3))}, "window", "array of shape (3, 3)",
     "a 1-D window of odd length"),
    ({"window": np.ones(35)}, "window", "length 35", "an odd length <= n_fbins = 32"),
    ({"window": "no-such-window"}, "window", "no-such-window",
     "a scipy.signal window name, e.g. 'hamming'"),
    ({"time_window_length": 5, "time_window": np.ones(4)}, "time_window",
     "array of shape (4,)", "a 1-D window of odd length"),
])
def test_error_texts(kwargs, field, value, allowed):
    x = np.cos(2 * np.pi * 3 * np.arange(32) / 32)
    with pytest.raises(InputError) as exc:
        pwvd(x, **kwargs)
    assert (exc.value.field, exc.value.value, exc.value.allowed) == (field, value, allowed)


def test_short_records_are_refused():
    with pytest.raises(InputError) as exc:
        pwvd([1.0, 2.0, 3.0])
    assert exc.value.allowed == "at least 4 samples along the last axis"
    assert pwvd([1.0, 2.0, 3.0, 5.0]).distribution.shape == (4, 4)


# ------------------------------------------------------------------------------------------
# second round: bounds at the bound, three-point smoothing, field names
# ------------------------------------------------------------------------------------------
def test_analytic_signal_of_two_samples_and_field():
    np.testing.assert_allclose(analytic_signal([1.0, 3.0]), [-1.0, 1.0], atol=1e-15)
    with pytest.raises(InputError) as exc:
        analytic_signal([1.0])
    assert exc.value.field == "x"


def test_window_array_as_long_as_n_fbins_and_smoothing_as_long_as_the_record():
    x = np.cos(2 * np.pi * 2 * np.arange(9) / 9) + np.arange(9) % 2
    res = pwvd(x, window=np.ones(9), n_fbins=9)  # h.size == n_fbins: accepted
    ref = _reference(hilbert(x - x.mean()), np.ones(9), np.ones(1), 9, True)
    np.testing.assert_allclose(res.distribution, ref, atol=1e-12 * np.abs(ref).max())
    smooth = pwvd(x, time_window_length=9, time_window="boxcar", window="boxcar",
                  window_length=3)  # 2P + 1 == N: accepted
    ref = _reference(hilbert(x - x.mean()), np.ones(3), np.ones(9), 9, True)
    np.testing.assert_allclose(smooth.distribution, ref, atol=1e-12 * np.abs(ref).max())


def test_three_point_smoothing_is_applied():
    res = pwvd(X48, window_length=9, time_window_length=3, time_window=np.array([1.0, 2.0,
                                                                                 5.0]))
    ref = _reference(hilbert(X48 - X48.mean()), hamming(9), np.array([1.0, 2.0, 5.0]), 48,
                     True)
    np.testing.assert_allclose(res.distribution, ref, atol=1e-11 * np.abs(ref).max())


def test_unit_smoothing_length_ignores_the_smoothing_window():
    # 2P + 1 = 1 means no smoothing: the smoothing window is not even looked at
    a = pwvd(X48, time_window_length=1, time_window="no-such-window")
    np.testing.assert_allclose(a.distribution, pwvd(X48).distribution, atol=0)


def test_max_order_tolerance_is_inclusive():
    x = np.cos(2 * np.pi * 7 * np.arange(64) / 64)
    # (10 - 1e-12) + 1e-12 rounds to exactly 10.0: the bin at order 10 is kept
    assert pwvd(x, max_order=10.0 - 1e-12).orders[-1] == 10.0
