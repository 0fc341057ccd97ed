"""The measurement stage of ``geardyn run``: the paper's indicators on a realistic measurement.

The paper computes its Table 2/3 statistics and the condition metrics on noise-free state
velocities of perfect teeth. This stage computes the same indicators on what a condition-monitoring
engineer records: the housing acceleration at a sensor (the case's ``[measurement]`` chain:
transfer path, accelerometer, anti-alias filter, sampling, ADC, noise) with the shaft angle from
a once-per-rev tachometer (TSA through the pulse spline, not the simulated angle), on gears with
ISO 1328-1 tooth errors. Four variants, healthy and cracked, show which input drives which
indicator:

========================  =============================  =======================================
variant                   tooth errors                   sensor noise
========================  =============================  =======================================
``ideal``                 none (perfect involutes)       none (no additive noise, no ADC, no
                                                         tachometer jitter)
``errors``                :data:`DEFAULT_ERRORS`          none
``noise``                 none                           the case's chain (SNR, ADC, jitter)
``errors+noise``          :data:`DEFAULT_ERRORS`          the case's chain: *the realistic record*
========================  =============================  =======================================

Cost, reuse and cache: the records without errors are the simulation stage's own records (the
case's model, healthy and cracked); only the two records with errors are new simulations of the
same length, through the same on-disk cache as the simulation stage
(:func:`geardyn.studies.paper.cached_simulation`, passed in by the pipeline). The chain and the
indicators take well under a second per variant; their results are cached too (kind
``"measurement"``), keyed by the case, the maps, the model and the error and chain settings.
The measured record is shorter than the simulated one by the chain's lead-in and tail
(:meth:`geardyn.measurement.MeasurementChain.lead_in`, about 0.08 s with the default housing
mode). A case whose own ``[modifications]`` are active uses those as its errors (its simulation
records then hold them, and the error-free variants are the new simulations).

Module layout: imports the measurement chain, the diagnostics and the cache, never the pipeline
(:mod:`.paper`) or the report; the report reads ``summary["measurement"]``.
"""

from __future__ import annotations

import math
import warnings
from collections.abc import Callable

import numpy as np

from ..config import Case, case_to_toml
from .paper_result import StudyResult
from .paper_values import CONDITION_METRICS

__all__ = ["DEFAULT_ERRORS", "DEFAULT_ERRORS_SOURCE", "VARIANTS", "INDICATORS",
           "HOUSING_DAMPING", "measurement_stage", "measured_indicators", "drivers",
           "detections", "housing_damping_sweep", "MEASUREMENT_CACHE_VERSION",
           "reproduce_commands", "NOT_COMPUTED"]

#: Tooth errors of the realistic record when the case has none: ISO 1328-1:2013 flank
#: tolerance class 6 on both gears (the issue's proposed default), drawn with the seeds of
#: ``examples/tooth_errors/case.toml`` (pinion 1, gear 2) over the whole tolerance
#: (``fraction = 1``: cumulative pitch deviation = F_pT). No relief, no runout.
DEFAULT_ERRORS = {"modifications.pinion.grade": 6, "modifications.pinion.seed": 1,
                  "modifications.gear.grade": 6, "modifications.gear.seed": 2}
DEFAULT_ERRORS_SOURCE = ("issue 14 default: ISO 1328-1:2013 flank tolerance class 6 on both "
                         "gears, pitch and profile deviations drawn with seeds 1 (pinion) and 2 "
                         "(gear), spanning the full tolerance")

#: The four variants: name -> (tooth errors, sensor noise).
VARIANTS = {"ideal": (False, False), "errors": (True, False), "noise": (False, True),
            "errors+noise": (True, True)}

#: Indicators shown, in order: (key, label, source table). Table 2's mean and STD are left
#: out (dimensional: m/s on the state velocity, m/s^2 on the accelerometer).
INDICATORS = (
    ("kurtosis", "TSA kurtosis", "Table 2"),
    ("crest_factor", "TSA crest factor", "Table 2"),
    ("envelope_kurtosis", "envelope kurtosis", "Table 3"),
    ("am_kurtosis", "AM kurtosis", "Table 3"),
    ("pm_kurtosis", "PM kurtosis", "Table 3"),
    ("residual_kurtosis", "residual kurtosis", "Table 3"),
    *((k, k.replace("NA4star", "NA4*").replace("EnergyRatio", "energy ratio"),
       "condition metrics") for k in CONDITION_METRICS if k != "Kurtosis"),
)

