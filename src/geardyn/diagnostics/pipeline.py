"""The whole diagnostics chain of Xue & Howard (section 4.2) on simulated or measured data.

For every signal: time synchronous average (TSA) -> RMS order spectrum -> residual, regular and
difference signals -> narrowband demodulation about a mesh harmonic (envelope, AM, PM,
analytic signal) -> PWVD of the TSA and of the residual -> statistics of the TSA (Table 2:
mean, STD, skewness, kurtosis, crest factor) and kurtoses of the residual, envelope, AM and PM
(Table 3) -> condition metrics (FM0, FM4, M6A, M8A, NA4, NA4*, NB4, energy ratio).

Entry points
------------
:func:`load_simulation` / :func:`load_measurement` / :func:`load`
    Read a geardyn simulation result (NetCDF) or measured data (CSV, .npy/.npz, .mat) into a
    :class:`Measurement` (defined in :mod:`.loading`, re-exported here).
:func:`diagnose`
    Run the chain on arrays; returns a :class:`DiagnosisResult` with ``to_dict()`` (all metrics,
    JSON-serialisable), ``figures()``, ``write_figures(folder)`` and ``write(out_dir)``
    (``metrics.json`` + ``figures/*.png``, each written atomically).
:func:`diagnose_file`
    ``load`` + ``diagnose``, the library side of ``geardyn diagnose FILE``.

Defaults: N = 2048 samples per revolution (a power of two for the FFTs; at least 276 are needed
for the PWVD to show the paper's 138 orders at half-order resolution, and 2048 resolves the
tooth-mesh events of a 23-tooth pinion with about 89 samples per tooth), 5th mesh harmonic
+/- 11 orders, the paper's residual (all mesh harmonics and the mean removed).
"""

from __future__ import annotations

import json
import math
import os
import warnings
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from geardyn.errors import NOT_GIVEN, DataFileError, GeardynError, InputError

from .demodulation import DemodulationResult, narrowband_demodulation
from .io import NETCDF_SUFFIXES
from .loading import (  # the readers (re-exported: the public names were defined here)
    SIMULATION_SIGNALS,
    Measurement,
    _namer,
    _same_rate,
    load,
    load_measurement,
    load_simulation,
)
from .metrics import (
    ConditionMetrics,
    SignalStatistics,
    condition_metrics,
    is_constant,
    kurtosis,
    signal_statistics,
)
from .spectra import OrderSpectrum, difference, order_spectrum, regular, residual
from .tfd import PWVDResult, pwvd
from .tsa import (
    DiagnosticsWarning,
    ShortRecordError,
    TSAResult,
    _check_int,
    tsa,
)

__all__ = [
    "SIMULATION_SIGNALS",
    "Measurement",
    "SignalDiagnosis",
    "DiagnosisResult",
    "load_simulation",
    "load_measurement",
    "load",
    "diagnose",
    "diagnose_file",
]

# --------------------------------------------------------------------------------------------
# results
# --------------------------------------------------------------------------------------------
@dataclass(frozen=True)
class SignalDiagnosis:
    """Everything the chain computes for one signal.

    Attributes
    ----------
    name : str
        Signal name.
    unit : str
        Signal unit u.
    tsa : TSAResult
        Synchronous average (u) over the shaft angle [rad].
    spectrum : OrderSpectrum
        RMS amplitude per shaft order (u, linear; use ``order_spectrum(..., db=True)`` for dB).
    residual : ndarray
        Residual signal (u) per the chosen preset.
    regular : ndarray
        Regular signal (u).
    difference : ndarray
        Difference signal (u).
    demodulation : DemodulationResult
        Narrowband demodulation about the chosen mesh harmonic.
    pwvd_tsa : PWVDResult
        PWVD of the TSA (u^2).
    pwvd_residual : PWVDResult
        PWVD of the residual (u^2).
    statistics : SignalStatistics
        Statistics of the TSA (Table 2).
    residual_kurtosis, envelope_kurtosis, am_kurtosis, pm_kurtosis : float
        Pearson kurtoses of the residual, narrowband envelope, AM and PM [-] (Table 3).
    metrics : ConditionMetrics
        Condition metrics of the TSA.
    """

    name: str
    unit: str
    tsa: TSAResult
    spectrum: OrderSpectrum
    residual: np.ndarray
    regular: np.ndarray
    difference: np.ndarray
    demodulation: DemodulationResult
    pwvd_tsa: PWVDResult
    pwvd_residual: PWVDResult
    statistics: SignalStatistics
    residual_kurtosis: float
    envelope_kurtosis: float
    am_kurtosis: float
    pm_kurtosis: float
    metrics: ConditionMetrics

    def to_dict(self, teeth: int | None = None) -> dict:
        """JSON-safe dict of the scalar results (no arrays except the mesh-harmonic amplitudes).

        Parameters
        ----------
        teeth : int, optional
            Z, to list the RMS amplitude of each mesh harmonic [u and dB re 1 u].
        """
        dem = self.demodulation
        out: dict[str, Any] = {
            "unit": self.unit,
            "n_averages": self.tsa.n_averages,
            "statistics": self.statistics.to_dict(),
            "kurtosis": {
                "tsa": _f(self.statistics.kurtosis),
                "residual": _f(self.residual_kurtosis),
                "envelope": _f(self.envelope_kurtosis),
                "amplitude_modulation": _f(self.am_kurtosis),
                "phase_modulation": _f(self.pm_kurtosis),
            },
            "demodulation": {
                "carrier_order": dem.carrier_order,
                "band": list(dem.band),
                # the carrier's mean phase, wrapped to (-180, 180] deg: where the band holds
                # no carrier the unwrapped phase drifts, and its mean read -346.5 or 733 deg
                "mean_phase_deg": _f(_wrapped_deg(float(np.mean(dem.pm)))),
                "mean_am": _f(float(np.mean(dem.am))),
                "envelope_excludes_carrier": dem.envelope_excludes_carrier,
            },
            "condition_metrics": self.metrics.to_dict(),
        }
        if teeth:
            amp = self.spectrum.amplitude
            orders = np.arange(teeth, amp.shape[-1], teeth)
            out["mesh_harmonics_rms"] = {
                str(int(k)): {"rms": _f(float(amp[k])),
                              "db": _f(float(20 * np.log10(max(amp[k], 1e-300))))}
                for k in orders
            }
        return out


