"""The report stage of the paper study: ``report.html``, ``results.nc`` and ``figures/``.

Reads a :class:`~.paper_result.StudyResult` (never the study module: no import circle). A case
whose physical inputs are the paper's is compared with the paper; any other case gets a report
titled by its name that lists what differs from the paper's case and compares with nothing.
"""

from __future__ import annotations

import json
import math
import sys
import time
from pathlib import Path

import numpy as np

from .._version import __version__, package_versions
from ..config import Case, case_to_toml
from ..io import NETCDF_COMPRESSION, atomic_path, json_safe, set_netcdf_attrs, to_netcdf
from .paper_report_case import (  # noqa: F401 - re-exported: the tests read the case table
    _case_table_rows,
    _difference_text,
    _fault_description,
    _own_case_title,
    _set_fields,
    case_sections,
    quick_sentence,
    used_case,
)
from .paper_result import StudyResult
from .paper_validation import SHAPE_FACTOR, STD_FACTOR
from .paper_values import (
    CONDITION_METRICS,
    FAULT_DIP,
    PAPER_TABLE2,
    PAPER_TABLE3,
    SIGNAL_KEYS,
    SIGNAL_TITLES,
)
from .paper_values import fault_word as _fault_word
from .paper_values import faulty_words as _faulty_words
from .report import Report

__all__ = ["report_stage", "write_results_netcdf", "ERRATA", "CITATIONS", "disagreements",
           "case_sections", "citations", "used_case", "quick_sentence",
           "model_comparison_statements", "TABLE_MODELS"]

ERRATA = [
    "Table 1's 'base radius 129.7 mm' of each gear is the sum r_b1 + r_b2; each base radius is "
    "64.84 mm (with 129.7 mm each, the centre distance shift would be 0.535 mm, not 1.07 mm).",
    "Eq. 8 divides by pi m cos(alpha'); the base pitch pi m cos(alpha) does not change with the "
    "centre distance. geardyn reports the physical contact ratio and the eq. 8 value side by side "
    "(1.4198 vs 1.4308 at +1.07 mm; the paper's '1.43' is the eq. 8 value).",
    "Eq. 13 has q_stp where q_stg (the gear's absolute torsional damping) is meant.",
    "Eq. 11 omits the separation function h on N r_p; geardyn applies h N in every equation, as "
    "appendix B does.",
    "Nomenclature: L05/L10 and KC105 are 0.5 mm / 1.0 mm centre distance changes, not 5 / 10 mm.",
    "The FE curves of the paper exist for 0, 0.5 and 1 mm only while the operating point is "
    "+1.07 mm; geardyn tabulates K(theta, d) from -0.5 to +2 mm and interpolates on "
    "boundary-fitted nodes, so the single/double contact handovers are not smeared between "
    "centre distances.",
]

CITATIONS = [
    "Xue, S. & Howard, I. (2018). Dynamic modelling of flexibly supported gears using iterative "
    "convergence of tooth mesh stiffness. Mechanical Systems and Signal Processing.",
    "Litvin, F. L. & Fuentes, A. (2004). Gear Geometry and Applied Theory, 2nd ed. Cambridge "
    "University Press (involute and trochoid fillet generation).",
    "Yang, D. C. H. & Lin, J. Y. (1987). Hertzian damping, tooth friction and bending elasticity "
    "in gear impact dynamics. J. Mech. Transm. Autom. Des. 109:189-196 (Hertz term).",
    "Tian, X. (2004). Dynamic simulation for system response of gearbox including localized gear "
    "faults. MSc thesis, University of Alberta (potential energy method).",
    "Sainsot, P., Velex, P. & Duverger, O. (2004). Contribution of gear body to tooth "
    "deflections. J. Mech. Des. 126:748-752 (fillet-foundation term).",
    "Chen, Z. & Shao, Y. (2011). Dynamic simulation of spur gear with tooth root crack "
    "propagating along tooth width and crack depth. Eng. Fail. Anal. 18:2149-2164.",
    "Mohammed, O. D., Rantatalo, M. & Aidanpaa, J.-O. (2013). Improving mesh stiffness "
    "calculation of cracked gears for the purpose of vibration-based fault analysis. Eng. Fail. "
    "Anal. 34:235-251 (crack limit line towards the tip).",
    "Ma, H., Song, R., Pang, X. & Wen, B. (2014). Time-varying mesh stiffness calculation of "
    "cracked spur gears. Eng. Fail. Anal. 44:179-194 (trochoid fillet in the PEM).",
    "ISO 6336-1:2019, Calculation of load capacity of spur and helical gears, part 1 (c', "
    "c_gamma_alpha).",
    "Newmark, N. M. (1959). A method of computation for structural dynamics. J. Eng. Mech. Div. "
    "ASCE 85:67-94.",
    "Hilber, H. M., Hughes, T. J. R. & Taylor, R. L. (1977). Improved numerical dissipation for "
    "time integration algorithms in structural dynamics. Earthq. Eng. Struct. Dyn. 5:283-292.",
    "Chaari, F., Bartelmus, W., Zimroz, R., Fakhfakh, T. & Haddar, M. (2012). Gearbox vibration "
    "signal amplitude and frequency modulation. Shock and Vibration 19(4):635-652 (I_m, I_out, "
    "k_cp, k_cg defaults).",
    "McFadden, P. D. (1986). Detecting fatigue cracks in gears by amplitude and phase "
    "demodulation of the meshing vibration. J. Vib. Acoust. Stress Reliab. Des. 108:165-170.",
    "McFadden, P. D. (1987). A revised model for the extraction of periodic waveforms by time "
    "domain averaging. Mech. Syst. Signal Process. 1:83-95 (TSA).",
    "Forrester, B. D. (1996). Advanced vibration analysis techniques for fault detection and "
    "diagnosis in geared transmission systems. PhD thesis, Swinburne University (PWVD of TSA).",
    "Stewart, R. M. (1977). Some useful data analysis techniques for gearbox diagnostics. "
    "University of Southampton, MHM/R/10/77 (FM0, FM4).",
    "Zakrajsek, J. J. (1989). An investigation of gear mesh failure prediction techniques. "
    "NASA TM-102340 (NA4).",
    "Martin, H. R. (1989). Statistical moment analysis as a means of surface damage detection. "
    "Proc. 7th Int. Modal Analysis Conf. (M6A, M8A).",
    "Decker, H. J., Handschuh, R. F. & Zakrajsek, J. J. (1994). An enhancement to the NA4 gear "
    "vibration diagnostic parameter. NASA TM-106553 (NA4*).",
    "Lebold, M., McClintic, K., Campbell, R., Byington, C. & Maynard, K. (2000). Review of "
    "vibration analysis methods for gearbox diagnostics and prognostics. Proc. 54th MFPT.",
]

#: Models of Tables 2 and 3 in the report and results.nc, in column order (model I-static is
#: geardyn's: the paper has no such column).
TABLE_MODELS = ("I", "I-static", "II")

#: The model comparison's ratios (``summary["model_comparison"]``), as results.nc variables.
MODEL_COMPARISON_VARIABLES = ("rms_ii_minus_i_static", "rms_ii_minus_i", "explained_fraction",
                              "top_share")


def command_line(argv: list[str] | None = None) -> str:
    """The command that made this report, as a user would type it again: ``geardyn ...`` when
    the process is the CLI (the ``geardyn`` script or ``python -m geardyn``, whose ``argv[0]``
    is the path of ``__main__.py``), arguments quoted for a POSIX shell; else the script that
    called the library."""
    import shlex

    argv = list(sys.argv if argv is None else argv)
    if not argv or not argv[0]:
        return "(library call)"
    prog = Path(argv[0])
    as_module = prog.name == "__main__.py" and prog.parent.name == "geardyn"
    if as_module or prog.name in ("geardyn", "geardyn.exe"):
        return shlex.join(["geardyn", *argv[1:]])
    return f"(library call from {shlex.join(argv)})"


def _versions() -> list[tuple[str, str]]:
    return package_versions()