#: Bump when the stage's results change meaning, so cached results are recomputed.
MEASUREMENT_CACHE_VERSION = "4"

#: Damping ratios of the housing modes [-] over which the realistic record's indicators are
#: recomputed (every mode of the case's modal path set to each): how much of a healthy
#: indicator the transfer path makes (``docs/verification/measurement.md``).
HOUSING_DAMPING = (0.005, 0.01, 0.02, 0.05, 0.1)
#: Indicators recomputed over :data:`HOUSING_DAMPING`.
HOUSING_INDICATORS = ("FM4", "NA4star", "EnergyRatio")

#: A change of an indicator by less than this factor either way is "no change" [-].
UNCHANGED_FACTOR = 1.1
#: The crack counts as detected when cracked / healthy exceeds this (as in the report's
#: condition-metrics table) [-].
DETECTION_RATIO = 1.5


def _variant_cases(case: Case, sim_case: Case) -> tuple[Case, Case, str]:
    """``(case without errors, case with errors, description of the errors)``."""
    from ..faults import without_faults
    from ..modifications import ToothModifications

    if ToothModifications.from_case(without_faults(sim_case)).active:  # errors, not wear
        plain = sim_case.model_copy(update={"modifications": None})
        return plain, sim_case, ("the case's own [modifications]: "
                                 + ToothModifications.from_case(
                                     without_faults(sim_case)).describe())
    err = sim_case.with_overrides(DEFAULT_ERRORS, source=DEFAULT_ERRORS_SOURCE)
    return sim_case, err, ("issue 14 default, drawn deviations spanning the whole tolerance "
                           "(cumulative pitch deviation = F_pT): "
                           + ToothModifications.from_case(without_faults(err)).describe())


def _chains(case: Case):
    """``{False: noise-free chain, True: the case's chain}``."""
    from ..config import MeasurementConfig
    from .measure import chain_from_config

    cfg = case.measurement if case.measurement is not None else MeasurementConfig()
    clean = cfg.model_copy(update={"snr": math.inf, "noise_level": None, "adc_bits": 0,
                                   "tach_jitter": 0.0})
    return {False: chain_from_config(clean), True: chain_from_config(cfg)}


def measured_indicators(avg: np.ndarray, *, teeth: int, harmonic: int, bandwidth: int,
                        residual_preset: str, na4_baseline_variance: float | None) -> dict:
    """The paper's Table 2/3 statistics and the condition metrics of one TSA.

    The same definitions as :func:`geardyn.diagnostics.diagnose` (statistics, narrowband
    demodulation about ``harmonic``, residual by ``residual_preset``) and as the report's
    condition-metrics table (:func:`geardyn.diagnostics.condition_metrics`, NA4* against
    ``na4_baseline_variance``), without the time-frequency distributions.

    Parameters
    ----------
    avg : ndarray
        One-revolution TSA (any unit).
    teeth, harmonic, bandwidth : int
        Teeth of the averaged gear, demodulated mesh harmonic and half band [orders].
    residual_preset : str
        Residual of Table 3's residual kurtosis.
    na4_baseline_variance : float, optional
        Healthy residual variance (unit^2) for NA4*.

    Returns
    -------
    dict
        Indicator key (:data:`INDICATORS`) -> float.
    """
    import warnings

    from ..diagnostics import (
        DiagnosticsWarning,
        condition_metrics,
        narrowband_demodulation,
        residual,
    )
    from ..diagnostics.metrics import kurtosis, signal_statistics

    with warnings.catch_warnings():
        warnings.simplefilter("ignore", DiagnosticsWarning)  # zero variance -> NaN, reported
        st = signal_statistics(avg)
        dem = narrowband_demodulation(avg, teeth=teeth, harmonic=harmonic, bandwidth=bandwidth)
        res = residual(avg, teeth=teeth, preset=residual_preset)
        cm = condition_metrics(avg, teeth=teeth, na4_baseline_variance=na4_baseline_variance)
    out = {"kurtosis": st.kurtosis, "crest_factor": st.crest_factor,
           "envelope_kurtosis": kurtosis(dem.envelope, warn_constant=False),
           "am_kurtosis": kurtosis(dem.am, warn_constant=False),
           "pm_kurtosis": kurtosis(dem.pm, warn_constant=False),
           "residual_kurtosis": kurtosis(res, warn_constant=False)}
    out.update({k: getattr(cm, k) for k, _, src in INDICATORS if src == "condition metrics"})
    return {k: float(v) for k, v in out.items()}


