"""PWVD: tone peak bin, equality with straightforward loop implementations, marginal, errors."""

from __future__ import annotations

import numpy as np
import pytest
from scipy.signal import hilbert
from scipy.signal.windows import hamming

from geardyn.diagnostics import analytic_signal, pwvd, spwvd
from geardyn.errors import InputError


def _tftb_pwvd_loop(z, h, nf, periodic):
    """Straightforward loop over time samples, after tftb's PseudoWignerVilleDistribution.run
    (lags truncated at the record ends) or with circular lags; returns (n_time, nf)."""
    n = z.size
    lh = (h.size - 1) // 2
    tfr = np.zeros((nf, n), dtype=complex)
    for icol in range(n):
        taumax = lh if periodic else min(icol, n - icol - 1, round(nf / 2), lh)
        tau = np.arange(-taumax, taumax + 1)
        idx = np.remainder(nf + tau, nf)
        if periodic:
            tfr[idx, icol] = h[lh + tau] * z[(icol + tau) % n] * np.conj(z[(icol - tau) % n])
        else:
            tfr[idx, icol] = h[lh + tau] * z[icol + tau] * np.conj(z[icol - tau])
    return np.real(np.fft.fft(tfr, axis=0)).T


def _spwvd_loop(z, h, g, nf):
    """Direct double sum of the smoothed PWVD with circular indices."""
    n = z.size
    lh = (h.size - 1) // 2
    lg = (g.size - 1) // 2
    g = g / g.sum()
    out = np.zeros((n, nf))
    for i in range(n):
        r = np.zeros(nf, dtype=complex)
        for m in range(-lh, lh + 1):
            acc = 0.0
            for p in range(-lg, lg + 1):
                acc += g[lg + p] * z[(i - p + m) % n] * np.conj(z[(i - p - m) % n])
            r[m % nf] = h[lh + m] * acc
        out[i] = np.real(np.fft.fft(r))
    return out


def test_tone_peaks_at_bin_51():
    n = 256
    x = np.cos(2 * np.pi * 0.1 * np.arange(n))  # 0.1 cycles/sample -> bin 2 * 0.1 * 256 = 51.2
    res = pwvd(x, periodic=False)
    peaks = np.argmax(res.distribution, axis=1)
    assert np.all(peaks[20:-20] == 51)
    assert res.orders[51] == pytest.approx(25.5)  # bin k = order k/2
    assert res.distribution.shape == (n, n)
    assert res.window_length == 65  # N//4 made odd


def test_periodic_tone_order_axis():
    n = 512
    theta = 2 * np.pi * np.arange(n) / n
    res = pwvd(np.cos(23 * theta), max_order=60)
    peaks = np.argmax(res.distribution, axis=1)
    assert np.all(res.orders[peaks] == 23.0)  # every angle, no edge effects with circular lags
    assert res.orders[-1] == 60.0
    assert res.distribution.shape == (n, 121)
    np.testing.assert_allclose(res.angle_deg[[0, -1]], [0.0, 360.0 * (n - 1) / n])


@pytest.mark.parametrize("periodic", [False, True])
def test_vectorised_equals_loop_reference(periodic):
    rng = np.random.default_rng(11)
    n = 128
    x = rng.standard_normal(n) + np.cos(2 * np.pi * 9 * np.arange(n) / n)
    res = pwvd(x, periodic=periodic)
    z = hilbert(x - x.mean())
    np.testing.assert_allclose(z, analytic_signal(x), atol=1e-12)
    ref = _tftb_pwvd_loop(z, hamming(33), n, periodic)
    scale = np.max(np.abs(ref))
    np.testing.assert_allclose(res.distribution / scale, ref / scale, atol=1e-12)


# PseudoWignerVilleDistribution(hilbert(x - mean)).run() values of tftb 0.2.0 (numpy 1.26.4,
# scipy 1.12.0; tftb needs numpy < 2 so it cannot run here), indexed [time, frequency bin]
TFTB_X_N = 64
TFTB_VALUES = {
    (0, 0): 2.9005456075996126,
    (5, 10): 7.714577350960985,
    (13, 31): 1.969873704566886,
    (30, 20): -0.3323853704056935,
    (40, 63): -0.04449732002291862,
    (50, 7): 0.3252168873426168,
    (63, 12): 0.4501142110928255,
}
TFTB_ABS_MAX = 14.156076414073416


def test_equals_published_tftb_values():
    k = np.arange(TFTB_X_N)
    x = (np.cos(2 * np.pi * 0.1 * k) + 0.5 * np.sin(2 * np.pi * 0.23 * k + 0.4)
         + 0.3 * np.cos(2 * np.pi * 0.031 * k**1.3))
    w = pwvd(x, periodic=False).distribution
    for (i, j), v in TFTB_VALUES.items():
        assert w[i, j] == pytest.approx(v, rel=1e-12, abs=1e-13)
    assert np.abs(w).max() == pytest.approx(TFTB_ABS_MAX, rel=1e-12)


def test_time_marginal_identity():
    # sum over the N_f bins of W(n, k) = N_f * h(0) * |z[n]|^2 (only lag 0 survives)
    rng = np.random.default_rng(2)
    x = rng.standard_normal(256)
    res = pwvd(x, n_fbins=300, window_length=101)
    z = analytic_signal(x)
    np.testing.assert_allclose(res.distribution.sum(axis=1), 300 * np.abs(z) ** 2,
                               rtol=1e-10)


def test_smoothed_equals_loop_reference():
    rng = np.random.default_rng(4)
    n = 64
    x = rng.standard_normal(n)
    res = spwvd(x, time_window_length=7)
    assert res.time_window_length == 7
    ref = _spwvd_loop(analytic_signal(x), hamming(17), hamming(7), n)
    np.testing.assert_allclose(res.distribution, ref, atol=1e-10 * np.abs(ref).max())
    # smoothing with a unit window is the PWVD
    np.testing.assert_allclose(pwvd(x, time_window_length=1).distribution,
                               pwvd(x).distribution, atol=0)


def test_smoothed_truncated_runs_and_reduces_cross_terms():
    n = 256
    t = np.arange(n)
    x = np.cos(2 * np.pi * 0.1 * t) + np.cos(2 * np.pi * 0.3 * t)  # cross term at 0.2
    plain = pwvd(x, periodic=False)
    smooth = spwvd(x, periodic=False, time_window_length=31)
    rows = slice(60, -60)
    k_cross = int(round(2 * 0.2 * n))
    k_tone = int(round(2 * 0.1 * n))
    ratio_plain = np.abs(plain.distribution[rows, k_cross]).max() / plain.distribution[
        rows, k_tone].mean()
    ratio_smooth = np.abs(smooth.distribution[rows, k_cross]).max() / smooth.distribution[
        rows, k_tone].mean()
    assert ratio_smooth < 0.1 * ratio_plain


def test_bad_window_lengths():
    x = np.ones(64) + np.arange(64)
    with pytest.raises(InputError, match="window_length"):
        pwvd(x, window_length=16)
    with pytest.raises(InputError, match="window_length"):
        pwvd(x, window_length=129)
    with pytest.raises(InputError, match="time_window_length"):
        pwvd(x, time_window_length=4)
    with pytest.raises(InputError, match="window"):
        pwvd(x, window="no-such-window")
    with pytest.raises(InputError, match="x: .*index 2"):
        pwvd(np.r_[1.0, 2.0, np.nan, 4.0, 5.0])