#: Why a statistic can differ from the paper's, by statistic (shown with the misses).
MISS_REASONS = {
    "std": "The paper does not give its damping values (geardyn's are documented defaults, see "
           "the case table); a standard deviation scales with the response amplitude, which the "
           "damping sets near the resonances.",
    "kurtosis": "The TSA's kurtosis weighs the crack event against the mesh vibration; it "
                "depends on the crack's stiffness loss (PEM or FE) and on the damping.",
    "crest_factor": "The crest factor is set by the sharpest peak of the TSA, i.e. by the crack "
                    "event's size relative to the mesh vibration, which depends on the crack's "
                    "stiffness loss (PEM or FE) and the undocumented damping. geardyn's crack "
                    "events are smaller relative to the mesh vibration than the paper's; the "
                    "cause has not been identified.",
    "envelope_kurtosis": "The narrowband envelope's kurtosis measures how localised the crack "
                         "event is within the revolution.",
    "am_kurtosis": "The amplitude modulation's kurtosis depends on how the carrier amplitude "
                   "is split between the mesh harmonic and the crack's sidebands, and so on the "
                   "crack's stiffness loss and the damping; the cause of the difference has not "
                   "been identified.",
    "pm_kurtosis": "The phase modulation's kurtosis is set by how sharply the crack shifts the "
                   "phase of the demodulated mesh harmonic against the phase's spread "
                   "elsewhere; it depends on the crack model (PEM or FE), the damping and the "
                   "record length. The cause of the difference has not been identified.",
    "residual_kurtosis": "Residual kurtoses are ratios of tiny sideband energies; they depend "
                         "on the damping values the paper does not give and on the crack model "
                         "(PEM or FE), and a --quick record averages fewer revolutions.",
}


def disagreements(s: dict) -> list[str]:
    """Where geardyn's numbers differ from the paper's, in words, computed from the summary.

    Every comparison outside its tolerance is listed (grouped by statistic, with the values) and
    explained as far as geardyn can; the notes that follow are about things the tables cannot
    show.
    """
    out = []
    comps = s.get("comparisons", [])
    misses: dict[str, list[dict]] = {}
    for r in comps:
        if not r["pass"]:
            misses.setdefault(r.get("statistic", r["quantity"]), []).append(r)
    for stat, rows in misses.items():
        vals = "; ".join(f"{r['signal'].replace('_', ' ')}, model {r['model']}: "
                         f"{r['geardyn']:.4g} vs {r['paper']:.4g}" for r in rows)
        label = rows[0]["quantity"].split(",")[0]
        out.append(f"{label}: {len(rows)} of "
                   f"{sum(1 for r in comps if r.get('statistic') == stat)} outside "
                   f"{rows[0]['tolerance_text'].split(' (')[0]} ({vals}). "
                   f"{MISS_REASONS.get(stat, '')}")
    t3 = s.get("table3", {})
    for name, title in SIGNAL_TITLES.items():
        if name not in t3:
            continue
        ours = t3[name]["II"]["residual_kurtosis"] - t3[name]["I"]["residual_kurtosis"]
        paper = PAPER_TABLE3[name]["II"]["residual_kurtosis"] - \
            PAPER_TABLE3[name]["I"]["residual_kurtosis"]
        if np.sign(ours) != np.sign(paper):
            out.append(
                f"Residual kurtosis of the {title.split(' [')[0]}: the paper finds model II "
                f"{'lower' if paper < 0 else 'higher'} than model I "
                f"({PAPER_TABLE3[name]['I']['residual_kurtosis']:.2f} -> "
                f"{PAPER_TABLE3[name]['II']['residual_kurtosis']:.2f}); geardyn finds it "
                f"{'lower' if ours < 0 else 'higher'} ({t3[name]['I']['residual_kurtosis']:.2f} "
                f"-> {t3[name]['II']['residual_kurtosis']:.2f}).")
    out.append(
        "Absolute phase-modulation levels (the paper's 'PM stays around 40 deg' and similar) "
        "depend on the phase of the demodulated harmonic relative to the angle origin, which "
        "the paper does not define; geardyn reports its levels (summary.json, table3 "
        "pm_mean_deg) and compares the change between models, not the levels.")
    sims = s.get("simulations", {})
    pred = sims.get("model_II_cracked", {})
    start = sims.get("model_II-start_cracked", {})
    if pred and start:
        out.append(
            "Iterations of model II (Fig. 9): with the stiffness evaluated at the Newmark "
            "predictor (geardyn's default, second order), the first solve already meets the "
            f"paper's 0.1 um criterion (largest |b1 - b2| "
            f"{1e6 * (pred.get('max_residual_before_m') or 0):.3f} um), so no step iterates. "
            "With the paper's start-of-step evaluation (first order), |b1 - b2| reaches "
            f"{1e6 * (start.get('max_residual_before_m') or 0):.2f} um and "
            f"{100 * (start.get('steps_iterating_fraction') or 0):.1f}% of steps iterate, "
            "concentrated at the handovers and at the crack as in the paper (0.2 um and "
            "0.4 um there).")
    return out


#: How results.nc is laid out (its root attribute ``contents`` and the report say the same).
RESULTS_LAYOUT = (
    "results.nc: the root group holds Tables 2 and 3 (models I, I-static and II), the condition "
    "metrics, the model comparison (rms_ii_minus_i_static, rms_ii_minus_i, explained_fraction "
    "per state and signal) and the indicators on the realistic measurement "
    "(measured_indicators) as variables "
    "(xarray.open_dataset('results.nc') shows them) and the summary (JSON, as the report stage "
    "began: its complete is false and its stages end before the report; summary.json holds the "
    "final one) and case (TOML) as attributes; groups stiffness/healthy, stiffness/cracked (the maps) and "
    "diagnostics/model_<M>_<state> (TSA, residual, envelope, AM, PM, RMS spectrum on the angle "
    "and order axes). Open everything with xarray.open_datatree('results.nc') or one group with "
    "xarray.open_dataset('results.nc', group='diagnostics/model_II_cracked'). The simulated "
    "records are one file per run, runs/model_<M>_<state>.nc (xarray.open_dataset, or geardyn "
    "diagnose runs/model_II_cracked.nc). All variables are zlib-compressed with the shuffle "
    "filter; the records' derived, shown-only variables (pressure angle, contact ratios, mesh "
    "stiffness, iteration residuals) are float32, everything else float64.")


