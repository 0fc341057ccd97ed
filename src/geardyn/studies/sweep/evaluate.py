"""What one sweep run computes: the :class:`Evaluator` interface and geardyn's own.

:class:`GeardynEvaluator` runs :func:`evaluate_run`: the stiffness map (memoised per worker
process, disk-cached by :func:`geardyn.stiffness.build_map`), :func:`geardyn.dynamics.simulate`
and the diagnostics chain on the paper's three signals.
"""

from __future__ import annotations

import functools
import math
from collections.abc import Mapping
from dataclasses import dataclass
from typing import Any

import numpy as np

from ...config import Case
from ...errors import InputError
from .signals import RECORD_SIGNALS, check_signal_names, short_record_error
from .spec import StoreSpec

__all__ = ["Output", "Evaluator", "GeardynEvaluator", "evaluate_run", "diagnostic_features"]

# ============================================================================================
# evaluation of one run
# ============================================================================================
@dataclass(frozen=True)
class Output:
    """A per-run result variable of the store.

    Attributes
    ----------
    name : str
        Variable name.
    units : str
        Unit (``"1"`` for dimensionless).
    long_name : str
        Description.
    dims : tuple of str
        Dimensions besides ``run`` (e.g. ``("tsa_angle",)``).
    shape : tuple of int
        Their lengths.
    """

    name: str
    units: str
    long_name: str
    dims: tuple[str, ...] = ()
    shape: tuple[int, ...] = ()


class Evaluator:
    """What a sweep computes for each run (subclass it to store your own results).

    A subclass defines :meth:`outputs` (the variables, from the base case) and
    :meth:`__call__` (one run: a case and its seed in, a dict of those variables out; float64
    values, arrays for outputs with dimensions). It must be picklable (it is sent to the Dask
    workers) and deterministic given the case and the seed, so a recomputed run gives the same
    values. Exceptions are caught per run and recorded as failures.
    """

    #: True if :meth:`outputs` needs one evaluated run (``pilot``) to know array lengths.
    needs_pilot: bool = False

    def outputs(self, case: Case, pilot: Mapping[str, Any] | None = None) -> list[Output]:
        """The result variables (names, units, extra dimensions)."""
        raise NotImplementedError

    def coords(self, case: Case, pilot: Mapping[str, Any] | None = None
               ) -> dict[str, tuple[np.ndarray, dict]]:
        """Coordinates of the extra dimensions: name -> (values, attrs)."""
        return {}

    def __call__(self, case: Case, seed: int) -> dict[str, Any]:
        """Evaluate one run."""
        raise NotImplementedError

    def prepare_key(self, case: Case) -> str | None:
        """Runs with the same key share :meth:`prepare` (None: nothing to prepare)."""
        return None

    def prepare(self, case: Case) -> None:
        """Shared work done once per key before the runs (e.g. a stiffness map)."""

    def identity(self) -> dict:
        """JSON-able description (part of the sweep hash)."""
        return {"evaluator": f"{type(self).__module__}.{type(self).__qualname__}"}


_STATISTICS = [  # (field of SignalStatistics, unit is the signal's?, long name)
    ("mean", True, "mean of the TSA"),
    ("std", True, "standard deviation of the TSA (ddof 0)"),
    ("rms", True, "RMS of the TSA"),
    ("peak_to_peak", True, "peak-to-peak of the TSA"),
    ("skewness", False, "skewness g1 of the TSA"),
    ("kurtosis", False, "Pearson kurtosis of the TSA"),
    ("crest_factor", False, "crest factor max|x - mean|/std of the TSA"),
    ("crest_factor_rms", False, "crest factor max|x|/RMS of the TSA"),
]
_KURTOSES = [
    ("residual_kurtosis", "kurtosis of the residual signal"),
    ("envelope_kurtosis", "kurtosis of the envelope about the demodulated mesh harmonic"),
    ("am_kurtosis", "kurtosis of the amplitude modulation"),
    ("pm_kurtosis", "kurtosis of the phase modulation"),
]
_METRICS = [
    ("FM0", "FM0: peak-to-peak / sum of mesh harmonic amplitudes"),
    ("FM4", "FM4: kurtosis of the difference signal"),
    ("M6A", "M6A: sixth normalised moment of the difference signal"),
    ("M8A", "M8A: eighth normalised moment of the difference signal"),
    ("NA4", "NA4 of the residual (single record)"),
    ("NB4", "NB4 of the envelope (single record)"),
    ("EnergyRatio", "energy ratio RMS(difference)/RMS(regular)"),
]