@dataclass(frozen=True)
class DiagnosisResult:
    """Result of :func:`diagnose` for all signals.

    Attributes
    ----------
    signals : dict of str to SignalDiagnosis
        Per-signal results, in input order.
    teeth : int
        Z [-].
    samples_per_rev : int
        N [-].
    harmonic : int
        Demodulation mesh harmonic [-].
    bandwidth : int
        Demodulation half-band [orders].
    residual_preset : str
        Residual preset.
    method : str
        ``"angle"`` or ``"tach"``.
    source : str
        Input description (file), may be empty.
    settings : dict
        The other options used (JSON-safe).
    """

    signals: dict[str, SignalDiagnosis]
    teeth: int
    samples_per_rev: int
    harmonic: int
    bandwidth: int
    residual_preset: str
    method: str
    source: str = ""
    settings: dict = field(default_factory=dict)

    def __repr__(self) -> str:
        """A line a notebook can show: the signals, their averages and kurtoses (the
        dataclass's repr printed every array, 10,000 characters: a user audit)."""
        sig = ", ".join(f"{k} ({v.tsa.n_averages} revolutions, kurtosis "
                        f"{v.statistics.kurtosis:.4g}"
                        f", residual {v.residual_kurtosis:.4g})" for k, v in self.signals.items())
        return (f"DiagnosisResult(teeth={self.teeth}, method={self.method!r}, "
                f"samples_per_rev={self.samples_per_rev}, signals: {sig}"
                + (f", source={self.source!r}" if self.source else "") + ")")

    def to_dict(self) -> dict:
        """All metrics and settings as a JSON-serialisable dict (NaN/inf as None)."""
        return {
            "geardyn_diagnostics": 1,
            "source": self.source,
            "settings": {
                "teeth": self.teeth,
                "samples_per_rev": self.samples_per_rev,
                "harmonic": self.harmonic,
                "bandwidth": self.bandwidth,
                "residual_preset": self.residual_preset,
                "method": self.method,
                **self.settings,
            },
            "signals": {k: v.to_dict(self.teeth) for k, v in self.signals.items()},
        }

    def figures(self) -> dict[str, Any]:
        """All figures, keyed by a file-name stem (``<signal>_<kind>``).

        Kinds: ``tsa``, ``spectrum`` (dB, mesh harmonics marked), ``residual``, ``pwvd_tsa``,
        ``pwvd_residual``, ``demodulation`` and ``analytic``.
        """
        return dict(self._iter_figures())

    def _iter_figures(self):
        """Yield ``(stem, Figure)`` one at a time (so writing them holds one in memory)."""
        from . import plots

        for name, d in self.signals.items():
            stem = _safe(name)
            u = d.unit
            yield f"{stem}_tsa", plots.plot_tsa(d.tsa, label=name, unit=u)
            db = order_spectrum(d.tsa.average, scaling="rms", db=True)
            yield f"{stem}_spectrum", plots.plot_order_spectrum(db, teeth=self.teeth,
                                                                label=name, unit=u)
            yield f"{stem}_residual", plots.plot_residual(d.residual, label=name, unit=u)
            yield f"{stem}_pwvd_tsa", plots.plot_pwvd(d.pwvd_tsa, teeth=self.teeth,
                                                      label=f"TSA of {name}", unit=u)
            yield f"{stem}_pwvd_residual", plots.plot_pwvd(
                d.pwvd_residual, teeth=self.teeth, label=f"residual of {name}", unit=u)
            yield f"{stem}_demodulation", plots.plot_demodulation(d.demodulation, label=name,
                                                                  unit=u)
            yield f"{stem}_analytic", plots.plot_analytic_signal(d.demodulation, label=name,
                                                                 unit=u)

    def write_figures(self, folder, *, dpi: int = 110) -> list[Path]:
        """Write every figure as ``<folder>/<stem>.png`` (atomically); returns the paths."""
        folder = Path(folder)
        folder.mkdir(parents=True, exist_ok=True)
        written = []
        for stem, fig in self._iter_figures():
            target = folder / f"{stem}.png"
            _atomic_write(target, lambda fh, fig=fig: fig.savefig(fh, format="png", dpi=dpi))
            written.append(target)
        return written

    def write(self, out_dir, *, figures: bool = True, dpi: int = 110) -> dict[str, Any]:
        """Write ``metrics.json`` and (optionally) ``figures/*.png`` into ``out_dir``.

        Each file is written to a temporary file in the same folder and moved into place with
        :func:`os.replace`, so a reader never sees a half-written file.

        Returns
        -------
        dict
            ``{"metrics": Path, "figures": [Path, ...]}``.
        """
        out = Path(out_dir)
        try:
            out.mkdir(parents=True, exist_ok=True)
        except OSError as exc:
            raise DataFileError(out, f"cannot create the output folder ({exc})") from exc
        text = json.dumps(self.to_dict(), indent=2, allow_nan=False)
        metrics_path = out / "metrics.json"
        _atomic_write(metrics_path, lambda fh: fh.write(text.encode("utf-8")))
        figs = self.write_figures(out / "figures", dpi=dpi) if figures else []
        return {"metrics": metrics_path, "figures": figs}


