"""Narrowband demodulation: band limits at the bound, full error texts, exact band spectra.

Written against the mutants that survived the first mutation run of
``geardyn.diagnostics.demodulation`` (docs/mutation.md): every band check is tried at the bound
(accepted) and just beyond (refused) with the full error text, the band spectrum is compared bin
by bin with the DFT computed here, and the degenerate inputs (zero signal) are checked.
"""

from __future__ import annotations

import warnings

import numpy as np
import pytest

from geardyn.diagnostics import DiagnosticsWarning, band_limits, narrowband_demodulation
from geardyn.diagnostics.demodulation import _band_spectrum, band_analytic_signal
from geardyn.errors import InputError

N = 256
T = 2 * np.pi * np.arange(N) / N


def _error(*args) -> InputError:
    with pytest.raises(InputError) as exc:
        band_limits(*args)
    return exc.value


def test_band_limits_at_the_nyquist_and_mean_bounds():
    # K + B = N/2 - 1 is the highest band allowed; N/2 is refused
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        assert band_limits(10, 5, 4, 110) == (46, 54)  # K + B = 54 = 110 // 2 - 1
    with pytest.warns(DiagnosticsWarning):  # 2B >= Z
        assert band_limits(10, 1, 9, 64) == (1, 19)  # K - B = 1: the lowest allowed
    err = _error(10, 5, 4, 108)  # K + B = 54 > 108 // 2 - 1 = 53
    assert err.field == "bandwidth" and err.value == 4
    assert err.allowed == ("a band 50+/-B (mesh harmonic 5 x 10 teeth) inside orders 1..53 "
                           "(Nyquist is 54 orders for 108 samples per revolution); use a lower "
                           "harmonic, smaller band or more samples (or check the tooth count)")
    # odd N: N // 2 - 1 (not N / 2 - 1)
    assert band_limits(10, 5, 4, 111) == (46, 54)
    assert _error(10, 5, 5, 111).allowed.startswith(
        "a band 50+/-B (mesh harmonic 5 x 10 teeth) inside orders 1..54 ")


def test_band_touching_the_mean_is_refused_before_the_tooth_count_check():
    err = _error(10, 1, 10, 256)  # K - B = 0: reaches the mean (and B = Z)
    assert err.allowed.startswith("a band 10+/-B (mesh harmonic 1 x 10 teeth) inside orders "
                                  "1..127 (Nyquist is 128 orders")


def test_band_containing_the_neighbouring_harmonic():
    err = _error(10, 2, 10, 256)  # B = Z
    assert err.field == "bandwidth" and err.value == 10
    assert err.allowed == ("less than the tooth count 10: the band 10..30 would contain the "
                           "neighbouring mesh harmonic (10 or 30)")
    with pytest.warns(DiagnosticsWarning) as rec:
        assert band_limits(10, 2, 9, 256) == (11, 29)  # B = Z - 1 accepted
    assert len(rec) == 1


@pytest.mark.parametrize(("teeth", "b_ok", "b_warn"), [(23, 11, 12), (24, 11, 12)])
def test_overlap_warning_starts_at_2b_equal_z(teeth, b_ok, b_warn):
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        band_limits(teeth, 2, b_ok, 512)
    with pytest.warns(DiagnosticsWarning) as rec:
        band_limits(teeth, 2, b_warn, 512)
    k = 2 * teeth
    assert str(rec[0].message) == (
        f"demodulation band {k}+/-{b_warn} overlaps the band of the neighbouring mesh harmonic "
        f"(2B >= Z = {teeth}); sidebands of two harmonics are mixed. B <= {(teeth - 1) // 2} "
        "avoids this.")


def test_one_tooth_passes_the_integer_check_and_fails_the_band_check():
    err = _error(1, 2, 1, 64)  # K = 2, B = 1 = Z
    assert (err.field, err.value) == ("bandwidth", 1)
    assert err.allowed.startswith("less than the tooth count 1: the band 1..3")


@pytest.mark.parametrize(("args", "field", "allowed"), [
    ((0, 1, 1, 256), "teeth", "a positive integer number of teeth"),
    ((10, 0, 1, 256), "harmonic", "a mesh harmonic number >= 1"),
    ((10, 1, 0, 256), "bandwidth", "a half-bandwidth >= 1 order"),
])
def test_integer_arguments(args, field, allowed):
    err = _error(*args)
    assert (err.field, err.value, err.allowed) == (field, 0, allowed)


def test_minimum_record_length_is_eight():
    x = np.cos(2 * np.pi * 2 * np.arange(8) / 8)
    with pytest.raises(InputError) as exc:
        narrowband_demodulation(x[:7], teeth=2, harmonic=1, bandwidth=1)
    assert exc.value.field == "x"
    assert exc.value.allowed == "at least 8 samples along the last axis"
    with pytest.raises(InputError) as exc:
        band_analytic_signal(x[:7], teeth=2, harmonic=1, bandwidth=1)
    assert (exc.value.field, exc.value.allowed) == ("x", "at least 8 samples along the last axis")
    # 8 samples: band 1..3 = N/2 - 1 is allowed
    with pytest.warns(DiagnosticsWarning):  # 2B >= Z
        dem = narrowband_demodulation(x, teeth=2, harmonic=1, bandwidth=1)
    np.testing.assert_allclose(dem.am, 1.0, atol=1e-14)