#: Record summaries of :func:`geardyn.dynamics.summary` stored per run:
#: (summary key, variable, unit, scale to SI, long name).
_SUMMARY = [
    ("mean_pinion_speed_rad_s", "sim__mean_pinion_speed", "rad/s", 1.0,
     "mean pinion angular velocity"),
    ("mean_mesh_force_N", "sim__mean_mesh_force", "N", 1.0, "mean normal mesh force"),
    ("mean_centre_distance_change_m", "sim__mean_centre_distance_change", "m", 1.0,
     "mean operating minus design centre distance (eq. 4)"),
    ("mean_pressure_angle_deg", "sim__mean_pressure_angle", "rad", math.pi / 180.0,
     "mean operating pressure angle (eq. 6)"),
    ("mean_contact_ratio", "sim__mean_contact_ratio", "1", 1.0,
     "mean operating contact ratio, physical"),
    ("mean_contact_ratio_eq8", "sim__mean_contact_ratio_eq8", "1", 1.0,
     "mean operating contact ratio by the paper's eq. 8"),
    ("mean_transmission_error_rad", "sim__mean_transmission_error", "rad", 1.0,
     "mean transmission error"),
    ("std_transmission_error_rad", "sim__std_transmission_error", "rad", 1.0,
     "standard deviation of the transmission error"),
    ("separation_fraction", "sim__separation_fraction", "1", 1.0,
     "fraction of recorded steps with the teeth separated"),
    ("steps_iterating_fraction", "sim__steps_iterating_fraction", "1", 1.0,
     "fraction of recorded steps needing centre-distance iterations (model II)"),
    ("max_iterations", "sim__max_iterations", "1", 1.0,
     "most centre-distance iterations in a recorded step (model II)"),
]


def _kurt(x: np.ndarray) -> float:
    from ...diagnostics import kurtosis  # the one kurtosis helper (NaN for a constant record)

    return kurtosis(x, warn_constant=False)