def _tables_dataset(result: StudyResult, case: Case):
    """Root of results.nc: Tables 2 and 3 (and the paper's, for the paper's case) and the
    condition metrics as labelled arrays."""
    import xarray as xr

    s = result.summary
    sigs = list(SIGNAL_KEYS.values())
    models = list(TABLE_MODELS)
    data = {}
    units = {"gear_vertical_velocity": "m/s", "pinion_angular_velocity": "rad/s",
             "transmission_error": "rad"}
    t2, t3 = s.get("table2", {}), s.get("table3", {})
    st2 = ["mean", "std", "skewness", "kurtosis", "crest_factor"]
    st3 = ["envelope_kurtosis", "am_kurtosis", "pm_kurtosis", "residual_kurtosis", "pm_mean_deg"]

    def arr(table, stats):
        return np.array([[[float(table.get(g, {}).get(m, {}).get(k, np.nan)) for k in stats]
                          for m in models] for g in sigs])

    # mixed units: each element's unit is in a coordinate that a selection keeps, e.g.
    # ds.table2.sel(signal="transmission_error", statistic2="std").statistic2_units -> "rad"
    units2 = [[units[g] if k in ("mean", "std") else "1" for k in st2] for g in sigs]
    units3 = ["deg" if k == "pm_mean_deg" else "1" for k in st3]
    per2 = {"units_coordinate": "statistic2_units",
            "comment": "units differ by signal and statistic (mean and STD in the signal's "
                       "unit, the shape statistics dimensionless): no single units attribute; "
                       "each element's unit is the coordinate statistic2_units, kept by .sel(), "
                       "e.g. table2.sel(signal='transmission_error', statistic2='std')"
                       ".statistic2_units"}
    per3 = {"units_coordinate": "statistic3_units",
            "comment": "units differ by statistic (kurtoses dimensionless, pm_mean_deg in "
                       "deg): no single units attribute; each element's unit is the coordinate "
                       "statistic3_units, kept by .sel()"}
    if t2:
        data["table2"] = (("signal", "model", "statistic2"), arr(t2, st2), {
            "long_name": "statistics of the TSA of the faulty ('cracked') records (paper's "
                         "Table 2): mean, STD, skewness g1, Pearson kurtosis, crest factor "
                         "max|x - mean|/STD; model I-static is geardyn's addition (K(theta) at "
                         "the static operating centre distance)", **per2})
        data["table3"] = (("signal", "model", "statistic3"), arr(t3, st3), {
            "long_name": "kurtoses of the narrowband envelope, AM, PM and residual and the PM "
                         "level (pm_mean_deg) of the faulty ('cracked') records (paper's "
                         "Table 3)", **per3})
        if result.paper_case:
            data["paper_table2"] = (("signal", "model", "statistic2"), arr(PAPER_TABLE2, st2),
                                    {"long_name": "the paper's Table 2 (NaN for model I-static: "
                                                  "not in the paper)", **per2})
            data["paper_table3"] = (("signal", "model", "statistic3"),
                                    arr(PAPER_TABLE3, st3[:4] + ["-"]),
                                    {"long_name": "the paper's Table 3 and residual kurtoses "
                                                  "(NaN for model I-static: not in the paper, "
                                                  "and for pm_mean_deg: the paper gives no "
                                                  "level)", **per3})
    cm = s.get("condition_metrics", {})
    if cm:
        vals = np.array([[[[np.nan if m not in cm[g] or cm[g][m][state][k] is None
                             else cm[g][m][state][k]
                            for k in CONDITION_METRICS] for state in ("healthy", "cracked")]
                          for m in models] for g in sigs], dtype=float)
        undefined = s.get("condition_metrics_undefined", {})
        data["condition_metrics"] = (("signal", "model", "state", "metric"), vals, {
            "long_name": "condition metrics of the TSA (MATLAB gearConditionMetrics names); NaN "
                         "where undefined or not computed", "units": "1",
            "undefined": json.dumps(undefined)})
    meas = s.get("measurement", {})
    if "indicators" in meas:
        from .paper_measurement import INDICATORS, VARIANTS

        ind = meas["indicators"]
        vals = np.array([[[np.nan if ind[v][state].get(k) is None else ind[v][state][k]
                           for k, _, _ in INDICATORS] for state in ("healthy", "cracked")]
                         for v in VARIANTS], dtype=float)
        data["measured_indicators"] = (("variant", "state", "indicator"), vals, {
            "long_name": f"Table 2/3 statistics and condition metrics of the TSA (from the "
                         f"tachometer) of the housing acceleration, model {meas['model']}: "
                         "ideal, tooth errors only, noise only, errors + noise",
            "units": "1", "tooth_errors": meas.get("errors", ""),
            "noise": meas.get("noise", ""), "transfer_path": meas.get("chain", "")})
    mc = s.get("model_comparison", {})
    mc_states = [st for st in ("cracked", "healthy") if st in mc]
    mc_signals = list(mc[mc_states[0]]["signals"]) if mc_states else []
    if mc_states:
        for var in MODEL_COMPARISON_VARIABLES:
            vals = np.array([[np.nan if mc[st]["signals"][g].get(var) is None
                              else mc[st]["signals"][g][var] for g in mc_signals]
                             for st in mc_states], dtype=float)
            data[var] = (("comparison_state", "compared_signal"), vals, {
                "units": "1", "long_name": mc[mc_states[0]]["definitions"][var],
                "records": "runs/model_I_<state>.nc, runs/model_I-static_<state>.nc, "
                           "runs/model_II_<state>.nc"})
        data["static_centre_distance_change"] = ("comparison_state", np.array(
            [mc[st]["static_centre_distance_change_mm"] * 1e-3 for st in mc_states]), {
                "units": "m", "long_name": "centre distance change at which model I-static "
                                           "reads K(theta) (static operating point, eq. 4)"})
    coords = {
        "signal": ("signal", sigs, {"long_name": "signal of Tables 2 and 3 (the paper's name; "
                                                 "units in the root attribute signal_units)"}),
        "model": ("model", models, {"long_name": "dynamic model (I-static is geardyn's)"}),
        "statistic2": ("statistic2", st2, {"long_name": "statistic of Table 2"}),
        "statistic3": ("statistic3", st3, {"long_name": "statistic of Table 3"}),
        "state": ("state", ["healthy", "cracked"],
                  {"long_name": "state of the pair ('cracked': the case's faulty pair, whatever "
                                "its fault)"}),
        "metric": ("metric", list(CONDITION_METRICS),
                   {"long_name": "condition metric (MATLAB gearConditionMetrics name)"})}
    if t2:
        coords["statistic2_units"] = (("signal", "statistic2"), units2,
                                      {"long_name": "units of each Table 2 statistic"})
        coords["statistic3_units"] = ("statistic3", units3,
                                      {"long_name": "units of each Table 3 statistic"})
    if mc_states:
        coords["comparison_state"] = ("comparison_state", mc_states, {
            "long_name": "state of the compared records ('cracked': the faulty pair)"})
        coords["compared_signal"] = ("compared_signal", mc_signals, {
            "long_name": "simulated signal compared between the models (runs/*.nc variable)"})
        coords["compared_signal_units"] = ("compared_signal",
                                           [mc[mc_states[0]]["signals"][g]["units"]
                                            for g in mc_signals],
                                           {"long_name": "units of each compared signal"})
    if "indicators" in meas:
        coords["variant"] = ("variant", list(VARIANTS), {
            "long_name": "measurement variant (tooth errors, sensor noise)"})
        coords["indicator"] = ("indicator", [k for k, _, _ in INDICATORS], {
            "long_name": "indicator of the TSA (Table 2/3 statistic or condition metric)"})
    used = {dim for d in data.values() for dim in
            ((d[0],) if isinstance(d[0], str) else d[0])}
    ds = xr.Dataset(data, coords={k: v for k, v in coords.items()
                                  if set((v[0],) if isinstance(v[0], str) else v[0]) <= used})
    ds.attrs.update({
        "title": (f"geardyn: {'the Xue & Howard (2018) case study' if result.paper_case else ''}"
                  f"{'' if result.paper_case else repr(case.name) + ' (not the paper case)'}"),
        "contents": RESULTS_LAYOUT,
        "signal_units": json.dumps(units),
        "run_files": json.dumps(s.get("run_files", {})),
        "summary_json": json.dumps(json_safe(s)),
        "case_toml": case_to_toml(case),
        "geardyn_version": __version__,
    })
    return ds


def _compressed(ds) -> dict:
    return {name: dict(NETCDF_COMPRESSION)
            for name, v in ds.variables.items() if v.dtype.kind in "biuf" and v.ndim > 0}


def write_results_netcdf(path: Path, result: StudyResult, case: Case) -> None:
    """The study's tables, maps and diagnostics in one NetCDF-4 file, written atomically.

    See :data:`RESULTS_LAYOUT`. The simulated records are not repeated here: they are
    ``runs/model_<M>_<state>.nc``, one file per run.

    The file goes through the output cache (:func:`.paper_cache.write_output`, keyed by every
    group's dataset and the encoding), all but the root's ``summary_json``: it holds this
    run's stage times and output paths, so it is set on the copy
    (:func:`geardyn.io.set_netcdf_attrs`) before the copy is renamed into place. A run into
    another folder with the same results then copies the bytes instead of writing the nine
    groups again (1.0-1.2 s of a 5 s warm ``geardyn run``, measured 2026-11-28).
    """
    from .paper_cache import write_output

    root = _tables_dataset(result, case)
    summary = root.attrs.pop("summary_json")
    groups = [("", root)]
    groups += [(f"stiffness/{state}", m.to_dataset()) for state, m in result.maps.items()]
    groups += [(f"diagnostics/model_{model}_{state}", _diagnosis_dataset(diag))
               for (model, state), diag in result.diagnoses.items()]

    def write(tmp: Path) -> None:
        for i, (group, ds) in enumerate(groups):
            to_netcdf(ds, tmp, mode="a" if i else "w", group=group or None,
                      encoding=_compressed(ds))

    with atomic_path(path, suffix=".nc") as tmp:
        write_output(tmp, "results", [(group, ds, list(ds.variables)) for group, ds in groups],
                     {"compression": NETCDF_COMPRESSION, "arrays": "numeric",
                      "layout": "groups"},
                     write)
        set_netcdf_attrs(tmp, {"summary_json": summary})