def test_band_spectrum_bin_by_bin():
    rng = np.random.default_rng(5)
    x = rng.standard_normal(N)
    dft = np.exp(-2j * np.pi * np.outer(np.arange(N), np.arange(N)) / N) @ x  # direct DFT
    band = _band_spectrum(x, 40, 60)
    expected = np.zeros(N, dtype=complex)
    expected[40:61] = 2 * dft[40:61]
    np.testing.assert_allclose(band, expected, atol=1e-10)
    # the band signal: inverse DFT of the kept bins, with the tones at the band edges included
    with pytest.warns(DiagnosticsWarning):  # 2B >= Z
        z = band_analytic_signal(x, teeth=10, harmonic=5, bandwidth=9)  # band 41..59
    direct = sum(2 * dft[k] * np.exp(1j * k * T) for k in range(41, 60)) / N
    np.testing.assert_allclose(z, direct, atol=1e-12)


def test_band_edges_are_inclusive_and_carrier_bin_removed_from_envelope():
    # tones at the lowest, carrier and highest order of the band 110 +/- 3 (teeth 22, h 5);
    # one order outside each edge must be rejected
    x = (0.3 * np.cos(107 * T) + np.cos(110 * T) + 0.2 * np.cos(113 * T)
         + 5.0 * np.cos(106 * T) + 5.0 * np.cos(114 * T))
    dem = narrowband_demodulation(x, teeth=22, harmonic=5, bandwidth=3)
    truth = 0.3 * np.exp(107j * T) + np.exp(110j * T) + 0.2 * np.exp(113j * T)
    np.testing.assert_allclose(dem.analytic, truth, atol=1e-12)
    np.testing.assert_allclose(dem.baseband, truth * np.exp(-110j * T), atol=1e-12)
    np.testing.assert_allclose(dem.envelope, np.abs(0.3 * np.exp(-3j * T)
                                                    + 0.2 * np.exp(3j * T)), atol=1e-12)
    np.testing.assert_allclose(dem.am, np.abs(truth), atol=1e-12)
    assert dem.band == (107, 113)
    assert (dem.carrier_order, dem.bandwidth, dem.harmonic, dem.teeth) == (110, 3, 5, 22)
    assert not dem.mean_phase_removed and dem.envelope_excludes_carrier
    np.testing.assert_allclose(dem.angle, T, atol=0)
    np.testing.assert_allclose(dem.pm_deg, np.degrees(dem.pm), atol=0)


def test_defaults_are_the_papers_band():
    x = np.cos(115 * 2 * np.pi * np.arange(2048) / 2048 + 0.7)
    dem = narrowband_demodulation(x, teeth=23)
    assert (dem.harmonic, dem.bandwidth, dem.carrier_order) == (5, 11, 115)
    np.testing.assert_allclose(dem.pm, 0.7, atol=1e-12)
    np.testing.assert_allclose(dem.am_relative, 0.0, atol=1e-12)


def test_zero_signal_gives_zero_relative_am_without_warning():
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        dem = narrowband_demodulation(np.zeros(N), teeth=10, harmonic=2, bandwidth=3)
    assert np.all(dem.am == 0.0) and np.all(dem.am_relative == 0.0)
    assert dem.am_relative.shape == (N,)


def test_phase_unwrapped_and_mean_removed_in_both_modes():
    pm = 2.5 * np.sin(T) + 1.0  # beyond pi: needs unwrapping; Bessel sidebands J_k(2.5)
    x = np.cos(46 * T + pm)
    kept = narrowband_demodulation(x, teeth=23, harmonic=2, bandwidth=11)
    removed = narrowband_demodulation(x, teeth=23, harmonic=2, bandwidth=11,
                                      remove_mean_phase=True)
    # J_12(2.5) ~ 1e-8: the truncated band recovers the phase to about that
    assert np.max(np.abs(kept.pm - pm)) < 1e-6
    np.testing.assert_allclose(removed.pm, pm - 1.0, atol=1e-6)
    np.testing.assert_allclose(removed.pm, kept.pm - kept.pm.mean(), atol=1e-14)
    assert removed.mean_phase_removed


def test_overlap_warning_points_at_the_caller():
    # mutmut's trampoline adds a stack frame, so the caller's line is checked outside mutmut only
    import os

    x = np.cos(46 * T)
    with pytest.warns(DiagnosticsWarning) as rec:
        narrowband_demodulation(x, teeth=23, harmonic=2, bandwidth=12)
        band_analytic_signal(x, teeth=23, harmonic=2, bandwidth=12)
    assert len(rec) == 2
    if "MUTANT_UNDER_TEST" not in os.environ:
        assert [w.filename for w in rec] == [__file__] * 2


def test_relative_am_of_a_weak_carrier():
    # mean AM 0.5 (below 1): a_rel = a / mean(a) - 1 = 0.3 cos 2 theta
    x = 0.5 * (1 + 0.3 * np.cos(2 * T)) * np.cos(46 * T)
    dem = narrowband_demodulation(x, teeth=23, harmonic=2, bandwidth=5)
    np.testing.assert_allclose(dem.am, 0.5 * (1 + 0.3 * np.cos(2 * T)), atol=1e-12)
    np.testing.assert_allclose(dem.am_relative, 0.3 * np.cos(2 * T), atol=1e-12)