def _atomic_write(target: Path, writer) -> None:
    """Write through ``writer(fileobj)`` to a temporary file beside ``target``, then rename."""
    from ..io import atomic_path

    with atomic_path(target) as tmp, open(tmp, "wb") as fh:
        writer(fh)
        fh.flush()
        os.fsync(fh.fileno())


def _safe(name: str) -> str:
    return "".join(c if c.isalnum() or c in "-_" else "_" for c in name) or "signal"


def _f(v):
    """A float for JSON: NaN and infinities become None (:func:`geardyn.io.json_safe`)."""
    from ..io import json_safe

    return json_safe(float(v))


# --------------------------------------------------------------------------------------------
# the chain
# --------------------------------------------------------------------------------------------
#: Largest signal magnitude the chain accepts (its squared quantities must stay in float64).
MAX_SIGNAL_MAGNITUDE = 1e150


def diagnose(
    signals: Mapping[str, np.ndarray],
    *,
    teeth: int,
    fs: float | None = None,
    time=None,
    angle=None,
    tach_times=None,
    pulses_per_rev: int = 1,
    samples_per_rev: int = 2048,
    harmonic: int = 5,
    bandwidth: int = 11,
    residual_preset: str = "paper",
    n_revolutions: int | None = None,
    skip_revolutions: int = 0,
    envelope_excludes_carrier: bool = True,
    remove_mean_phase: bool = False,
    pwvd_window_length: int | None = None,
    pwvd_max_order: float | None = None,
    units: Mapping[str, str] | None = None,
    source: str = "",
    pwvd_distributions: bool = True,
    doubt_teeth: bool = True,
) -> DiagnosisResult:
    """Run the diagnostics chain on one or more signals sharing a shaft angle.

    Parameters
    ----------
    signals : mapping of str to array_like
        Signals of equal length n (their own units).
    teeth : int
        Z, teeth of the gear on the averaged shaft [-] (paper: the 23-tooth pinion).
    fs : float, optional
        Sample rate [Hz] (with ``tach_times``).
    time : array_like, optional
        Sample times [s] (with ``tach_times``).
    angle : array_like, optional
        Exact shaft angle per sample [rad]. Give ``angle`` or ``tach_times``.
    tach_times : array_like, optional
        Tachometer pulse times [s].
    pulses_per_rev : int
        Tachometer pulses per revolution [-].
    samples_per_rev : int
        N of the TSA [-] (default 2048; see the module docstring).
    harmonic, bandwidth : int
        Demodulation carrier (mesh harmonic) and half-band [orders] (paper: 5, 11).
    residual_preset : str
        Residual preset ("paper", "matlab", "zakrajsek"); also used for NA4.
    n_revolutions, skip_revolutions : int, optional
        Revolutions to average / to skip at the start.
    envelope_excludes_carrier, remove_mean_phase : bool
        Demodulation options (see :func:`narrowband_demodulation`).
    pwvd_window_length : int, optional
        Odd PWVD lag window length [samples]; default N//4 made odd.
    pwvd_max_order : float, optional
        Highest order kept in the PWVDs [-]; default ``max(6, harmonic + 1) * teeth`` (the
        paper shows 138 orders), capped at N/2.
    units : mapping, optional
        Unit of each signal for labels.
    source : str
        Description of the input (file name) for the report.
    doubt_teeth : bool
        Warn when a TSA's strongest order is far above its mesh harmonics and not one of them
        (a wrong ``teeth``?). :func:`diagnose_file` passes False where the file states the
        teeth (a simulation result's ``pinion_teeth``, a ``geardyn measure`` record's case):
        there the strong order is the record's own (a worn flank's gap puts one at order 6).
    pwvd_distributions : bool
        Compute the PWVD distributions (default). False leaves each PWVD's distribution empty,
        shape (0, 0), with its axes and settings (:func:`.tfd.pwvd` ``distribution``); every
        other result is the same. For a caller that draws no PWVD: the two PWVDs per signal are
        most of this function's time.

    Returns
    -------
    DiagnosisResult

    Raises
    ------
    InputError
        Bad signals (NaN, unequal lengths), angle/tach problems, bad options (see the functions
        of each step).
    """
    if not isinstance(signals, Mapping) or not signals:
        raise InputError("signals", type(signals).__name__,
                         "a non-empty mapping of name -> 1-D array")
    z = _check_int(teeth, "teeth", 1, "a positive integer number of teeth")
    if isinstance(fs, str):  # "100 kHz", as diagnose_file and the command line take it
        from ..units import parse_frequency

        fs = parse_frequency(fs, "fs")
    if fs is not None and not (isinstance(fs, int | float | np.integer | np.floating)
                               and not isinstance(fs, bool) and math.isfinite(fs) and fs > 0):
        # checked on every path: with an angle it only times the record (the shaft speed), and
        # a string, a negative or a zero rate failed there or passed silently (a user audit)
        raise InputError("fs", fs, "a positive finite sample rate in Hz (a number, or a string "
                                   "with a unit such as '20 kHz')")
    if pwvd_max_order is not None and not (isinstance(pwvd_max_order, int | float)
                                           and not isinstance(pwvd_max_order, bool)
                                           and math.isfinite(pwvd_max_order)
                                           and pwvd_max_order > 0):
        raise InputError("pwvd_max_order", pwvd_max_order,
                         "a finite positive order (shaft orders), or None for the default")
    arrays = {}
    for name, arr in signals.items():
        a = np.asarray(arr, dtype=np.float64)
        if a.ndim != 1:
            raise InputError(f"signals[{name!r}]", f"array of shape {a.shape}", "a 1-D array")
        bad = np.flatnonzero(~np.isfinite(a))
        if bad.size:
            raise InputError(f"signals[{name!r}]",
                             f"{bad.size} non-finite value(s), first at index {bad[0]}",
                             "finite numbers only (no NaN or inf)")
        peak = float(np.max(np.abs(a))) if a.size else 0.0
        if peak > MAX_SIGNAL_MAGNITUDE:
            raise InputError(f"signals[{name!r}]", f"max |x| = {peak:.3g}",
                             f"|x| <= {MAX_SIGNAL_MAGNITUDE:g} in its unit: the PWVD and the "
                             "energy metrics are in unit^2, which float64 cannot hold beyond "
                             "1e308 (rescale the signal, e.g. express it in another unit)")
        arrays[name] = a
    lengths = {a.shape[0] for a in arrays.values()}
    if len(lengths) != 1:
        raise InputError("signals", {k: v.shape[0] for k, v in arrays.items()},
                         "signals of equal length")
    stack = np.stack(list(arrays.values()))
    t_res = tsa(stack, angle=angle, fs=fs, time=time, tach_times=tach_times,
                pulses_per_rev=pulses_per_rev, samples_per_rev=samples_per_rev,
                n_revolutions=n_revolutions, skip_revolutions=skip_revolutions)
    n = t_res.samples_per_rev
    max_order = pwvd_max_order
    if max_order is None:
        max_order = min(n / 2, max(6, int(harmonic) + 1) * z)
    units = dict(units or {})
    results: dict[str, SignalDiagnosis] = {}
    for c, name in enumerate(arrays):
        avg = t_res.average[c]
        one = TSAResult(average=avg, angle=t_res.angle, n_averages=t_res.n_averages,
                        samples_per_rev=n, start_angle=t_res.start_angle,
                        oversampling=t_res.oversampling, method=t_res.method)
        flat = is_constant(avg)
        spectrum = order_spectrum(avg, scaling="rms")
        if not flat and doubt_teeth:
            _warn_if_not_meshing(spectrum, z, name)
        res = residual(avg, teeth=z, preset=residual_preset)
        dem = narrowband_demodulation(avg, teeth=z, harmonic=harmonic, bandwidth=bandwidth,
                                      remove_mean_phase=remove_mean_phase,
                                      envelope_excludes_carrier=envelope_excludes_carrier)
        results[name] = SignalDiagnosis(
            name=name,
            unit=units.get(name, ""),
            tsa=one,
            spectrum=spectrum,
            residual=res,
            regular=regular(avg, teeth=z),
            difference=difference(avg, teeth=z),
            demodulation=dem,
            pwvd_tsa=pwvd(avg, window_length=pwvd_window_length, max_order=max_order,
                          distribution=pwvd_distributions),
            pwvd_residual=pwvd(res, window_length=pwvd_window_length, max_order=max_order,
                               distribution=pwvd_distributions),
            statistics=signal_statistics(avg),
            # of a constant TSA (a stuck sensor) these are moments of round-off: NaN
            residual_kurtosis=math.nan if flat else kurtosis(res, warn_constant=False),
            envelope_kurtosis=math.nan if flat else kurtosis(dem.envelope, warn_constant=False),
            am_kurtosis=math.nan if flat else kurtosis(dem.am, warn_constant=False),
            pm_kurtosis=math.nan if flat else kurtosis(dem.pm, warn_constant=False),
            metrics=condition_metrics(avg, teeth=z, residual_preset=residual_preset),
        )
    return DiagnosisResult(
        signals=results, teeth=z, samples_per_rev=n, harmonic=int(harmonic),
        bandwidth=int(bandwidth), residual_preset=residual_preset, method=t_res.method,
        source=source,
        settings={
            "n_averages": t_res.n_averages,
            "shaft_speed_rev_s": shaft_speed(angle=angle, tach_times=tach_times,
                                             pulses_per_rev=pulses_per_rev, fs=fs, time=time,
                                             n=next(iter(lengths))),
            "start_angle_rad": t_res.start_angle,
            "antialias_oversampling": t_res.oversampling,
            "pulses_per_rev": int(pulses_per_rev) if tach_times is not None else None,
            "envelope_excludes_carrier": bool(envelope_excludes_carrier),
            "remove_mean_phase": bool(remove_mean_phase),
            "pwvd_max_order": float(max_order),
            "pwvd_window_length": None if pwvd_window_length is None else int(pwvd_window_length),
            "statistics_conventions": "std ddof=0; skewness g1; kurtosis Pearson (normal=3); "
                                      "crest_factor=max|x-mean|/std; crest_factor_rms=max|x|/rms",
        },
    )