def _diagnosis_dataset(diag):
    import xarray as xr

    data = {}
    angle = None
    for name, sd in diag.signals.items():
        angle = sd.tsa.angle - sd.tsa.angle[0]
        u = sd.unit
        data[f"{name}_tsa"] = ("angle", sd.tsa.average, {"units": u, "long_name": f"TSA of {name}"})
        data[f"{name}_residual"] = ("angle", sd.residual, {"units": u,
                                                            "long_name": f"residual of {name}"})
        data[f"{name}_envelope"] = ("angle", sd.demodulation.envelope,
                                    {"units": u, "long_name": f"narrowband envelope of {name}"})
        data[f"{name}_am"] = ("angle", sd.demodulation.am,
                              {"units": u, "long_name": f"amplitude modulation of {name}"})
        data[f"{name}_pm"] = ("angle", sd.demodulation.pm,
                              {"units": "rad", "long_name": f"phase modulation of {name}"})
        data[f"{name}_spectrum_rms"] = ("order", sd.spectrum.amplitude,
                                        {"units": u, "long_name": f"RMS order spectrum of {name}"})
    orders = next(iter(diag.signals.values())).spectrum.orders
    return xr.Dataset(data, coords={"angle": ("angle", angle, {"units": "rad",
                                                               "long_name": "pinion angle"}),
                                    "order": ("order", orders, {"units": "1",
                                                                "long_name": "shaft order"})},
                      attrs={"metrics_json": json.dumps(json_safe(diag.to_dict()))})


def _size(path: Path) -> str:
    try:
        n = path.stat().st_size
    except OSError:
        return "-"
    return f"{n / 1e6:.1f} MB" if n >= 1e5 else f"{n / 1e3:.0f} kB"


def _zero_small(x: float, tiny: float) -> float:
    """``0.0`` for a value within ``tiny`` of zero (round-off), else ``x``."""
    return 0.0 if abs(x) <= tiny else x


def _fmt_num(v) -> str:
    return "undefined" if v is None or not math.isfinite(v) else f"{v:.4g}"


def fault_event_words(s: dict, faulty_pair: bool, faulty: str, fault: str) -> str:
    """Where the Figs. 8-10 analogues are centred, for their captions: around the first fault
    event when the study located it (summary keys ``fault_event_angle_deg`` and
    ``fault_event_period_deg``), else the middle of the record, with the reason for a faulty
    pair (``faulty_pair``) whose maps do not locate the fault."""
    event = s.get("fault_event_angle_deg")
    if event is not None:
        # at the design centre distance (model I's); at the static operating one the drop can
        # peak a few degrees later (178.1 against 175.3 deg for the paper's crack with PEM)
        op = s.get("crack_angle_in_stiffness_deg")
        at_op = (f"; at the static operating centre distance, {op:.1f} deg" if op is not None
                 and abs(op - event) >= 0.05 else "")
        return (f"around a {fault} event (dashed: the pinion passes {event:.1f} deg, where the "
                f"{faulty} map falls furthest below the healthy one at the design centre "
                f"distance{at_op}; every {s.get('fault_event_period_deg', 360.0):.1f} deg)")
    if faulty_pair:
        return (f"in the middle of the record (the stiffness maps do not locate this {fault}: "
                f"the {faulty} map nowhere falls {FAULT_DIP:.1%} below the healthy one)")
    return "in the middle of the record"