def _state_reference(result: StudyResult, model: str) -> dict:
    """The same indicators on the ideal state velocity (gear vertical velocity, exact angle)
    from the diagnostics stage, healthy and cracked (None where undefined there)."""
    ref = {}
    cm = result.summary.get("condition_metrics", {}).get("gear_vertical_velocity", {})
    for state in ("healthy", "cracked"):
        d = result.diagnoses.get((model, state))
        if d is None or "v_yg" not in d.signals:
            continue
        sd = d.signals["v_yg"]
        row = {"kurtosis": sd.statistics.kurtosis, "crest_factor": sd.statistics.crest_factor,
               "envelope_kurtosis": sd.envelope_kurtosis, "am_kurtosis": sd.am_kurtosis,
               "pm_kurtosis": sd.pm_kurtosis, "residual_kurtosis": sd.residual_kurtosis}
        row = {k: float(v) for k, v in row.items()}
        row.update(cm.get(model, {}).get(state, {}))
        ref[state] = {k: row.get(k) for k, _, _ in INDICATORS}
    return ref


def _compute(case: Case, sim_case: Case, result: StudyResult, model: str,
             simulate: Callable, tick: Callable[[str], None]) -> dict:
    """The stage's numbers (see :func:`measurement_stage`); JSON-ready."""
    from ..diagnostics import tach_pulse_times, tsa
    from ..diagnostics.metrics import central_moment
    from ..diagnostics.spectra import residual
    from ..faults import without_faults
    from .measure import housing_forces

    plain, err, err_text = _variant_cases(case, sim_case)
    chains = _chains(case)
    # the healthy pair has no faults (no wear gap), as in the simulation stage
    sim_toml = {"cracked": case_to_toml(sim_case),
                "healthy": case_to_toml(without_faults(sim_case))}
    records = {}
    for has_err, c_faulty in ((False, plain), (True, err)):
        for state in ("healthy", "cracked"):
            key = (model, state)
            c = c_faulty if state == "cracked" else without_faults(c_faulty)
            if case_to_toml(c) == sim_toml[state] and key in result.sims:
                ds = result.sims[key]
            else:
                tick(f"simulation with{'' if has_err else 'out'} tooth errors, {state}")
                ds = simulate(c, result.maps[state], model)
            records[(has_err, state)] = (c, ds)
    d = case.diagnostics
    z = case.pinion.teeth if chains[True].tach.shaft == "pinion" else case.gear.teeth
    tsas: dict = {}
    info: dict = {}
    for name, (has_err, noisy) in VARIANTS.items():
        for state in ("healthy", "cracked"):
            tick(f"{name}, {state}")
            c, ds = records[(has_err, state)]
            shaft = "p" if chains[noisy].tach.shaft == "pinion" else "g"
            m = chains[noisy].measure(ds["time"].values,
                                      housing_forces(c, result.maps[state], ds),
                                      ds[f"theta_{shaft}"].values, ds[f"omega_{shaft}"].values)
            # a record shorter than one revolution holds no pulse edge (a flat tach)
            tp = (tach_pulse_times(m.tach, fs=m.fs) if np.ptp(m.tach) > 0
                  else np.empty(0))
            if tp.size < 3:
                return {"skipped": (
                    f"the measured record ({m.acc.size / m.fs:.3g} s after the chain's lead-in "
                    f"and tail of {m.info['lead_in'] + m.info['tail']:.3g} s) holds "
                    f"{tp.size} tachometer pulse(s), fewer than the 3 a TSA over two "
                    "revolutions needs: lengthen simulation.record_time")}
            t = tsa(m.acc, tach_times=tp, fs=m.fs, samples_per_rev=d.samples_per_rev,
                    min_revolutions=2)
            tsas[(name, state)] = t.average
            info[(name, state)] = {"revolutions": int(t.n_averages),
                                   "record_s": m.acc.size / m.fs,
                                   "acc_rms_m_s2": float(np.std(m.acc)),
                                   "noise_rms_m_s2": float(m.noise_rms),
                                   "fs_Hz": float(m.fs)}
    housing = housing_damping_sweep(
        case, {state: (c, ds, result.maps[state])
               for (has_err, state), (c, ds) in records.items() if has_err}, z, tick)
    out_var: dict = {}
    for name in VARIANTS:
        v0 = central_moment(residual(tsas[(name, "healthy")], teeth=z, preset="zakrajsek"), 2)
        out_var[name] = {state: measured_indicators(
            tsas[(name, state)], teeth=z, harmonic=d.harmonic, bandwidth=d.bandwidth,
            residual_preset=d.residual_preset, na4_baseline_variance=v0)
            for state in ("healthy", "cracked")}
    chain = chains[True]
    return {
        "model": model,
        "signal": "housing acceleration at the sensor [m/s^2], TSA from the tachometer",
        "teeth": int(z),
        "errors": err_text,
        "noise": (f"the case's [measurement] chain: SNR "
                  f"{'none' if chain.sensor.snr is None else format(chain.sensor.snr, 'g')} dB, "
                  f"ADC {chain.sensor.adc_bits or 'none'} bits, tachometer jitter "
                  f"{chain.tach.jitter:g} s"),
        "chain": chain.path.describe(),
        "variants": {name: {"errors": e, "noise": n} for name, (e, n) in VARIANTS.items()},
        "indicators": out_var,
        "records": {f"{name}|{state}": v for (name, state), v in info.items()},
        "housing_damping": housing,
        "tsa": {f"{name}|{state}": [float(x) for x in a] for (name, state), a in tsas.items()},
    }