#: How much the strongest order of a TSA (from order 3, above the shaft orders of runout and
#: eccentricity) must exceed every mesh harmonic, when it is not one, for :func:`diagnose` to
#: doubt the number of teeth [-].
NOT_MESHING_FACTOR = 3.0


def _warn_if_not_meshing(spectrum, teeth: int, name: str) -> None:
    """Warn when a TSA's strongest order (>= 3) is not a multiple of ``teeth`` and exceeds its
    largest mesh harmonic :data:`NOT_MESHING_FACTOR` times: a wrong tooth count puts the mesh
    order (and every metric built on it) in the wrong place, without any other sign."""
    amp = np.asarray(spectrum.amplitude, dtype=float)
    if amp.size <= max(3, teeth):
        return
    k = 3 + int(np.argmax(amp[3:]))
    mesh = amp[teeth::teeth]
    if k % teeth and mesh.size and amp[k] > NOT_MESHING_FACTOR * float(mesh.max()):
        warnings.warn(f"{name}: the TSA's strongest order is {k}, not a multiple of the mesh "
                      f"order {teeth} ({amp[k] / float(mesh.max()):.3g} times its largest mesh "
                      f"harmonic): has the gear on the averaged shaft {teeth} teeth? A "
                      "gear mesh puts its order at a multiple of the tooth count",
                      DiagnosticsWarning, stacklevel=3)