def report_stage(case: Case, out: Path, result: StudyResult) -> None:
    """Write ``results.nc`` and the self-contained ``report.html``; PNGs into ``figures/``."""
    t_report = time.perf_counter()
    s = result.summary
    paper = result.paper_case
    method = case.stiffness.method
    n_fig = len(result.figures)
    result.emit("report: results.nc", 0, n_fig + 2)
    write_results_netcdf(out / "results.nc", result, case)
    result.files["results"] = out / "results.nc"
    # the figures a second process has been drawing: this process draws those it has not
    # started (geardyn.studies.figure_process)
    result.figures.finish()
    if paper:
        title = "geardyn: the Xue & Howard (2018) case study"
        subtitle = f"case '{case.name}': {case.description}"
    else:
        title, subtitle = _own_case_title(case, s.get("differences_from_paper", []))
    subtitle += (f" | stiffness by "
                 f"{'finite elements' if method == 'fe' else 'the potential energy method'}"
                 f"{' | QUICK run (shorter records)' if result.quick else ''}")
    rep = Report(title, out, subtitle=subtitle)
    faulty, fault = _faulty_words(case)
    F = result.figures
    done = {"n": 1}

    def fig(name: str, caption: str) -> None:
        if name in F:
            rep.figure(F[name], name, caption)
            done["n"] += 1
            result.emit("report: figures", done["n"], n_fig + 2)

    checks = s.get("checks", [])
    comps = s.get("comparisons", [])
    n_pass = sum(r["pass"] for r in comps)
    n_check = sum(r["pass"] for r in checks)
    cr = s.get("contact_ratio", {})

    # ---------------------------------------------------------------- summary
    rep.heading("Summary")
    if paper:
        rep.paragraph(
            f"Comparisons with the paper that depend on the mesh stiffness and the dynamics "
            f"(Tables 2 and 3): {n_pass} of {len(comps)} within their tolerance, "
            f"{len(comps) - n_pass} outside (listed and explained under 'Where geardyn "
            f"disagrees with the paper'). Separately, {n_check} of {len(checks)} consistency "
            "checks pass; these are fixed by the inputs, the static balance or a calibration "
            "and are not counted as validation.")
        rep.paragraph(
            "Under the input torque the bearings open the centre distance by "
            f"{s.get('centre_distance_change_mm', float('nan')):.4f} mm (paper: about 1.07 mm), "
            f"the operating pressure angle is {s.get('operating_pressure_angle_deg', float('nan')):.3f}"
            f" deg (paper: 21.18 deg) and the contact ratio {cr.get('physical', float('nan')):.4f} "
            f"({cr.get('paper_eq8', float('nan')):.4f} by the paper's eq. 8; paper: 1.43). The "
            f"crack shows at about {s.get('crack_angle_deg', float('nan')):.0f} deg of pinion "
            "rotation (paper: about 170 deg, by geardyn's choice of the cracked tooth).")
    else:
        rep.paragraph(
            "Under the input torque the bearings open the centre distance by "
            f"{s.get('centre_distance_change_mm', float('nan')):.4f} mm, the operating "
            f"pressure angle is {s.get('operating_pressure_angle_deg', float('nan')):.3f} deg and "
            f"the contact ratio {cr.get('physical', float('nan')):.4f} "
            f"({cr.get('paper_eq8', float('nan')):.4f} by eq. 8 of Xue & Howard)."
            + (_located_sentence(case, s) if s.get("crack_angle_deg") is not None
               and _fault_word(case) else "")
            + (f" Not located in the TSA: {s['gear_fault_averaged_out']}."
               if s.get("gear_fault_averaged_out") else "")
            + f" {n_check} of {len(checks)} consistency checks pass.")
    if result.quick:
        rep.note("This is a --quick run: shorter records (fewer revolutions averaged)"
                 + (", coarser stiffness maps" if any(d["key"].startswith("stiffness.") for d in
                                                     s.get("quick_settings", [])) else "")
                 + "; the values used are under 'The case and every assumption'. Run "
                 "'geardyn run' without --quick for the full study.")
    for n in result.notes:
        rep.note(n)

    # ---------------------------------------------------------------- differences, case
    run_case = case_sections(rep, case, s)

    rep.heading("Corrections to the paper that geardyn applies")
    rep.bullets(ERRATA)

    # ---------------------------------------------------------------- geometry
    rep.heading("Geometry at the operating centre distance")
    try:
        geo = json.loads((out / "geometry.json").read_text())
    except (OSError, ValueError):
        geo = {}
    grows = []
    for label, key in (("design", "design"), ("+0.5 mm", "dd_0.5mm"), ("+1.0 mm", "dd_1.0mm"),
                       ("static operating point", "static_operating_point")):
        if key in geo:
            o = geo[key]["operating"]
            grows.append([label, o["centre_distance_m"] * 1e3, o["pressure_angle_deg"],
                          o["contact_ratio"]["physical"], o["contact_ratio"]["paper_eq8"],
                          o["single_contact_fraction"],
                          _zero_small(o["normal_backlash_m"] * 1e6, 1e-6)])
    rep.table(["centre distance", "d' [mm]", "pressure angle [deg]", "contact ratio",
               "contact ratio (eq. 8)", "single-contact fraction", "normal backlash [um]"],
              grows, caption="Operating geometry (Xue & Howard eqs. 4, 6, 8); backlash below "
                             "1e-6 um is round-off and shown as 0")

    # ---------------------------------------------------------------- stiffness
    rep.heading("Mesh stiffness K(theta, d) (Figs. 5, 6)")
    how = (f"2-D finite elements of the real tooth (plane {case.stiffness.fe.plane})"
           if method == "fe" else
           "potential energy (Hertz, bending, shear, axial compression over the exact involute "
           "+ trochoid tooth, fillet-foundation of Sainsot et al.)")
    grid = result.maps.get("healthy")
    dd = (np.asarray(grid.dd, dtype=float) if grid is not None else
          np.linspace(run_case.stiffness.centre_distance_min,
                      run_case.stiffness.centre_distance_max, run_case.stiffness.centre_distances))
    rep.paragraph(
        f"Method: {how}, face width {case.pair.face_width * 1e3:g} mm, "
        f"E = {case.material.youngs_modulus / 1e9:g} GPa. The map covers centre distance "
        f"changes {dd[0] * 1e3:g} to {dd[-1] * 1e3:g} mm on {dd.size} grid lines with "
        "boundary-fitted nodes.")
    mm = s.get("mean_mesh_stiffness_N_per_m", {})
    if mm:
        rep.table(["centre distance change", "mean k_mb [N/m]"], list(mm.items()),
                  caption="Mean mesh stiffness over a revolution (healthy)")
    fig("fig_fe_mesh", "Finite-element mesh of the cracked tooth (zoom): the mesh the "
                       "stiffness maps were computed on"
                       + (f" (--quick: refinement {s['fe_mesh_refinement']:g})"
                          if result.quick and "fe_mesh_refinement" in s else "") + ".")
    fig("fig5_stiffness", "Fig. 5a analogue: combined torsional mesh stiffness K_t [N m/rad] "
                          "against pinion rolling angle for centre distance changes 0, 0.5, 1 mm.")
    fig("fig5_load_sharing", "Fig. 5b analogue: load sharing ratio of one tooth pair.")
    located = s.get("fault_event_angle_deg") is not None
    fig("fig6_crack", "Fig. 6 analogue: healthy (K00) and cracked (KC005, KC105) stiffness."
        if faulty == "cracked" else
        f"Fig. 6 analogue for this case's {fault}: healthy (K00) and {faulty} stiffness at centre "
        "distance changes 0 and 1 mm, "
        + (f"around the pinion angle where the {faulty} map falls furthest below the healthy "
           "one." if located else
           f"not centred on the {fault}: the {faulty} map nowhere falls {FAULT_DIP:.1%} below "
           "the healthy one."))

    # ---------------------------------------------------------------- dynamics
    rep.heading("Dynamics, model I, model I-static and model II (Figs. 8-10)")
    sims = s.get("simulations", {})
    srows = []
    for key, v in sims.items():
        srows.append([key.replace("_", " ").replace("cracked", faulty),
                      v.get("mean_centre_distance_change_m", 0) * 1e3,
                      v.get("mean_pressure_angle_deg"), v.get("mean_contact_ratio"),
                      v.get("mean_contact_ratio_eq8"), v.get("mean_pinion_speed_rad_s"),
                      v.get("mean_transmission_error_rad"), v.get("steps_iterating_fraction"),
                      (v.get("max_residual_before_m") or float("nan")) * 1e6])
    rep.table(["run", "mean d' - d [mm]", "pressure angle [deg]", "contact ratio",
               "contact ratio (eq. 8)", "pinion speed [rad/s]", "mean TE [rad]",
               "steps iterating [-]", "max |b1 - b2| before [um]"], srows,
              caption="Simulated records (means over the recorded time)")
    fig("fig8_design_parameters", "Fig. 8 analogue: centre distance change, operating pressure "
                                  "angle and contact ratio of model II "
                                  f"{fault_event_words(s, bool(_fault_word(case)), faulty, fault)}"
                                  "; time from the start of the record.")
    fig("fig9_iteration", "Fig. 9 analogue: |b1 - b2| before and after the iteration, the "
                          "number of iterations and the mesh stiffness used.")
    fig("fig10_stiffness", "Fig. 10 analogue: mesh stiffness used by model I, K_m(theta), and "
                           "by model II, K_m(theta, d); dashed: model I-static, K_m(theta, d_s) "
                           "at the static operating centre distance (not in the paper).")
    mc = s.get("model_comparison", {})
    if mc:
        _model_comparison_section(rep, mc, method, fig, faulty)

    # ---------------------------------------------------------------- diagnostics
    rep.heading("Diagnostics (Figs. 11-23, Tables 2 and 3)")
    fig("fig11_tsa", "Fig. 11 analogue: time synchronous averages over one pinion revolution, "
                     "model I (left) and model II (right).")
    t2 = s.get("table2", {})
    rows2 = []
    for name, title in SIGNAL_TITLES.items():
        if name not in t2:
            continue
        for metric in ("mean", "std", "skewness", "kurtosis", "crest_factor"):
            first = title if metric == "mean" else ""
            rows2.append([first, metric.replace("_", " "),
                          *_model_cells(t2[name], PAPER_TABLE2[name] if paper else None, metric)])
    cap2 = ("Table 2: statistics of the TSA (STD ddof 0, skewness g1, Pearson kurtosis, crest "
            "factor max|x - mean|/STD)")
    if paper:
        rep.table(["signal", "statistic", *_model_headers(True)], rows2, left_columns=2,
                  caption=cap2 + I_STATIC_COLUMN_NOTE)
    else:
        rep.table(["signal", "statistic", *_model_headers(False)], rows2, left_columns=2,
                  caption=cap2.replace("Table 2", "Statistics as the paper's Table 2")
                  + I_STATIC_NOTE_OWN_CASE)
    fig("fig12_spectra", "Fig. 12 analogue: RMS order spectra of the TSAs in dB re 1 unit, "
                         "mean removed (no DC bin); dotted lines mark the mesh harmonics.")
    fig("fig13_residuals", "Fig. 13 analogue: residual signals (all mesh harmonics removed).")
    fig("fig14_pwvd_tsa_gear", "Fig. 14 analogue: PWVD of the TSA of the output gear vertical "
                               "velocity.")
    captions = {"v_yg": ("output gear vertical velocity", 15, 16, 17),
                "omega_p": ("input pinion angular velocity", 18, 19, 20),
                "transmission_error": ("transmission error", 21, 22, 23)}
    for sig, (title, a, b, c) in captions.items():
        fig(f"fig{a}_pwvd_residual_{sig}", f"Fig. {a} analogue: PWVD of the residual of the "
                                           f"{title}.")
        fig(f"fig{b}_demodulation_{sig}", f"Fig. {b} analogue: narrowband envelope, amplitude "
                                          f"and phase modulation of the {title} about the "
                                          f"{case.diagnostics.harmonic}th mesh harmonic.")
        fig(f"fig{c}_analytic_{sig}", f"Fig. {c} analogue: analytic signal of the demodulated "
                                      f"harmonic of the {title}.")
    t3 = s.get("table3", {})
    rows3 = []
    for name, title in SIGNAL_TITLES.items():
        if name not in t3:
            continue
        for metric, label in (("envelope_kurtosis", "envelope kurtosis"),
                              ("am_kurtosis", "amplitude modulation kurtosis"),
                              ("pm_kurtosis", "phase modulation kurtosis"),
                              ("residual_kurtosis", "residual kurtosis (text of Fig. 13)")):
            first = title if metric == "envelope_kurtosis" else ""
            rows3.append([first, label,
                          *_model_cells(t3[name], PAPER_TABLE3[name] if paper else None, metric)])
    cap3 = "Table 3: kurtoses of the demodulated signals and of the residual"
    if paper:
        rep.table(["signal", "quantity", *_model_headers(True)], rows3, left_columns=2,
                  caption=cap3 + I_STATIC_COLUMN_NOTE)
    else:
        rep.table(["signal", "quantity", *_model_headers(False)], rows3, left_columns=2,
                  caption=cap3.replace("Table 3", "As the paper's Table 3")
                  + I_STATIC_NOTE_OWN_CASE)

    cm = s.get("condition_metrics", {})
    if cm:
        _condition_metrics_section(rep, cm, s.get("condition_metrics_undefined", {}),
                                   (faulty, fault))
        if s.get("gear_fault_averaged_out"):  # a metric below its healthy value says why
            rep.note(f"These metrics are of the pinion's TSA: {s['gear_fault_averaged_out']}; "
                     "they do not measure how well an average over the gear's revolutions "
                     "would see it.")
    if "measurement" in s:
        _measurement_section(rep, s["measurement"], result, fig, case, (faulty, fault))

    # ---------------------------------------------------------------- checks, comparisons
    rep.heading("Consistency checks (not validation)")
    rep.paragraph(
        "Quantities fixed by the inputs, the geometry, the static torque balance or a "
        "calibration. A failure here means broken plumbing, except the offset of the fault "
        "seen in the TSA: that one fails where other modulation (tooth errors, another fault) "
        "outweighs the fault's in the envelope, and the envelope's peak then does not locate "
        "it. A pass says nothing about the mesh stiffness or the dynamics, so these rows are "
        "not counted as validation.")
    _rows_table(rep, checks, "expected")
    if paper:
        rep.heading("Comparisons with the paper")
        rep.paragraph(
            "Statistics of the simulated, synchronously averaged signals of the cracked pair "
            "(Tables 2 and 3), which depend on the mesh stiffness and the dynamics. The paper "
            "states no uncertainty, so the tolerances are geardyn's, fixed before comparing "
            "and symmetric in the log-ratio: STD within a factor of "
            f"{STD_FACTOR:g} either way (the paper does not give its damping values, and a "
            "standard deviation scales with the response amplitude), kurtoses and crest "
            f"factors within a factor of {SHAPE_FACTOR:g} either way (they describe the "
            f"waveform's shape, not its size). {n_pass} of {len(comps)} within tolerance, "
            f"{len(comps) - n_pass} misses.")
        _rows_table(rep, comps, "paper")
        rep.heading("Where geardyn disagrees with the paper, and why")
        rep.bullets(disagreements(s))

    # ---------------------------------------------------------------- run details
    rep.heading("Run details")
    rep.paragraph(RESULTS_LAYOUT)
    if faulty != "cracked":
        rep.paragraph(
            "Key names: in summary.json, results.nc (state 'cracked', stiffness/cracked, "
            "diagnostics/model_<M>_cracked) and the runs/*_cracked.nc files, 'cracked' names "
            f"the {faulty} pair of this case ({_fault_description(case)}) and crack_angle_deg "
            f"the angle where its {fault} shows; the names are kept for every fault so scripts "
            "read every run alike.")
    files = [("results.nc", _size(out / "results.nc"))]
    run_files = s.get("run_files", {})
    for rel in run_files.values():
        files.append((rel, _size(out / rel)))
    for name in ("stiffness_healthy.nc", "stiffness_cracked.nc", "summary.json",
                 "geometry.json", "case.toml"):
        files.append((name, _size(out / name)))
    total_nc = sum((out / f).stat().st_size for f in ["results.nc", *run_files.values()]
                   if (out / f).exists())
    files.append(("results.nc + runs/*.nc", f"{total_nc / 1e6:.1f} MB"))
    rep.table(["file", "size"], files, caption="Files written (report.html and figures/*.png "
                                               "besides)", left_columns=1)
    result.emit("report: report.html", n_fig + 1, n_fig + 2)
    t_rep = time.perf_counter() - t_report
    times = [[k, v] for k, v in result.seconds.items() if k != "report"]
    times.append(["report (until this file was written)", t_rep])
    times.append(["total", sum(v for k, v in result.seconds.items() if k != "report") + t_rep])
    rep.table(["stage", "wall time [s]"], times, caption="Time per stage")
    rep.table(["package", "version"], _versions(), caption="Versions")
    rep.paragraph(f"Command line: {command_line()}.")
    rep.heading("Citations")
    rep.bullets(citations(result.maps.values()))
    rep.write(footer=f"geardyn {__version__}.")
    s["figures"] = sorted(p.name for p in rep.figures)
    s["output_size_bytes"] = {"results.nc": (out / "results.nc").stat().st_size,
                              "results.nc + runs": total_nc}
    result.emit("report: report.html", n_fig + 2, n_fig + 2)


