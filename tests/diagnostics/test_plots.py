"""Figure functions: return matplotlib Figures with unit-labelled axes, no pyplot state."""

from __future__ import annotations

import io
import sys

import numpy as np
import pytest

from geardyn.diagnostics import (
    narrowband_demodulation,
    order_spectrum,
    plot_analytic_signal,
    plot_demodulation,
    plot_order_spectrum,
    plot_pwvd,
    plot_residual,
    plot_tsa,
    pwvd,
    residual,
    tsa,
)

N = 512
TH = 2 * np.pi * np.arange(N) / N
X = (np.cos(23 * TH) + 0.3 * np.cos(115 * TH + 0.2 * np.exp(-((TH - 3) / 0.05) ** 2))
     + 0.01 * np.cos(24 * TH))


def _labels(fig):
    return [t for ax in fig.axes for t in (ax.get_xlabel(), ax.get_ylabel())]


def _png(fig):
    buf = io.BytesIO()
    fig.savefig(buf, format="png", dpi=40)
    return buf.getvalue()


@pytest.fixture(scope="module")
def products():
    theta = 2 * np.pi * np.arange(3 * 700 + 5) / 700
    t_res = tsa(np.cos(23 * theta), angle=theta, samples_per_rev=N)
    dem = narrowband_demodulation(X, teeth=23)
    return t_res, dem


@pytest.mark.slow
def test_every_figure_has_units_and_renders(products):
    from matplotlib.figure import Figure

    t_res, dem = products
    figs = {
        "tsa": plot_tsa(t_res, label="v_yg", unit="m/s"),
        "tsa_array": plot_tsa(X, label="x", unit="m/s"),
        "spectrum": plot_order_spectrum(order_spectrum(X, db=True), teeth=23, unit="m/s"),
        "spectrum_from_tsa": plot_order_spectrum(X, teeth=23, unit="m/s"),
        "residual": plot_residual(residual(X, teeth=23), unit="m/s"),
        "pwvd": plot_pwvd(pwvd(X, max_order=140), teeth=23, unit="m/s"),
        "pwvd_db": plot_pwvd(pwvd(X), scale="db"),
        "demodulation": plot_demodulation(dem, unit="m/s"),
        "analytic": plot_analytic_signal(dem, unit="m/s"),
    }
    for name, fig in figs.items():
        assert isinstance(fig, Figure), name
        labels = " ".join(_labels(fig))
        assert "[" in labels, (name, labels)  # every axis label carries a unit
        assert _png(fig)[:4] == b"\x89PNG", name
    assert "shaft angle [deg]" in _labels(figs["tsa"])
    assert figs["tsa"].axes[0].get_xlim() == (0.0, 360.0)
    assert "v_yg [m/s]" in _labels(figs["tsa"])
    assert "RMS amplitude [dB re 1 m/s]" in _labels(figs["spectrum"])
    assert "shaft order [-]" in _labels(figs["pwvd"])
    # a signal whose unit is not known is not labelled dimensionless (a user audit, 11-27)
    assert "PWVD [unit not given]" in _labels(plot_pwvd(pwvd(X, max_order=40)))
    assert "acc [unit not given]" in _labels(plot_tsa(X[:64], label="acc"))
    assert "PM [deg]" in _labels(figs["demodulation"])
    assert "real part [m/s]" in _labels(figs["analytic"])
    # mesh harmonics marked on the spectrum: dashed lines at 23, 46, ...
    xs = sorted(line.get_xdata()[0] for line in figs["spectrum"].axes[0].get_lines())
    assert xs[:3] == [23, 46, 69]


def test_no_pyplot_state(products):
    t_res, dem = products
    plot_tsa(t_res)
    plot_demodulation(dem)
    if "matplotlib.pyplot" in sys.modules:  # another test may have imported it
        import matplotlib.pyplot as plt

        assert plt.get_fignums() == []