def housing_damping_sweep(case: Case, records: dict, teeth: int,
                          tick: Callable[[str], None] = lambda item: None) -> dict:
    """The realistic record's indicators with every housing mode's damping ratio set to each of
    :data:`HOUSING_DAMPING` (same forces, errors, noise settings and tachometer).

    Parameters
    ----------
    case : Case
        Its ``[measurement]`` chain (a modal path; a measured FRF table has no damping to vary).
    records : dict
        ``state -> (case with errors, simulation Dataset, stiffness map)``, ``state`` in
        ``"healthy"``, ``"cracked"``.
    teeth : int
        Teeth of the averaged gear.

    Returns
    -------
    dict
        ``damping_ratios`` [-], ``case_damping_ratios`` [-], ``mode_frequencies_Hz``,
        ``mesh_period_s`` (mean speed of the healthy record), ``decay_over_mesh_period`` (the
        lowest mode's decay time ``1 / (zeta 2 pi f)`` over the mesh period [-]) and
        ``healthy`` / ``cracked``: indicator -> list over the damping ratios (NaN where the
        record is too short for the path's memory at that damping, or leaves fewer than two
        whole revolutions after the chain's lead-in and tail, the reason under
        ``not_computed``); or ``skipped``.
    """
    from ..config import MeasurementConfig
    from ..diagnostics import DiagnosticsWarning, tach_pulse_times, tsa
    from ..diagnostics.metrics import central_moment
    from ..diagnostics.spectra import residual
    from ..errors import GeardynError, InputError
    from .measure import chain_from_config, housing_forces

    cfg = case.measurement if case.measurement is not None else MeasurementConfig()
    if cfg.frf_table is not None:
        return {"skipped": "the transfer path is a measured FRF table (no modal damping to vary)"}
    d = case.diagnostics
    freqs = [float(f) for f in cfg.mode_frequencies]
    forces = {state: housing_forces(c, m, ds) for state, (c, ds, m) in records.items()}
    out: dict = {"damping_ratios": list(HOUSING_DAMPING),
                 "case_damping_ratios": [float(z) for z in cfg.mode_damping_ratios],
                 "mode_frequencies_Hz": freqs, "healthy": {}, "cracked": {}}
    _, ds_h, _ = records["healthy"]
    shaft = cfg.tach_shaft[0]
    omega = float(np.mean(ds_h[f"omega_{shaft}"].values))
    out["mesh_period_s"] = 2.0 * math.pi / (omega * teeth)
    out["decay_over_mesh_period"] = [1.0 / (zeta * 2.0 * math.pi * min(freqs))
                                     / out["mesh_period_s"] for zeta in HOUSING_DAMPING]
    for k in HOUSING_INDICATORS:
        out["healthy"][k], out["cracked"][k] = [], []
    for zeta in HOUSING_DAMPING:
        tick(f"housing damping {100 * zeta:g}%")
        chain = chain_from_config(cfg.model_copy(
            update={"mode_damping_ratios": [zeta] * len(freqs)}))
        avgs = {}
        try:
            for state, (_c, ds, _m) in records.items():
                m = chain.measure(ds["time"].values, forces[state],
                                  ds[f"theta_{shaft}"].values, ds[f"omega_{shaft}"].values)
                tp = tach_pulse_times(m.tach, fs=m.fs) if np.ptp(m.tach) > 0 else np.empty(0)
                with warnings.catch_warnings():  # fewer than 2 revolutions: said below instead
                    warnings.filterwarnings("ignore", "TSA over only", DiagnosticsWarning)
                    t = tsa(m.acc, tach_times=tp, fs=m.fs, samples_per_rev=d.samples_per_rev,
                            min_revolutions=2)
                if t.n_averages < 2:  # one revolution is no average: not the other ratios' TSA
                    raise InputError("time", f"{m.acc.size / m.fs:.3g} s measured (after the "
                                     f"chain's lead-in and tail), {t.n_averages} whole "
                                     "revolution", "at least 2 whole revolutions for a TSA")
                avgs[state] = t.average
        except GeardynError as exc:  # a lightly damped path's memory outlasts a short record
            out.setdefault("not_computed", {})[f"{zeta:g}"] = str(exc)
            for state in ("healthy", "cracked"):
                for k in HOUSING_INDICATORS:
                    out[state][k].append(math.nan)
            continue
        v0 = central_moment(residual(avgs["healthy"], teeth=teeth, preset="zakrajsek"), 2)
        for state, avg in avgs.items():
            ind = measured_indicators(avg, teeth=teeth, harmonic=d.harmonic,
                                      bandwidth=d.bandwidth, residual_preset=d.residual_preset,
                                      na4_baseline_variance=v0)
            for k in HOUSING_INDICATORS:
                out[state][k].append(ind[k])
    return out