def _citation_key(text: str) -> tuple[str, str]:
    """(first author's surname, year) of a citation, in the full form of :data:`CITATIONS`
    ("Yang, D. C. H. & Lin, J. Y. (1987). ...") or the maps' short form ("Yang & Lin 1987,
    ...")."""
    import re

    name = re.match(r"[^\W\d_][\w'-]*", text)
    year = re.search(r"\b(1[89]\d\d|20\d\d)\b", text)
    return (name.group(0) if name else text, year.group(1) if year else "")


def citations(maps) -> list[str]:
    """The report's citations: :data:`CITATIONS`, then those the stiffness ``maps`` cite
    (their ``citations`` attribute) that it does not hold already, each work once, in its full
    form where :data:`CITATIONS` has one (a work is matched by its first author and year)."""
    cites = list(CITATIONS)
    known = {_citation_key(c) for c in cites}
    for m in maps:
        c = m.attrs.get("citations")
        for text in (json.loads(c) if isinstance(c, str) else (c or [])):
            if _citation_key(text) not in known:
                cites.append(text)
                known.add(_citation_key(text))
    return cites


def _rows_table(rep: Report, rows: list[dict], ref_label: str) -> None:
    vrows = [[r["quantity"], r["reference"], r["geardyn"], r["tolerance_text"],
              "pass" if r["pass"] else "FAIL", r.get("source", ""), r.get("note", "")]
             for r in rows]
    rep.table(["quantity", ref_label, "geardyn", "tolerance", "result", "source", "note"], vrows,
              left_columns=1, left=(3, 5, 6),
              classes=[["", "", "", "", "pass" if r["pass"] else "fail", "", ""] for r in rows])


def location_check_failed(s: dict) -> dict | None:
    """The consistency check of the fault's angle in the TSA (its offset from where the faulty
    map is weakest) when it failed, else None."""
    for row in s.get("checks", []):
        if "seen in the TSA: offset" in str(row.get("quantity", "")) and not row.get("pass"):
            return row
    return None


def _located_sentence(case: Case, s: dict) -> str:
    """Where the narrowband envelope puts the fault: " The fault shows at about 172 deg of
    pinion rotation (...)."; with a gear fault the pinion's TSA averages out, the pinion's
    faults only; where the location check failed, the peak and why it is not the fault's (it
    claimed the crack "shows at about 196 deg" beside its own failed check: a user audit)."""
    failed = location_check_failed(s)
    if failed is not None:
        return (f" The narrowband envelope peaks at about {s.get('crack_angle_deg'):.0f} deg of "
                f"pinion rotation, {abs(float(failed['geardyn'])):.1f} deg from where the faulty "
                f"map is weakest (more than the envelope's resolution, +/- "
                f"{float(failed['tolerance']):.1f} deg): it does not locate the "
                f"{_fault_word(case)} here (see the consistency checks).")
    word = _fault_word(case)
    if s.get("gear_fault_averaged_out"):
        n = sum(1 for f in (case.faults or ()) if (f.gear or "pinion") == "pinion") + int(
            case.active_crack is not None and case.crack.gear == "pinion")
        word = "pinion's faults" if n > 1 else "pinion's fault"
    verb = "show" if word.endswith("faults") else "shows"
    return (f" The {word} {verb} at about {s.get('crack_angle_deg'):.0f} deg of pinion rotation "
            "(the peak of the narrowband envelope).")