def diagnostic_features(signals: Mapping[str, np.ndarray], angle: np.ndarray, *, teeth: int,
                        samples_per_rev: int = 2048, harmonic: int = 5, bandwidth: int = 11,
                        residual_preset: str = "paper", mesh_harmonics: int | None = None,
                        keep_tsa: bool = False) -> dict[str, Any]:
    """Per-signal statistics, kurtoses and condition metrics of the TSA (the sweep's results).

    The same chain and conventions as :func:`geardyn.diagnostics.diagnose` (TSA against the
    exact shaft angle; residual per ``residual_preset``; narrowband demodulation about mesh
    harmonic ``harmonic`` +/- ``bandwidth`` orders; Table 2 statistics; condition metrics) without
    the time-frequency distributions, which a sweep does not store and which cost most of
    ``diagnose``'s time (``tests/sweep/test_evaluate.py`` checks the values against
    ``diagnose(...).to_dict()``).

    Parameters
    ----------
    signals : mapping of str to ndarray
        Signals of equal length (their own units).
    angle : ndarray
        Shaft angle of every sample [rad], increasing.
    teeth : int
        Teeth on the averaged shaft [-].
    samples_per_rev, harmonic, bandwidth, residual_preset
        As in :func:`~geardyn.diagnostics.diagnose`.
    mesh_harmonics : int, optional
        Mesh harmonics whose RMS amplitude is returned (default ``harmonic + 1``).
    keep_tsa : bool
        Also return each TSA (``<signal>__tsa``).

    Returns
    -------
    dict
        ``<signal>__<name>`` floats (see :class:`GeardynEvaluator` for the list), ``n_averages``,
        ``<signal>__mesh_harmonic_rms`` arrays and optionally ``<signal>__tsa`` arrays.
    """
    from ...diagnostics import (
        condition_metrics,
        narrowband_demodulation,
        order_spectrum,
        residual,
        signal_statistics,
        tsa,
    )

    names = list(signals)
    stack = np.stack([np.asarray(signals[n], dtype=np.float64) for n in names])
    t_res = tsa(stack, angle=angle, samples_per_rev=samples_per_rev)
    h = mesh_harmonics if mesh_harmonics is not None else harmonic + 1
    out: dict[str, Any] = {"n_averages": float(t_res.n_averages)}
    for c, name in enumerate(names):
        avg = t_res.average[c]
        stats = signal_statistics(avg)
        for f, _, _ in _STATISTICS:
            out[f"{name}__{f}"] = float(getattr(stats, f))
        res = residual(avg, teeth=teeth, preset=residual_preset)
        dem = narrowband_demodulation(avg, teeth=teeth, harmonic=harmonic, bandwidth=bandwidth)
        out[f"{name}__residual_kurtosis"] = _kurt(res)
        out[f"{name}__envelope_kurtosis"] = _kurt(dem.envelope)
        out[f"{name}__am_kurtosis"] = _kurt(dem.am)
        out[f"{name}__pm_kurtosis"] = _kurt(dem.pm)
        cm = condition_metrics(avg, teeth=teeth, residual_preset=residual_preset)
        for f, _ in _METRICS:
            out[f"{name}__{f}"] = float(getattr(cm, f))
        amp = order_spectrum(avg, scaling="rms").amplitude
        orders = teeth * np.arange(1, h + 1)
        out[f"{name}__mesh_harmonic_rms"] = np.where(orders < amp.shape[-1],
                                                     amp[np.minimum(orders, amp.shape[-1] - 1)],
                                                     np.nan)
        if keep_tsa:
            out[f"{name}__tsa"] = avg.copy()
    return out


class _MapRequest:
    """A case that hashes and compares by the key of its map's inputs (the memo's key)."""

    __slots__ = ("key", "case")

    def __init__(self, key: str, case: Case):
        self.key, self.case = key, case

    def __hash__(self) -> int:
        return hash(self.key)

    def __eq__(self, other: object) -> bool:
        return isinstance(other, _MapRequest) and other.key == self.key


@functools.lru_cache(maxsize=32)
def _cached_map(request: _MapRequest):
    """The stiffness maps of this worker process: the 32 most recently used, by inputs' key."""
    from ...stiffness import build_map

    return build_map(request.case, cracked=True)


def _stiffness_map(case: Case):
    """The case's (cracked) stiffness map, memoised per process by its inputs' hash
    (:func:`geardyn.cache.cache_key` of :func:`geardyn.stiffness.map_inputs`, the key of the
    disk cache)."""
    from ...cache import cache_key
    from ...stiffness import map_inputs

    return _cached_map(_MapRequest(cache_key(map_inputs(case, case.stiffness.method, True)), case))