def _cache_key(case: Case, sim_case: Case, result: StudyResult, model: str) -> str:
    from .._version import __version__
    from ..cache import cache_key

    return cache_key({"case": case_to_toml(case), "sim_case": case_to_toml(sim_case),
                      "maps": {s: m.attrs.get("inputs_hash") for s, m in result.maps.items()},
                      "model": model, "errors": DEFAULT_ERRORS, "geardyn": __version__,
                      "version": MEASUREMENT_CACHE_VERSION})


def measurement_stage(case: Case, sim_case: Case, result: StudyResult, *,
                      simulate: Callable, cache=None) -> None:
    """Fill ``result.summary["measurement"]`` (see the module docstring).

    Parameters
    ----------
    case : Case
        The study's case.
    sim_case : Case
        The case the simulation stage ran (shorter with ``--quick``); its records in
        ``result.sims`` are reused.
    result : StudyResult
        Needs ``maps`` and ``sims`` (and ``diagnoses`` for the state-velocity reference).
    simulate : callable
        ``simulate(case, stiffness_map, model) -> Dataset``, cached (the pipeline passes
        :func:`geardyn.studies.paper.cached_simulation`).
    cache : Cache, optional
        Default :func:`geardyn.cache.default_cache`.
    """
    import json

    from ..cache import default_cache
    from ..io import json_safe, write_json_atomic

    model = case.simulation.model
    cache = cache or default_cache()
    steps = {"n": 0}
    total = 2 + 2 * len(VARIANTS) + len(HOUSING_DAMPING)

    def tick(item: str) -> None:
        result.emit(f"measurement: {item}", min(steps["n"], total), total)
        steps["n"] += 1

    result.emit("measurement: from the cache or computed", 0, total)
    data, _ = cache.get_or_build(
        "measurement", _cache_key(case, sim_case, result, model), ".json",
        build=lambda: _compute(case, sim_case, result, model, simulate, tick),
        save=lambda obj, path: write_json_atomic(path, json_safe(obj)),
        load=lambda path: json.loads(path.read_text()))
    result.emit("measurement: indicators", total, total)
    data = dict(data)
    hd = data.get("housing_damping")
    if hd and "skipped" not in hd:  # the cached JSON holds NaN (not computed) as null
        for state in ("healthy", "cracked"):
            hd[state] = {k: [math.nan if x is None else x for x in v]
                         for k, v in hd[state].items()}
    data["reference"] = _state_reference(result, model)
    if "skipped" not in data:
        # the diagnostics stage found the healthy map periodic (no errors): the ideal healthy
        # residual is numerical remainder, and ratios to it are undefined (its reason)
        periodic = bool(result.summary.get("condition_metrics_undefined"))
        data["undefined"] = ({"ideal": ["NA4star", "EnergyRatio cracked / healthy"]}
                             if periodic else {})
        data["drivers"] = drivers(data["indicators"], data["undefined"])
        data["detections"] = detections(data["indicators"], data["undefined"])
    tsa = data.pop("tsa", {})
    result.summary["measurement"] = data
    result.measured_tsa = {tuple(k.split("|")): np.asarray(v, dtype=float)
                           for k, v in tsa.items()}