def shaft_speed(*, angle=None, tach_times=None, pulses_per_rev: int = 1, fs=None, time=None,
                n: int) -> dict | None:
    """Speed of the averaged shaft over the record [rev/s]: ``{"mean", "min", "max"}``, the
    extremes over whole revolutions (from the pulses, ``pulses_per_rev`` at a time, or from the
    angle's crossings of whole turns); None when the record holds no whole revolution.

    Printed beside the number of averaged revolutions (``geardyn diagnose``) so that a wrong
    ``pulses_per_rev`` or angle unit shows as a wrong speed. Arguments as for :func:`diagnose`
    (already checked by its TSA); ``n`` is the number of samples. An angle channel without
    sample times (no ``fs``, no ``time``) has no speed: None.
    """
    if tach_times is not None:
        tt = np.asarray(tach_times, dtype=np.float64)
        tt = tt[np.isfinite(tt)]
        k = int(pulses_per_rev)
        if tt.size <= k:
            return None
        per_rev = tt[k:] - tt[:-k]  # [s] per revolution, pulse to pulse
        mean = (tt.size - 1) / k / float(tt[-1] - tt[0])
    else:
        if fs is None and time is None:  # an angle without times: no speed to tell
            return None
        a = np.asarray(angle, dtype=np.float64)
        t = (np.arange(n) / float(fs)) if time is None else np.asarray(time, dtype=np.float64)
        turns = (a - a[0]) / (2 * math.pi)
        if turns[-1] < 1.0:
            return None
        crossings = np.interp(np.arange(0.0, math.floor(turns[-1]) + 1.0), turns, t)
        per_rev = np.diff(crossings)
        mean = float(turns[-1]) / float(t[-1] - t[0])
    speeds = 1.0 / per_rev[per_rev > 0]
    if speeds.size == 0:
        return None
    return {"mean": float(mean), "min": float(speeds.min()), "max": float(speeds.max())}