def evaluate_run(case: Case, store_options: StoreSpec | None = None, seed: int = 0
                 ) -> dict[str, Any]:
    """One sweep run: stiffness map, simulation, diagnostics.

    The map comes from :func:`geardyn.stiffness.build_map` (disk cache) through a per-process
    memo; :func:`geardyn.dynamics.simulate` runs the case's model; the recorded signals
    (``store_options.signals``, by default the paper's ``v_yg`` [m/s], ``omega_p`` [rad/s] and
    ``transmission_error`` [rad]) are averaged against the exact pinion angle ``theta_p`` with
    the pinion's teeth and reduced by :func:`diagnostic_features` with the case's
    ``[diagnostics]`` settings. With ``noise_snr_db``, white Gaussian noise of standard deviation
    ``std(x) 10^(-SNR/20)`` is added to each signal first, drawn from
    ``numpy.random.default_rng(seed)``.

    Parameters
    ----------
    case : Case
        The run's case.
    store_options : StoreSpec, optional
        What to return besides the metrics (default :class:`StoreSpec()`).
    seed : int
        The run's seed (used only for the measurement noise).

    Returns
    -------
    dict
        Variable name -> float or array (see :class:`GeardynEvaluator`).

    Raises
    ------
    GeardynError
        From the geometry, the map, the simulation (NumericalError on divergence) or the
        diagnostics.
    """
    from ...diagnostics.tsa import ShortRecordError
    from ...dynamics import simulate, summary

    opts = store_options or StoreSpec()
    m = _stiffness_map(case)
    ds = simulate(case, m)
    missing = [s for s in [*opts.signals, "theta_p"] if s not in ds.variables]
    if missing:
        raise InputError("store.signals", missing, "variables of the simulation result: "
                                                   + ", ".join(sorted(ds.data_vars)))
    signals = {s: np.asarray(ds[s].values, dtype=np.float64) for s in opts.signals}
    angle = np.asarray(ds["theta_p"].values, dtype=np.float64)
    if opts.noise_snr_db is not None:
        rng = np.random.default_rng(seed)
        scale = 10.0 ** (-opts.noise_snr_db / 20.0)
        signals = {k: v + rng.standard_normal(v.shape) * (np.std(v) * scale)
                   for k, v in signals.items()}
    d = case.diagnostics
    teeth = int(np.asarray(ds.attrs.get("pinion_teeth", case.pinion.teeth)).reshape(-1)[0])
    try:
        out = diagnostic_features(signals, angle, teeth=teeth, samples_per_rev=d.samples_per_rev,
                                  harmonic=d.harmonic, bandwidth=d.bandwidth,
                                  residual_preset=d.residual_preset, keep_tsa=opts.tsa)
    except ShortRecordError as exc:  # in the sweep's terms: simulation.record_time
        raise short_record_error(exc, ds, case) from None
    summ = summary(ds)
    for key, name, _, scale, _ in _SUMMARY:
        out[name] = float(summ[key]) * scale
    if opts.raw:
        for s in [*opts.signals, "theta_p"]:
            out[f"{s}__series"] = signals.get(s, angle) if s != "theta_p" else angle
        t = np.asarray(ds["time"].values, dtype=np.float64)
        out["__time__"] = t - t[0]
    return out


