"""Gear vibration diagnostics: TSA, order spectra, residual/difference signals, demodulation,
PWVD, statistics and condition metrics, figures, and the end-to-end chain.

Functions follow the scipy.signal style: arrays in, keyword-only options, frozen result
dataclasses. Angles are in radians and orders in shaft orders; every one-revolution record
(a TSA) is treated as one period of a periodic signal, so the FFT-based steps are exact.

The chain of Xue & Howard (section 4.2)::

    from geardyn.diagnostics import tsa, order_spectrum, residual, narrowband_demodulation
    avg = tsa(x, angle=theta_p, samples_per_rev=2048).average
    spec = order_spectrum(avg, scaling="rms", db=True)       # dB re 1 per shaft order
    res = residual(avg, teeth=23, preset="paper")            # all mesh harmonics removed
    dem = narrowband_demodulation(avg, teeth=23, harmonic=5, bandwidth=11)

or all at once with :func:`diagnose` / :func:`diagnose_file`.
"""

from .demodulation import DemodulationResult, band_limits, narrowband_demodulation
from .io import DataTable, read_simulation, read_table
from .metrics import (
    ConditionMetrics,
    NA4Tracker,
    SignalStatistics,
    band_envelope,
    central_moment,
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
from .pipeline import (
    SIMULATION_SIGNALS,
    DiagnosisResult,
    Measurement,
    SignalDiagnosis,
    diagnose,
    diagnose_file,
    load,
    load_measurement,
    load_simulation,
)
from .plots import (
    plot_analytic_signal,
    plot_demodulation,
    plot_order_spectrum,
    plot_pwvd,
    plot_residual,
    plot_tsa,
)
from .spectra import (
    RESIDUAL_PRESETS,
    OrderSpectrum,
    difference,
    mesh_orders,
    order_filter,
    order_spectrum,
    regular,
    regular_orders,
    residual,
    residual_orders,
)
from .tfd import PWVDResult, analytic_signal, pwvd, spwvd
from .tsa import DiagnosticsWarning, TSAResult, angle_from_tach, tach_pulse_times, tsa

__all__ = [
    # tsa
    "tsa",
    "TSAResult",
    "tach_pulse_times",
    "angle_from_tach",
    "DiagnosticsWarning",
    # spectra / order filter
    "order_spectrum",
    "OrderSpectrum",
    "order_filter",
    "mesh_orders",
    "regular_orders",
    "residual_orders",
    "regular",
    "residual",
    "difference",
    "RESIDUAL_PRESETS",
    # demodulation
    "narrowband_demodulation",
    "DemodulationResult",
    "band_limits",
    # time-frequency
    "pwvd",
    "spwvd",
    "analytic_signal",
    "PWVDResult",
    # statistics and metrics
    "signal_statistics",
    "SignalStatistics",
    "condition_metrics",
    "ConditionMetrics",
    "central_moment",
    "kurtosis",
    "fm0",
    "fm4",
    "m6a",
    "m8a",
    "na4",
    "na4_star",
    "nb4",
    "band_envelope",
    "energy_ratio",
    "NA4Tracker",
    # figures
    "plot_tsa",
    "plot_order_spectrum",
    "plot_residual",
    "plot_pwvd",
    "plot_demodulation",
    "plot_analytic_signal",
    # reading data and the chain
    "read_table",
    "read_simulation",
    "DataTable",
    "Measurement",
    "load",
    "load_measurement",
    "load_simulation",
    "SIMULATION_SIGNALS",
    "diagnose",
    "diagnose_file",
    "DiagnosisResult",
    "SignalDiagnosis",
]