def diagnose_file(
    path,
    *,
    teeth: int | None = None,
    signals: Sequence[str | int] | str | int | None = None,
    fs: float | None = None,
    time: str | int | None = None,
    angle: str | int | None = None,
    tach: str | int | None = None,
    tach_column_is_pulse_times: bool = False,
    pulses_per_rev: int | None = None,
    tach_threshold: float | None = None,
    tach_edge: str = "rising",
    tach_min_interval: float | None = None,
    angle_unit: str | None = None,
    unwrap_angle: bool = False,
    default_teeth: int | None = None,
    option_names: Mapping[str, str] | None = None,
    **options,
) -> DiagnosisResult:
    """Load a file (simulation NetCDF or measured data) and run :func:`diagnose` on it.

    For a simulation result only ``signals`` (data variable names; default the paper's three)
    and ``teeth`` (default the ``pinion_teeth`` attribute) are used, the angle is ``theta_p``;
    it has its own time axis, so ``fs`` (other than its own rate) and ``time`` (other than
    ``"time"``) are refused. For measured data ``signals`` are column names/positions and
    ``teeth`` defaults to what the file says (:func:`load_measurement`), else
    ``default_teeth``; see :func:`load_measurement` for the sampling and angle arguments.

    Parameters
    ----------
    path : str or path-like
        The input file.
    teeth : int, optional
        Z [-].
    signals : str, int or sequence, optional
        Signals to diagnose.
    fs, time, angle, tach, tach_column_is_pulse_times, pulses_per_rev, tach_threshold,
    tach_edge, tach_min_interval, angle_unit, unwrap_angle
        See :func:`load_measurement`.
    default_teeth : int, optional
        Z [-] for measured data whose file does not say it (the command line passes its case's
        pinion); a simulation result must say it.
    option_names : mapping, optional
        Names to give the arguments in error messages (argument -> name, e.g. ``{"fs":
        "--fs"}``); default the argument names.
    **options
        Passed to :func:`diagnose` (``samples_per_rev``, ``harmonic``, ``bandwidth``,
        ``residual_preset``, ...).

    Returns
    -------
    DiagnosisResult

    Raises
    ------
    DataFileError
        Besides the file problems of the loaders: a record too short to hold one whole
        revolution of the averaged shaft.
    InputError
        See :func:`load_simulation`, :func:`load_measurement` and :func:`diagnose`.
    """
    name_of = _namer(option_names)
    if not Path(path).exists():  # before any argument that only the file's content decides
        raise DataFileError(path, "no such file")
    if teeth is not None:
        _check_int(teeth, name_of("teeth"), 1, "a positive integer number of teeth")
    if isinstance(fs, str):  # "20 kHz", as the command line's --fs
        from ..units import parse_frequency

        fs = parse_frequency(fs, name_of("fs"))
    netcdf = Path(path).suffix.lower() in NETCDF_SUFFIXES
    if netcdf and (tach is not None or angle is not None) and _is_simulation_record(path):
        # its exact angle theta_p is what a tach or angle channel would approximate (and the
        # measured-data reading then asked for --signal and --fs: a user audit, 2026-11-27)
        given, value = ("tach", tach) if tach is not None else ("angle", angle)
        raise InputError(name_of(given), value,
                         f"no {name_of('tach')} or {name_of('angle')} for a geardyn simulation "
                         f"record: {Path(path).name} is averaged on its exact pinion angle "
                         f"(theta_p); they are for measured data (a geardyn measure file, a "
                         f"DAQ's file)")
    # a NetCDF file is read as a geardyn simulation (exact angle theta_p) unless the shaft angle
    # is given as for measured data (a tach or angle channel): then any NetCDF file of 1-D
    # channels (e.g. written by geardyn measure or a DAQ) reads like a CSV, fs from its attribute
    simulation = netcdf and tach is None and angle is None
    if simulation:
        sig = None if signals is None else ([signals] if isinstance(signals, str)
                                            else [str(s) for s in signals])
        m = load_simulation(path, signals=sig, option_names=option_names)
        _check_own_time_axis(path, m.time, fs, time, name_of)
        # the exact angle theta_p: the options of a measured angle would be ignored silently
        for key, value, idle in (("tach_column_is_pulse_times", tach_column_is_pulse_times,
                                  False), ("pulses_per_rev", pulses_per_rev, None),
                                 ("angle_unit", angle_unit, None), ("tach_edge", tach_edge,
                                                                     "rising"),
                                 ("unwrap_angle", unwrap_angle, False),
                                 ("tach_threshold", tach_threshold, None),
                                 ("tach_min_interval", tach_min_interval, None)):
            if value != idle:
                raise InputError(name_of(key), value,
                                 f"no {name_of(key)} for a geardyn simulation result: "
                                 f"{Path(path).name} carries its exact shaft angle (theta_p); "
                                 f"it applies to a measured {name_of('tach')} or "
                                 f"{name_of('angle')} channel")
    else:
        if signals is None:  # name the columns there are (the file is read for them)
            from .io import read_table

            try:
                names = read_table(path).names
            except GeardynError:
                names = []
            shown = ", ".join(repr(n) for n in names[:12]) + (" ..." if len(names) > 12
                                                              else "")
            raise InputError(name_of("signals"), NOT_GIVEN,
                             "the column(s) to diagnose (name or position)"
                             + (f": one of {shown}" if shown else ""))
        m = load_measurement(path, signal=signals, fs=fs, time=time, angle=angle, tach=tach,
                             tach_column_is_pulse_times=tach_column_is_pulse_times,
                             pulses_per_rev=pulses_per_rev, tach_threshold=tach_threshold,
                             tach_edge=tach_edge, tach_min_interval=tach_min_interval,
                             angle_unit=angle_unit, unwrap_angle=unwrap_angle,
                             option_names=option_names)
    if teeth is not None and m.teeth is not None and int(teeth) != m.teeth:
        # the file states the teeth of the shaft it averages over: another count puts every
        # mesh order in the wrong place (no error otherwise, only wrong numbers)
        shaft = "the pinion (theta_p)" if simulation else "the tachometer's shaft"
        raise InputError(name_of("teeth"), int(teeth),
                         f"{Path(path).name}'s own count for {shaft}, {m.teeth}, or no "
                         f"{name_of('teeth')}: the file states it")
    z = teeth if teeth is not None else m.teeth
    if z is None and not simulation:
        z = default_teeth
    if z is None:
        raise InputError(name_of("teeth"), None,
                         "the number of teeth of the gear on the averaged shaft ("
                         f"{Path(path).name} stores neither it nor the case it was made with)")
    try:
        return diagnose(m.signals, teeth=z, fs=m.fs, time=m.time, angle=m.angle,
                        tach_times=m.tach_times, pulses_per_rev=m.pulses_per_rev,
                        units=m.units, source=str(path),
                        **{"doubt_teeth": m.teeth is None, **options})
    except ShortRecordError as exc:
        raise _short_record(path, m, exc, simulation) from None
    except InputError as exc:
        raise _renamed(exc, name_of) from None