def _condition_metrics_section(rep: Report, cm: dict, undefined: dict,
                               words: tuple[str, str] = ("cracked", "crack")) -> None:
    faulty, fault = words
    rep.heading(f"{fault.capitalize()} detection: condition metrics, healthy against {faulty}",
                level=3)
    rep.paragraph("Condition metrics of the TSA (MATLAB gearConditionMetrics names; NA4* "
                  f"uses the healthy record's residual variance as baseline). The {fault} counts "
                  f"as detected by a metric when the {faulty} value exceeds the healthy one by "
                  "more than 50%.")
    ratio_undef = "EnergyRatio cracked / healthy" in undefined
    if undefined:
        reason = next(iter(undefined.values()))
        rep.note(f"NA4* and the energy ratio's change are shown as 'undefined': {reason}. "
                 "The healthy values of FM4, M6A, M8A and NA4 are statistics of that same "
                 "numerical remainder.")
    if any("I-static" in cm[name] for name in SIGNAL_KEYS.values()):
        rep.paragraph("Model I-static (the stiffness map held at the static operating centre "
                      "distance) is geardyn's addition, not in the paper: where its rows read as "
                      "model II's, the metric sees the fault without model II's iteration.")
    rows4, cls4 = [], []
    for name in SIGNAL_KEYS.values():
        for m in [m for m in ("I", "I-static", "II") if m in cm[name]]:
            h, c = cm[name][m]["healthy"], cm[name][m]["cracked"]
            for k in CONDITION_METRICS:
                hk, ck = h.get(k), c.get(k)
                if hk is None or ck is None:
                    cells = ["undefined", "undefined", "undefined", "-"]
                    det = False
                elif k == "EnergyRatio" and ratio_undef:
                    cells = [hk, ck, "undefined", "-"]
                    det = False
                else:
                    ratio = ck / hk if hk and math.isfinite(hk) else float("nan")
                    det = bool(ratio > 1.5)
                    cells = [hk, ck, ratio, "detected" if det else "-"]
                rows4.append([f"{name.replace('_', ' ')}, model {m}" if k == "FM0" else "", k,
                              *cells])
                cls4.append(["", "", "", "", "", "pass" if det else ""])
    rep.table(["signal, model", "metric", "healthy", faulty, f"{faulty} / healthy", fault],
              rows4, left_columns=2, classes=cls4)


def _measurement_section(rep: Report, m: dict, result: StudyResult, fig, case: Case,
                         words: tuple[str, str] = ("cracked", "crack")) -> None:
    """The paper's indicators on a realistic measurement (:mod:`.paper_measurement`)."""
    from .paper_measurement import INDICATORS, NOT_COMPUTED, VARIANTS, statements

    faulty, fault = words

    rep.heading("The indicators on a realistic measurement (housing accelerometer, tooth "
                "errors, noise)", level=3)
    if "skipped" in m:
        rep.note(f"Not computed: {m['skipped']}.")
        return
    rec = m["records"].get("errors+noise|healthy", {})
    secs = result.seconds.get("measurement")
    # a case with its own tooth errors: the simulation stage's records hold them (the text
    # said "perfect teeth" for the tooth-error example: a user audit, 2026-11-27)
    own = str(m.get("errors", "")).startswith("the case's own")
    rep.paragraph(
        "The tables above use noise-free state velocities of "
        + ("the case's teeth (with its own errors)" if own else "perfect teeth")
        + " and the exact shaft angle. Here the same indicators (Table 2's shape statistics, "
        "Table 3's kurtoses, the "
        f"condition metrics) are computed for model {m['model']} on what a condition-monitoring "
        f"engineer records: the {m['signal']}, through the case's transfer path "
        f"({m['chain']}). Four variants separate the inputs: 'ideal' (perfect teeth; no "
        "additive noise, ADC or tachometer jitter), 'errors only', 'noise only' and 'errors + "
        f"noise' (the realistic record). Tooth errors: {m['errors']}. Noise: {m['noise']}. "
        f"Each record is {rec.get('record_s', float('nan')):.3g} s at "
        f"{rec.get('fs_Hz', float('nan')):.6g} Hz ({rec.get('revolutions', 0)} revolutions "
        "averaged; the simulated records less the chain's lead-in and tail). The records "
        + ("with errors are the simulation stage's; the two without are extra cached "
           if own else "without errors are the simulation stage's; the two with errors are "
           "extra cached ")
        + "simulations of the same length"
        + (f"; this stage took {secs:.1f} s." if secs is not None else "."))
    if m.get("undefined", {}).get("ideal"):
        rep.note("On the ideal record the healthy residual is numerical remainder (all teeth "
                 f"alike), so NA4* and the {faulty} / healthy energy ratio are undefined there, "
                 "as in the table above; with tooth errors or noise the healthy baseline is "
                 "real and they are finite.")
    labels = {k: (lab, src) for k, lab, src in INDICATORS}
    ref = m.get("reference", {})
    undefined_ideal = set(m.get("undefined", {}).get("ideal", []))
    for state in ("healthy", "cracked"):
        rows = []
        for k, row in m["drivers"][state].items():
            lab, src = labels[k]
            r = ref.get(state, {}).get(k)
            ideal = row["ideal"]
            cells = [lab, src, "undefined" if r is None else r,
                     "undefined" if ideal is None or k in undefined_ideal else ideal,
                     row["errors"], row["noise"], row["errors+noise"], row["driver"]]
            rows.append(cells)
        rep.table(["indicator", "source", "state velocity, exact angle", "sensor: ideal",
                   "errors only", "noise only", "errors + noise", "driven by"], rows,
                  left_columns=2, left=(7,),
                  caption=f"{state.replace('cracked', faulty).capitalize()} pair: indicators "
                          "of the TSA of the gear "
                          "vertical velocity (the paper's signal, from the tables above) and "
                          "of the housing acceleration in the four variants; 'driven by' is "
                          "the input whose variant lies closer to the realistic one (log "
                          "scale), 'neither' when no variant moves it by 10%")
    det = m["detections"]
    drows, dcls = [], []
    for k, (lab, _src) in labels.items():
        cells = [lab]
        cl = [""]
        for name in VARIANTS:
            r = det[name][k]
            cells.append("undefined" if r["ratio"] is None else r["ratio"])
            cl.append("pass" if r["detected"] else "")
        drows.append(cells)
        dcls.append(cl)
    rep.table(["indicator", "ideal", "errors only", "noise only", "errors + noise"], drows,
              left_columns=1, classes=dcls,
              caption=f"{faulty.capitalize()} / healthy of each indicator on the housing "
                      f"acceleration (highlighted: above 1.5, the {fault} is seen)")
    hd = m.get("housing_damping")
    if hd and "skipped" not in hd:
        hrows = []
        skipped = {f"{float(k):g}" for k in hd.get("not_computed", {})}
        for i, zeta in enumerate(hd["damping_ratios"]):
            fh, fc = hd["healthy"]["FM4"][i], hd["cracked"]["FM4"][i]
            if f"{zeta:g}" in skipped:  # the same word as the sentence below the table
                hrows.append([100 * zeta, hd["decay_over_mesh_period"][i], *[NOT_COMPUTED] * 5])
                continue
            hrows.append([100 * zeta, hd["decay_over_mesh_period"][i], fh, fc,
                          fc / fh if fh else float("nan"), hd["cracked"]["NA4star"][i],
                          hd["cracked"]["EnergyRatio"][i] / hd["healthy"]["EnergyRatio"][i]
                          if hd["healthy"]["EnergyRatio"][i] else float("nan")])
        rep.table(["damping ratio of every housing mode [%]",
                   "decay time of the lowest mode / mesh period", "FM4 healthy",
                   f"FM4 {faulty}", f"FM4 {faulty} / healthy", f"NA4* {faulty}",
                   f"energy ratio {faulty} / healthy"],
                  hrows, left_columns=0,
                  caption="The realistic record (errors + noise) through the same transfer path "
                          "with every mode's damping ratio set to each value: how much of the "
                          "healthy FM4 the housing path makes (modes "
                          + ", ".join(f"{f:g} Hz" for f in hd["mode_frequencies_Hz"])
                          + "; this case's damping ratios: "
                          + ", ".join(f"{100 * z:g}%" for z in hd["case_damping_ratios"]) + ")")
    rep.paragraph("What the numbers say (computed from the tables, not written by hand):")
    rep.bullets(statements(m, words))
    fig("fig24_measured_tsa", "TSA of the housing acceleration over one revolution from the "
                              "tachometer: ideal, tooth errors only, and tooth errors with "
                              f"noise (the realistic record), healthy and {faulty}.")
    cmd = m.get("reproduce")
    if cmd:
        real = m["indicators"]["errors+noise"]
        rep.paragraph(
            "The same realistic records as files (this run's effective case as it wrote it to "
            "case.toml: case file, --set overrides, stiffness method"
            + ("; the case's own [modifications] are the tooth errors" if cmd["own_errors"]
               else "; the --set modifications options are the tooth errors above")
            + "; the record as long as this section's, "
            + f"{m['records']['errors+noise|healthy']['record_s']:.4g} s"
            + (", and the --quick run's coarser map and shorter settling" if result.quick
               else "")
            + f"; paths from the folder the run was started in): {cmd['healthy']} and "
            f"{cmd['faulty']}, then {cmd['diagnose_healthy']} and {cmd['diagnose_faulty']}. "
            "The metrics.json that diagnose writes then holds this section's FM4 of the "
            f"realistic record, {_fmt_num(real['healthy']['FM4'])} healthy and "
            f"{_fmt_num(real['cracked']['FM4'])} {faulty}.")


