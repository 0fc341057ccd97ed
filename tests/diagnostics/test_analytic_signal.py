"""The analytic signal and the default lag window of the PWVD, computed without scipy.signal.

Oracles: the closed-form analytic signal of a sampled cosine (``exp(i 2 pi k n / N)``), the
closed-form Hamming window, and scipy.signal (``hilbert``, ``get_window``) as a second
implementation. Importing scipy.signal costs about 0.4 s and 24 MB in every process that
diagnoses, so geardyn's diagnostics of a run must not import it (checked in a fresh interpreter).
"""

from __future__ import annotations

import subprocess
import sys
import textwrap

import numpy as np
import pytest

from geardyn.diagnostics import analytic_signal, pwvd
from geardyn.diagnostics.tfd import _odd_window


@pytest.mark.parametrize("n", [2, 3, 8, 9, 1000, 1001, 4096])
def test_analytic_signal_of_a_cosine_is_the_complex_exponential(n):
    """``cos(2 pi k t) -> exp(i 2 pi k t)`` for every order below Nyquist, and the Nyquist bin
    of an even N (and the mean, when kept) stays real: the end-point rule of Marple (1999)."""
    t = np.arange(n) / n
    # orders up to 40 (the cosine oracle's own rounding grows with the phase 2 pi k n / N)
    for k in sorted({1, 2, max(1, min((n - 1) // 2, 40))}):
        if 2 * k >= n:
            continue
        z = analytic_signal(3.0 * np.cos(2 * np.pi * k * t + 0.4))
        np.testing.assert_allclose(z, 3.0 * np.exp(1j * (2 * np.pi * k * t + 0.4)),
                                   rtol=0, atol=1e-12 * 3.0)
    if n % 2 == 0:  # the Nyquist tone (-1)^n has no quadrature part
        x = np.cos(np.pi * np.arange(n))
        np.testing.assert_allclose(analytic_signal(x), x, rtol=0, atol=1e-12)
    x = 2.5 + np.cos(2 * np.pi * t) if n > 2 else np.array([3.5, 1.5])
    kept = analytic_signal(x, remove_mean=False)
    np.testing.assert_allclose(kept.real, x, rtol=0, atol=1e-12)
    np.testing.assert_allclose(analytic_signal(x).real, x - x.mean(), rtol=0, atol=1e-12)


@pytest.mark.parametrize("n", [2, 5, 64, 257, 12288])
def test_analytic_signal_equals_scipy_hilbert(n):
    """The same weights as scipy.signal.hilbert (a second implementation), to rounding."""
    from scipy.signal import hilbert

    x = np.random.default_rng(n).standard_normal(n) + 0.7
    np.testing.assert_allclose(analytic_signal(x), hilbert(x - x.mean()), rtol=0,
                               atol=1e-13 * np.abs(x).max())
    np.testing.assert_allclose(analytic_signal(x, remove_mean=False), hilbert(x), rtol=0,
                               atol=1e-13 * np.abs(x).max())


@pytest.mark.parametrize("m", [1, 3, 5, 129, 1025])
def test_default_window_is_the_symmetric_hamming_window(m):
    """``w(n) = 0.54 - 0.46 cos(2 pi n / (M - 1))``: 0.08 at the ends, 1 in the middle,
    symmetric; and scipy.signal's "hamming" with ``fftbins=False`` to rounding."""
    from scipy.signal.windows import get_window

    w = _odd_window("hamming", m, "window")
    assert w.shape == (m,) and w.dtype == np.float64
    if m == 1:
        assert w[0] == 1.0
    else:
        n = np.arange(m)
        np.testing.assert_allclose(w, 0.54 - 0.46 * np.cos(2 * np.pi * n / (m - 1)),
                                   rtol=0, atol=1e-15)
        assert w[0] == pytest.approx(0.08, abs=1e-15) and w[m // 2] == pytest.approx(1.0)
        np.testing.assert_array_equal(w, w[::-1])
    np.testing.assert_allclose(w, get_window("hamming", m, fftbins=False), rtol=0, atol=1e-15)
    # another scipy window name still goes to scipy.signal
    np.testing.assert_allclose(_odd_window("hann", m, "window"),
                               get_window("hann", m, fftbins=False), rtol=0, atol=0)


def test_pwvd_with_the_default_window_equals_the_window_from_scipy():
    """The PWVD with the default window and with scipy's Hamming window passed as an array."""
    from scipy.signal.windows import get_window

    rng = np.random.default_rng(4)
    x = np.cos(2 * np.pi * 7 * np.arange(256) / 256) + 0.1 * rng.standard_normal(256)
    a = pwvd(x, samples_per_rev=256)
    b = pwvd(x, samples_per_rev=256, window=get_window("hamming", a.window_length,
                                                       fftbins=False))
    np.testing.assert_allclose(a.distribution, b.distribution, rtol=0,
                               atol=1e-12 * np.abs(b.distribution).max())


@pytest.mark.slow
def test_diagnosing_a_record_does_not_import_scipy_signal(tmp_path):
    """``diagnose_file`` of a simulation record (TSA, residual, difference, the indicators,
    demodulation) and the PWVD with its default window, in a fresh interpreter, leave
    scipy.signal unimported."""
    code = textwrap.dedent("""
        import sys
        import numpy as np
        import xarray as xr
        from geardyn.diagnostics import diagnose_file, pwvd
        w, fs, z = 114.14, 20000.0, 23
        t = np.arange(int(8 * 2 * np.pi / w * fs)) / fs
        theta = w * t
        pulse = np.exp(-0.5 * ((np.mod(theta, 2 * np.pi) - 3.0) / 0.02) ** 2)
        v = 0.01 * np.cos(z * theta) + 0.003 * pulse
        ds = xr.Dataset({"theta_p": ("time", theta), "theta_g": ("time", theta * z / 61),
                         "v_yg": ("time", v), "omega_p": ("time", w + 0.1 * np.cos(z * theta)),
                         "transmission_error": ("time", 0.05 + 1e-5 * pulse)},
                        coords={"time": t}, attrs={"pinion_teeth": z, "gear_teeth": 61})
        ds["v_yg"].attrs["units"] = "m/s"
        ds.to_netcdf(sys.argv[1], engine="h5netcdf")
        result = diagnose_file(sys.argv[1], samples_per_rev=512)
        pwvd(v[:512], samples_per_rev=512)
        print(len(result.signals) > 0, "scipy.signal" in sys.modules)
    """)
    out = subprocess.run([sys.executable, "-c", code, str(tmp_path / "record.nc")],
                         capture_output=True, text=True, timeout=300)
    assert out.returncode == 0, out.stderr
    assert out.stdout.split() == ["True", "False"], out.stdout