def _wrapped_deg(phase: float) -> float:
    """``phase`` [rad] in degrees, wrapped to (-180, 180]."""
    deg = math.degrees(math.remainder(phase, 2.0 * math.pi))
    return 180.0 if deg == -180.0 else deg


def _is_simulation_record(path) -> bool:
    """Whether the NetCDF file ``path`` is a geardyn simulation record (``theta_p`` and the
    ``pinion_teeth`` attribute); False for any other file, readable or not (its reader says
    what is wrong with it)."""
    from ..io import NETCDF_LOCK, open_netcdf

    try:
        with NETCDF_LOCK:  # from the file's opening to its closing
            ds = open_netcdf(path)
            try:
                return "theta_p" in ds.variables and "pinion_teeth" in ds.attrs
            finally:
                ds.close()
    except Exception:  # noqa: BLE001 - not a readable NetCDF file: not a simulation record
        return False


#: Arguments of :func:`diagnose` named by the :func:`diagnose_file` argument they come from
#: (the pulse times from the ``tach`` channel), for the error messages of a file's diagnosis.
_FILE_ARGUMENT_OF = {"tach_times": "tach", "angle": "angle", "fs": "fs", "time": "time",
                     "teeth": "teeth", "pulses_per_rev": "pulses_per_rev",
                     "harmonic": "harmonic", "bandwidth": "bandwidth",
                     "samples_per_rev": "samples_per_rev", "residual_preset": "residual_preset"}