def _ratio(a, b) -> float:
    if a is None or b is None or not (math.isfinite(a) and math.isfinite(b)) or b == 0:
        return math.nan
    return abs(a / b)


def _lr(a, b) -> float:
    """``|log(a / b)|`` (NaN where undefined)."""
    r = _ratio(a, b)
    return abs(math.log(r)) if r > 0 and math.isfinite(r) else math.nan


def drivers(ind: dict, undefined: dict | None = None) -> dict:
    """Which input sets each indicator of the realistic record, computed from the variants.

    For each state and indicator, the single-input variants (``errors``, ``noise``) are
    compared with the realistic one (``errors+noise``) on a log scale: the input whose variant
    lies closer to it drives the indicator; when neither single input moves the indicator from
    ``ideal`` by more than :data:`UNCHANGED_FACTOR` it is ``"neither"``.

    Returns
    -------
    dict
        ``{state: {indicator: {"driver": "errors" | "noise" | "neither", "ideal", "errors",
        "noise", "errors+noise"}}}``.
    """
    undefined = undefined or {}
    out: dict = {}
    for state in ("healthy", "cracked"):
        rows = {}
        for k, _, _ in INDICATORS:
            v = {name: ind[name][state].get(k) for name in VARIANTS}
            ideal = None if k in undefined.get("ideal", []) else v["ideal"]
            both = v["errors+noise"]
            d_err, d_noise = _lr(both, v["errors"]), _lr(both, v["noise"])
            move = max(_lr(v["errors"], ideal), _lr(v["noise"], ideal), _lr(both, ideal))
            if ideal is not None and math.isfinite(move) and move < math.log(UNCHANGED_FACTOR):
                driver = "neither"
            elif not (math.isfinite(d_err) and math.isfinite(d_noise)):
                driver = "undetermined"
            else:
                driver = "errors" if d_err <= d_noise else "noise"
            rows[k] = {"driver": driver, **{n: (None if n == "ideal" and ideal is None
                                                else v[n]) for n in VARIANTS}}
        out[state] = rows
    return out


def detections(ind: dict, undefined: dict | None = None) -> dict:
    """Cracked / healthy of each indicator per variant, and whether it exceeds
    :data:`DETECTION_RATIO`: ``{variant: {indicator: {"ratio", "detected"}}}`` (ratio None
    where undefined: NA4* of an ideal healthy baseline)."""
    undefined = undefined or {}
    out: dict = {}
    for name in VARIANTS:
        rows = {}
        for k, _, _ in INDICATORS:
            if name == "ideal" and k in ("NA4star", "EnergyRatio") and undefined.get(name):
                rows[k] = {"ratio": None, "detected": False}
                continue
            r = _ratio(ind[name]["cracked"].get(k), ind[name]["healthy"].get(k))
            rows[k] = {"ratio": r if math.isfinite(r) else None,
                       "detected": bool(math.isfinite(r) and r > DETECTION_RATIO)}
        out[name] = rows
    return out


def _fmt(v) -> str:
    return "undefined" if v is None or not math.isfinite(v) else f"{v:.3g}"