class GeardynEvaluator(Evaluator):
    """The standard sweep run: :func:`evaluate_run` and its variables.

    Per signal ``s`` (unit u): ``s__mean``, ``s__std``, ``s__rms``, ``s__peak_to_peak`` (u);
    ``s__skewness``, ``s__kurtosis``, ``s__crest_factor``, ``s__crest_factor_rms`` (the TSA's
    statistics, paper Table 2); ``s__residual_kurtosis``, ``s__envelope_kurtosis``,
    ``s__am_kurtosis``, ``s__pm_kurtosis`` (Table 3); ``s__FM0``, ``s__FM4``, ``s__M6A``,
    ``s__M8A``, ``s__NA4``, ``s__NB4``, ``s__EnergyRatio`` (condition metrics; MATLAB's RMS,
    Kurtosis and CrestFactor are ``s__rms``, ``s__kurtosis`` and ``s__crest_factor_rms``; NA4*
    needs a healthy baseline and is not stored); ``s__mesh_harmonic_rms`` (u, along
    ``mesh_harmonic``); with ``tsa``, ``s__tsa`` (u, along ``tsa_angle``); with ``raw``,
    ``s__series`` and ``theta_p__series`` (along ``time``). Also ``n_averages`` (revolutions
    averaged) and the record's summary (:func:`geardyn.dynamics.summary`, SI):
    ``sim__mean_pinion_speed`` [rad/s], ``sim__mean_mesh_force`` [N],
    ``sim__mean_centre_distance_change`` [m], ``sim__mean_pressure_angle`` [rad],
    ``sim__mean_contact_ratio``, ``sim__mean_contact_ratio_eq8``,
    ``sim__mean_transmission_error``, ``sim__std_transmission_error`` [rad],
    ``sim__separation_fraction``, ``sim__steps_iterating_fraction``, ``sim__max_iterations``.

    Parameters
    ----------
    store : StoreSpec
        The sweep's ``[store]`` section.
    """

    def __init__(self, store: StoreSpec | None = None):
        self.store = store or StoreSpec()
        check_signal_names(self.store.signals)

    @property
    def needs_pilot(self) -> bool:  # type: ignore[override]
        return self.store.raw

    def _units(self, signal: str) -> str:
        return RECORD_SIGNALS[signal]  # __init__ accepts only these names

    def outputs(self, case: Case, pilot: Mapping[str, Any] | None = None) -> list[Output]:
        d = case.diagnostics
        outs = [Output("n_averages", "1", "whole revolutions in the synchronous average")]
        outs += [Output(name, unit, long) for _, name, unit, _, long in _SUMMARY]
        for s in self.store.signals:
            u = self._units(s)
            for f, own, desc in _STATISTICS:
                outs.append(Output(f"{s}__{f}", u if own else "1", f"{desc} of {s}"))
            for f, desc in _KURTOSES:
                outs.append(Output(f"{s}__{f}", "1", f"{desc} of {s}"))
            for f, desc in _METRICS:
                outs.append(Output(f"{s}__{f}", "1", f"{desc} of {s}"))
            outs.append(Output(f"{s}__mesh_harmonic_rms", u, f"RMS amplitude of the mesh "
                                                             f"harmonics of the TSA of {s}",
                               ("mesh_harmonic",), (d.harmonic + 1,)))
            if self.store.tsa:
                outs.append(Output(f"{s}__tsa", u, f"synchronous average of {s} over the "
                                                   "pinion angle", ("tsa_angle",),
                                   (d.samples_per_rev,)))
        if self.store.raw:
            if pilot is None:
                raise InputError("store.raw", True, "a pilot run to size the series")
            n = int(np.asarray(pilot["__time__"]).shape[0])
            for s in [*self.store.signals, "theta_p"]:
                outs.append(Output(f"{s}__series", self._units(s) if s != "theta_p" else "rad",
                                   f"recorded {s}" + (" (with the added noise)"
                                                      if self.store.noise_snr_db is not None
                                                      and s != "theta_p" else ""),
                                   ("time",), (n,)))
        return outs

    def coords(self, case: Case, pilot: Mapping[str, Any] | None = None
               ) -> dict[str, tuple[np.ndarray, dict]]:
        d = case.diagnostics
        out = {"mesh_harmonic": (np.arange(1, d.harmonic + 2), {
            "units": "1", "long_name": "mesh harmonic (order / pinion teeth)"})}
        if self.store.tsa:
            n = d.samples_per_rev
            out["tsa_angle"] = (2 * np.pi * np.arange(n) / n, {
                "units": "rad", "long_name": "pinion angle within the averaged revolution"})
        if self.store.raw and pilot is not None:
            out["time"] = (np.asarray(pilot["__time__"], dtype=np.float64), {
                "units": "s", "long_name": "time from the start of the recording"})
        return out

    def __call__(self, case: Case, seed: int) -> dict[str, Any]:
        return evaluate_run(case, self.store, seed)

    def prepare_key(self, case: Case) -> str | None:
        from ...cache import cache_key
        from ...stiffness import map_inputs

        return cache_key(map_inputs(case, case.stiffness.method, True))

    def prepare(self, case: Case) -> None:
        _stiffness_map(case)

    def identity(self) -> dict:
        return {"evaluator": "geardyn.studies.sweep.GeardynEvaluator",
                "store": self.store.model_dump(mode="json")}