def _renamed(exc: InputError, name_of) -> InputError:
    """``exc`` of :func:`diagnose` with its field named as the caller of :func:`diagnose_file`
    knows it (``tach_times`` -> ``tach``, or the command-line option ``--tach``); ``exc`` as it
    is when nothing changes."""
    import re

    m = re.fullmatch(r"signals\[(['\"])(.*)\1\]", str(exc.field))
    if m:  # diagnose's signals['acc']: the file's column, as the caller named it
        return InputError(f"{name_of('signals')} {m.group(2)!r}", exc.value, exc.allowed)
    parts = str(exc.field).split("/")
    field = "/".join(name_of(_FILE_ARGUMENT_OF[p]) if p in _FILE_ARGUMENT_OF else p
                     for p in parts)
    return exc if field == exc.field else InputError(field, exc.value, exc.allowed)


def _check_own_time_axis(path, time_axis: np.ndarray, fs, time, name_of) -> None:
    """A simulation result samples on its own ``time`` axis: refuse an ``fs`` (other than its
    own rate) or a ``time`` column (other than ``"time"``) instead of ignoring them."""
    file_name = Path(path).name
    if fs is not None:
        steps = np.diff(time_axis)
        rate = 1.0 / float(np.median(steps)) if steps.size and np.median(steps) > 0 else None
        if rate is None or not _same_rate(fs, rate):
            own = f"{rate:.10g} Hz" if rate is not None else "its time axis"
            raise InputError(name_of("fs"), f"{fs:.10g} Hz",
                             f"no {name_of('fs')} for a geardyn simulation result: "
                             f"{file_name} has its own time axis ({own})")
    if time is not None and str(time) != "time":
        raise InputError(name_of("time"), time,
                         f"no {name_of('time')} for a geardyn simulation result: {file_name} "
                         "has its own time axis ('time')")


def _short_record(path, m: Measurement, exc: ShortRecordError,
                  simulation: bool) -> DataFileError:
    """The TSA's "no whole revolution" in the terms of the file: how many revolutions the
    record spans, what is needed and, when the speed is known, how long a record would do."""
    revs, skip = exc.revolutions, exc.skip
    need = skip + 2  # any record of skip + 2 revolutions holds a whole one after the skip
    seconds = per_rev = None
    if m.time is not None and m.time.size > 1:
        seconds = float(m.time[-1] - m.time[0])
    elif m.fs:
        seconds = (next(iter(m.signals.values())).shape[0] - 1) / m.fs
    if m.tach_times is not None and m.tach_times.size > 1:
        tt = m.tach_times
        per_rev = float(tt[-1] - tt[0]) * m.pulses_per_rev / (tt.size - 1)
    elif seconds is not None and revs > 0:
        per_rev = seconds / revs
    text = (f"too short to diagnose: the record spans {revs:.3g} revolutions of the averaged "
            "shaft" + (f" ({skip} to be skipped at the start)" if skip else "")
            + f"; the average needs one whole revolution ({need} revolutions always hold one)")
    now = f"this one is {seconds:.3g} s" if seconds is not None else ""
    if per_rev is not None and np.isfinite(per_rev) and per_rev > 0:
        long = f"{need * per_rev:.3g} s"
        if simulation:
            text += f": simulate at least {long} (simulation.record_time; {now or 'longer'})"
        else:
            text += f": record at least {long} at this speed" + (f" ({now})" if now else "")
    else:
        text += ": a longer record is needed"
    return DataFileError(path, text)