def statements(data: dict, words: tuple[str, str] = ("cracked", "crack")) -> list[str]:
    """The section's conclusions in words, computed from ``summary["measurement"]``: which
    input drives each indicator of the realistic record, healthy and cracked, and which
    indicators see the crack in each variant. ``words``: the report's adjective and noun for
    the faulty state (``("faulty", "fault")`` when the fault is not a crack); the data keep
    the key ``"cracked"``."""
    faulty, fault = words
    if "skipped" in data:
        return []
    labels = {k: lab for k, lab, _ in INDICATORS}
    out = []
    drv = data["drivers"]
    for state in ("healthy", "cracked"):
        groups: dict[str, list[str]] = {}
        for k, row in drv[state].items():
            groups.setdefault(row["driver"], []).append(labels[k])
        parts = []
        for driver, text in (("errors", "the tooth errors set"), ("noise", "the noise sets"),
                             ("neither", "neither input moves by more than "
                                         f"{100 * (UNCHANGED_FACTOR - 1):.0f}%"),
                             ("undetermined", "undetermined (a variant's value is undefined)")):
            if groups.get(driver):
                n = len(groups[driver])
                parts.append(f"{text} {'all ' if n == len(INDICATORS) else ''}{n}"
                             f" ({', '.join(groups[driver])})")
        key = "; ".join(
            f"{labels[k]} {_fmt(drv[state][k]['errors+noise'])} (ideal "
            f"{_fmt(drv[state][k]['ideal'])}, errors only {_fmt(drv[state][k]['errors'])}, "
            f"noise only {_fmt(drv[state][k]['noise'])})"
            for k in ("FM4", "NA4star", "EnergyRatio") if k in drv[state])
        out.append(f"{state.replace('cracked', faulty).capitalize()} pair, realistic record: "
                   + "; ".join(parts)
                   + f". {key}.")
    er_err_h = drv["healthy"].get("EnergyRatio", {}).get("errors")
    er_noise_c = drv["cracked"].get("EnergyRatio", {}).get("noise")
    if er_err_h is not None and er_noise_c is not None:
        cmp = "larger" if er_err_h > er_noise_c else "smaller"
        out.append(f"The tooth errors alone give the healthy pair an energy ratio of "
                   f"{_fmt(er_err_h)}, {cmp} than the {faulty} pair's without errors "
                   f"({_fmt(er_noise_c)}, noise only): the errors' difference signal is "
                   f"{cmp} than the {fault}'s.")
    out += housing_statements(data.get("housing_damping"))
    det = data["detections"]
    names = {"ideal": "the ideal record", "errors": "tooth errors only",
             "noise": "noise only", "errors+noise": "the realistic record (errors + noise)"}
    for name in VARIANTS:
        seen = sorted(((r["ratio"], labels[k]) for k, r in det[name].items() if r["detected"]),
                      reverse=True)
        if seen:
            out.append(f"{fault.capitalize()} seen ({faulty} / healthy > {DETECTION_RATIO:g}) "
                       f"on {names[name]} by "
                       f"{len(seen)} of {len(det[name])} indicators, strongest first: "
                       + ", ".join(f"{lab} x{r:.3g}" for r, lab in seen) + ".")
        else:
            best = max(((r["ratio"], labels[k]) for k, r in det[name].items()
                        if r["ratio"] is not None), default=None)
            out.append(f"{fault.capitalize()} seen on {names[name]} by none of the indicators"
                       + (f" (largest {faulty} / healthy: {best[1]} x{best[0]:.3g})." if best
                          else "."))
    return out


#: FM4 within this of 3 counts as "near 3" (a Gaussian difference signal) in the statements [-].
GAUSSIAN_FM4_BAND = 0.5

#: The word for a housing-damping value the record is too short to compute (table and text).
NOT_COMPUTED = "not computed"


