"""Order spectrum and the exact order-domain filter (regular / residual / difference)."""

from __future__ import annotations

import numpy as np
import pytest

from geardyn.diagnostics import (
    RESIDUAL_PRESETS,
    difference,
    mesh_orders,
    order_filter,
    order_spectrum,
    regular,
    regular_orders,
    residual,
    residual_orders,
)
from geardyn.errors import InputError

N = 2048
THETA = 2 * np.pi * np.arange(N) / N


def test_rms_spectrum_db_oracle():
    spec = order_spectrum(0.05 * np.cos(46 * THETA), scaling="rms", db=True)
    assert spec.amplitude[46] == pytest.approx(-29.0309, abs=5e-5)
    assert spec.amplitude[46] == pytest.approx(20 * np.log10(0.05 / np.sqrt(2)), abs=1e-12)
    assert spec.orders[46] == 46.0
    # every other bin is empty (floored far below)
    others = np.delete(spec.amplitude, 46)
    assert np.all(others < -250)


def test_rms_and_peak_scaling_dc_and_nyquist():
    x = 0.7 + 2.0 * np.cos(5 * THETA + 0.3) + 0.5 * np.cos(N // 2 * THETA)
    rms = order_spectrum(x)
    peak = order_spectrum(x, scaling="peak")
    assert rms.amplitude[0] == pytest.approx(0.7, abs=1e-13)
    assert rms.amplitude[5] == pytest.approx(2.0 / np.sqrt(2), abs=1e-13)
    assert peak.amplitude[5] == pytest.approx(2.0, abs=1e-13)
    assert peak.amplitude[0] == pytest.approx(0.7, abs=1e-13)
    # Nyquist: cos(pi n) takes the values +/-0.5: amplitude 0.5 (and its discrete RMS 0.5)
    assert rms.amplitude[-1] == pytest.approx(0.5, abs=1e-13)
    # Parseval: sum of squared RMS amplitudes = mean square of the record
    assert np.sum(rms.amplitude**2) == pytest.approx(np.mean(x**2), rel=1e-12)
    db = order_spectrum(x, db=True, db_ref=2.0)
    assert db.amplitude[5] == pytest.approx(20 * np.log10(np.sqrt(2) / 2.0), abs=1e-12)


def test_order_spectrum_along_axis():
    x = np.stack([np.cos(3 * THETA), 2 * np.cos(7 * THETA)])
    spec = order_spectrum(x.T, axis=0, scaling="peak")
    assert spec.amplitude.shape == (N // 2 + 1, 2)
    assert spec.amplitude[3, 0] == pytest.approx(1.0)
    assert spec.amplitude[7, 1] == pytest.approx(2.0)


def test_order_filter_is_exact_and_complementary():
    rng = np.random.default_rng(0)
    x = rng.standard_normal(N)
    orders = [0, 1, 23, 46, 500, N // 2]
    kept = order_filter(x, orders, keep=True)
    removed = order_filter(x, orders, keep=False)
    np.testing.assert_allclose(kept + removed, x, atol=1e-13)
    # kept part equals the direct sum of the sinusoids at those orders
    xf = np.fft.rfft(x)
    direct = np.zeros(N)
    for k in orders:
        scale = 1.0 if k in (0, N // 2) else 2.0
        direct += scale * np.real(xf[k] * np.exp(1j * k * THETA)) / N
    np.testing.assert_allclose(kept, direct, atol=1e-12)
    assert np.all(np.abs(np.fft.rfft(removed)[orders]) < 1e-10)


def test_order_filter_rejects_out_of_range_orders():
    with pytest.raises(InputError, match="orders"):
        order_filter(np.ones(64), [33])
    with pytest.raises(InputError, match="orders"):
        order_filter(np.ones(64), [-1])


def test_mesh_and_regular_orders():
    np.testing.assert_array_equal(mesh_orders(23, 256), [23, 46, 69, 92, 115])
    np.testing.assert_array_equal(mesh_orders(23, 256, harmonics=2), [23, 46])
    ords = regular_orders(23, 256, shaft_harmonics=2, mesh_harmonics=2, sidebands=1,
                          include_dc=True)
    np.testing.assert_array_equal(ords, [0, 1, 2, 22, 23, 24, 45, 46, 47])


def test_residual_presets_remove_the_documented_orders():
    z = 23
    p = residual_orders(z, N, preset="paper")
    np.testing.assert_array_equal(p, np.concatenate([[0], z * np.arange(1, N // 2 // z + 1)]))
    np.testing.assert_array_equal(residual_orders(z, N, preset="matlab"), [1, 2, 23, 46])
    zk = residual_orders(z, N, preset="zakrajsek")
    assert {0, 1, 2, 23, 46, 115}.issubset(set(zk))
    assert not {22, 24, 114, 116, 3}.intersection(set(zk))
    # overrides
    np.testing.assert_array_equal(
        residual_orders(z, N, preset="matlab", remove_dc=True, mesh_harmonics=1), [0, 1, 2, 23])
    assert set(RESIDUAL_PRESETS) == {"paper", "matlab", "zakrajsek"}
    with pytest.raises(InputError, match="residual_preset"):
        residual(np.ones(N), teeth=z, preset="nasa")


def test_residual_keeps_sidebands_and_shaft_orders():
    z = 23
    x = (3.0 + np.cos(z * THETA) + 0.5 * np.cos(2 * z * THETA) + 0.1 * np.cos((z + 1) * THETA)
         + 0.05 * np.cos(THETA))
    r = residual(x, teeth=z, preset="paper")
    np.testing.assert_allclose(r, 0.1 * np.cos((z + 1) * THETA) + 0.05 * np.cos(THETA),
                               atol=1e-13)
    rz = residual(x, teeth=z, preset="zakrajsek")
    np.testing.assert_allclose(rz, 0.1 * np.cos((z + 1) * THETA), atol=1e-13)


def test_signal_decomposition():
    """x = mean + regular + first-order sidebands + difference (exactly)."""
    rng = np.random.default_rng(5)
    z = 23
    x = (1.0 + np.cos(z * THETA) + 0.3 * np.cos(2 * z * THETA) + 0.2 * np.cos(THETA)
         + 0.1 * np.cos((z - 1) * THETA) + 0.01 * rng.standard_normal(N))
    y = regular(x, teeth=z)
    d = difference(x, teeth=z)
    sb = order_filter(x, np.concatenate([mesh_orders(z, N) - 1,
                                         mesh_orders(z, N)[mesh_orders(z, N) < N // 2] + 1]),
                      keep=True)
    np.testing.assert_allclose(x.mean() + y + sb + d, x, atol=1e-12)
    assert abs(y.mean()) < 1e-14 and abs(d.mean()) < 1e-14
    # regular holds the shaft and mesh orders
    spec_y = order_spectrum(y, scaling="peak").amplitude
    assert spec_y[z] == pytest.approx(1.0, abs=2e-3)
    assert spec_y[1] == pytest.approx(0.2, abs=2e-3)
    assert spec_y[z - 1] < 1e-12
    with_sb = regular(x, teeth=z, sidebands=1)
    np.testing.assert_allclose(with_sb, y + sb, atol=1e-12)