#: Appended to the captions of Tables 2 and 3.
I_STATIC_COLUMN_NOTE = (". Model I-static (K(theta) at the static operating centre distance, "
                        "held fixed) is geardyn's addition: the paper has no such model ('-')")
#: The same for a case that is not the paper's: no paper columns, so no '-' (a user audit).
I_STATIC_NOTE_OWN_CASE = (". Model I-static (K(theta) at the static operating centre distance, "
                          "held fixed) is geardyn's addition, not in the paper")


def _model_headers(paper: bool) -> list[str]:
    """Column headers of Tables 2 and 3 after the signal and statistic columns."""
    if paper:
        return [h for m in TABLE_MODELS for h in (f"paper, model {m}", f"geardyn, model {m}")]
    return [f"model {m}" for m in TABLE_MODELS]


def _model_cells(ours: dict, theirs: dict | None, key: str) -> list:
    """One row's cells of Table 2 or 3 (``theirs``: the paper's values, None off the paper's
    case); '-' where a model has no value (the paper's I-static, an older summary)."""
    cells = []
    for m in TABLE_MODELS:
        if theirs is not None:
            cells.append(theirs.get(m, {}).get(key, "-"))
        cells.append(ours.get(m, {}).get(key, "-"))
    return cells


def _pct(x) -> str:
    return "-" if x is None or not math.isfinite(x) else f"{100.0 * x:.3g} %"


def _finite(signals: dict, key: str) -> dict:
    """``signal -> value`` of ``key`` where it is a finite number."""
    return {n: v[key] for n, v in signals.items()
            if v.get(key) is not None and math.isfinite(v[key])}


def model_comparison_statements(mc: dict, method: str, faulty: str = "cracked") -> list[str]:
    """What the model comparison says, in words, generated from its numbers.

    Parameters
    ----------
    mc : dict
        ``summary["model_comparison"]`` (:func:`geardyn.studies.paper.model_comparison`).
    method : {"fe", "pem"}
        Stiffness method of the run (the PEM's handover steps get their own sentence).
    faulty : str
        The report's word for the state ``"cracked"`` ("faulty" when the fault is not a crack).

    Returns
    -------
    list of str
        One statement per state, then one on where the remaining difference sits, and for the
        PEM one on what that means.
    """
    out = []
    tops = []
    for st in ("cracked", "healthy"):
        if st not in mc:
            continue
        sig = mc[st]["signals"]

        d_s, d_1, f, top = (_finite(sig, k) for k in ("rms_ii_minus_i_static",
                                                      "rms_ii_minus_i", "explained_fraction",
                                                      "top_share"))
        tops += list(top.values())
        if not d_s or not d_1:
            continue
        worst = max(d_s, key=d_s.get)
        text = (f"{st.replace('cracked', faulty).capitalize()} pair: model I-static "
                "reproduces model II to within "
                f"{_pct(d_s[worst])} of each signal's STD (largest over the {len(d_s)} signals: "
                f"{worst.replace('_', ' ')}), against {_pct(min(d_1.values()))} to "
                f"{_pct(max(d_1.values()))} for model I")
        if f:
            text += (f"; the static shift of the operating point (centre distance change "
                     f"{mc[st]['static_centre_distance_change_mm']:.4g} mm) explains "
                     f"{_pct(min(f.values()))} to {_pct(max(f.values()))} of the model II - "
                     "model I difference (RMS)")
        text += (f". On this case what model II adds beyond the static shift (the "
                 f"centre-distance dynamics, and time-step effects) is at most {_pct(d_s[worst])} "
                 "of a signal's STD.")
        out.append(text)
    if tops:
        out.append(f"Where the remaining difference sits: the largest 1 % of the samples carry "
                   f"{_pct(min(tops))} to {_pct(max(tops))} of the squared model II - model "
                   "I-static difference (over the signals and states; about 1 % for a "
                   "difference spread evenly over the record, near 100 % for isolated steps).")
    if method == "pem" and out:
        out.append(
            "With the potential-energy map the single/double contact handovers move with the "
            "centre distance, so model II's few-micrometre motion about the static point puts "
            "some handovers in a different time step than model I-static's: the records then "
            "differ by isolated one-step events. geardyn's verification of model I-static (paper "
            "case, PEM map, time steps 10, 5 and 2.5 us) finds the velocity and "
            "transmission-error part of that gap shrinking with the time step and the mesh "
            "force's one-step spikes not: part of the model II - model I-static difference above is "
            "a time-step effect of the PEM's sharp handovers, not centre-distance dynamics.")
    return out


def _model_comparison_section(rep: Report, mc: dict, method: str, fig,
                              faulty: str = "cracked") -> None:
    """The model comparison: table, figure and the generated statements."""
    rep.heading("How much of the model II - model I difference the static shift explains",
                level=3)
    rep.paragraph(
        "Model I reads the mesh stiffness at the design centre distance, model II at the "
        "operating centre distance iterated every step, and model I-static (geardyn's addition, "
        "not in the paper) at the static operating centre distance of eq. 4, held fixed. Model "
        "II differs from model I-static only through the centre-distance dynamics, from model I "
        "through those and the static shift. Per signal, over the recorded time: RMS of the "
        "difference (its mean included) over model II's standard deviation; explained fraction "
        "1 - RMS(II - I-static) / RMS(II - I) (1: the static shift explains all of the model "
        "II - model I difference); top 1 %: the share of the squared II - I-static difference "
        "in the largest 1 % of its samples.")
    rows = []
    for st in ("cracked", "healthy"):
        if st not in mc:
            continue
        for i, (name, v) in enumerate(mc[st]["signals"].items()):
            rows.append([st.replace("cracked", faulty) if i == 0 else "",
                         name.replace("_", " "), v.get("units", ""),
                         _pct(v.get("rms_ii_minus_i_static")), _pct(v.get("rms_ii_minus_i")),
                         _pct(v.get("explained_fraction")), _pct(v.get("top_share"))])
    rep.table(["pair", "signal", "unit", "RMS(II - I-static) / STD(II)", "RMS(II - I) / STD(II)",
               "explained fraction", "top 1 % share"], rows, left_columns=3,
              caption="Model I and model I-static against model II (compare_models of the "
                      "records in runs/)")
    fig("fig_model_comparison", "RMS(II - I) / STD(II) and RMS(II - I-static) / STD(II) per "
                                "signal (log scale).")
    rep.paragraph("What the numbers say (generated from the table):")
    rep.bullets(model_comparison_statements(mc, method, faulty))