def housing_statements(hd: dict | None) -> list[str]:
    """What :func:`housing_damping_sweep`'s numbers say, in words (computed, not written)."""
    if not hd or "skipped" in hd:
        return [] if not hd else [f"Housing damping not varied: {hd['skipped']}."]
    z = hd["damping_ratios"]
    fm = [math.nan if v is None else float(v) for v in hd["healthy"]["FM4"]]  # NaN: JSON null
    ratio = hd["decay_over_mesh_period"]
    near = [i for i, v in enumerate(fm) if math.isfinite(v) and abs(v - 3) <= GAUSSIAN_FM4_BAND]
    own = ", ".join(f"{100 * v:g}%" for v in sorted(set(hd["case_damping_ratios"])))
    skipped = {f"{float(k):g}" for k in hd.get("not_computed", {})}
    text = ("Healthy FM4 of the realistic record with every housing mode's damping ratio set to "
            + ", ".join(f"{100 * a:g}%: "
                        + (NOT_COMPUTED if f"{a:g}" in skipped else _fmt(b))
                        for a, b in zip(z, fm, strict=True))
            + f" (this case's path: {own}; the lowest mode's decay time 1 / (zeta 2 pi f) is "
            f"{ratio[-1]:.2g} to {ratio[0]:.2g} mesh periods over that range). ")
    if hd.get("not_computed"):
        text += ("Not computed at " + ", ".join(f"{100 * float(k):g}%" for k in
                                                hd["not_computed"])
                 + ": the record is too short for that path's memory (lead-in and tail) and "
                 "a TSA over two revolutions (lengthen simulation.record_time). ")
    if near:
        text += ("FM4 is within " f"{GAUSSIAN_FM4_BAND:g} of 3, the value of a Gaussian "
                 "difference signal, at " + ", ".join(f"{100 * z[i]:g}%" for i in near)
                 + " (decay " + ", ".join(f"{ratio[i]:.2g}" for i in near)
                 + " mesh periods); the tooth errors' transients of successive meshes overlap "
                 "there, while a more damped path leaves them isolated and impulsive.")
    else:
        text += (f"FM4 is not within {GAUSSIAN_FM4_BAND:g} of 3, the value of a Gaussian "
                 "difference signal, at any of these damping ratios"
                 + (" where it was computed" if skipped else "")
 + ": the healthy difference signal is not Gaussian-like at any of them.")
    return [text]


def reproduce_commands(case_file: str, case: Case, sim_case: Case, map_case: Case,
                       record_s: float) -> dict:
    """``geardyn measure`` and ``geardyn diagnose`` command lines that write this stage's
    realistic records (errors + noise) as files and diagnose them.

    Parameters
    ----------
    case_file : str
        The run's ``case.toml`` (the effective case: case file, ``--set`` overrides and the
        stiffness method), as the command line shall name it.
    case, sim_case, map_case : Case
        The study's case, the case its simulations ran (shorter with ``--quick``) and the one
        its stiffness maps were built from (coarser with ``--quick``).
    record_s : float
        Length of the stage's measured record [s] (``geardyn measure`` measures
        ``simulation.record_time``; the stage measured its simulated record less the chain's
        lead-in and tail).

    Returns
    -------
    dict
        ``healthy``, ``faulty`` (``geardyn measure``), ``diagnose_healthy``,
        ``diagnose_faulty`` (``geardyn diagnose``): shell command lines; ``own_errors``: whether
        the case's own ``[modifications]`` are the tooth errors.
    """
    import shlex

    sets = []
    if map_case.stiffness.centre_distances != case.stiffness.centre_distances:
        sets.append(f"stiffness.centre_distances={map_case.stiffness.centre_distances}")
    if map_case.stiffness.fe.refinement != case.stiffness.fe.refinement:
        sets.append(f"stiffness.fe.refinement={map_case.stiffness.fe.refinement:g}")
    if sim_case.simulation.settle_time != case.simulation.settle_time:
        sets.append(f"simulation.settle_time={sim_case.simulation.settle_time:.12g} s")
    sets.append(f"simulation.record_time={record_s:.12g} s")
    _, err, _ = _variant_cases(case, sim_case)
    own = err is sim_case
    if not own:
        sets += [f"{k}={v}" for k, v in DEFAULT_ERRORS.items()]
    base = ["geardyn", "measure", "-c", case_file, *(x for s in sets for x in ("--set", s))]
    diag = ["-c", case_file, "--signal", "acc", "--tach", "tach"]
    return {"healthy": shlex.join([*base, "--no-crack", "--out", "healthy.nc"]),
            "faulty": shlex.join([*base, "--out", "faulty.nc"]),
            "diagnose_healthy": shlex.join(["geardyn", "diagnose", "healthy.nc", *diag]),
            "diagnose_faulty": shlex.join(["geardyn", "diagnose", "faulty.nc", *diag]),
            "own_errors": own}
