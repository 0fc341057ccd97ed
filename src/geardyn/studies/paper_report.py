"""The report stage of the paper study: ``report.html``, ``results.nc`` and ``figures/``."""

from __future__ import annotations

import json
import platform
import sys
from importlib import metadata
from pathlib import Path

import numpy as np

from ..config import Case, case_to_toml
from ..io import atomic_path, json_safe
from .report import Report

__all__ = ["report_stage", "write_results_netcdf", "ERRATA", "CITATIONS"]

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

SIGNAL_TITLES = {"gear_vertical_velocity": "output gear vertical velocity [m/s]",
                 "pinion_angular_velocity": "input pinion angular velocity [rad/s]",
                 "transmission_error": "transmission error theta_p - theta_g [rad]"}


def _versions() -> list[tuple[str, str]]:
    out = [("python", platform.python_version()), ("platform", platform.platform())]
    for pkg in ("geardyn", "numpy", "scipy", "numba", "xarray", "h5netcdf", "matplotlib",
                "pydantic", "scikit-fem", "gmsh"):
        try:
            out.append((pkg, metadata.version(pkg)))
        except metadata.PackageNotFoundError:
            out.append((pkg, "not installed"))
    return out


def _case_rows(case: Case) -> list[tuple[str, str, str]]:
    """(key, value, source) for every value of the case, in file order."""
    text = case_to_toml(case)
    import tomllib

    data = tomllib.loads(text)
    rows: list[tuple[str, str, str]] = []

    def walk(node, prefix):
        for k, v in node.items():
            key = f"{prefix}.{k}" if prefix else k
            if isinstance(v, dict) and not ("value" in v and set(v) <= {"value", "source"}):
                walk(v, key)
            elif isinstance(v, dict):
                rows.append((key, str(v["value"]), v.get("source", "")))
            elif key in ("name", "description"):
                continue
            else:
                rows.append((key, str(v), case.provenance.get(key, "geardyn default "
                                                                    "(schema default)")))

    walk(data, "")
    return rows


def _disagreements(s: dict) -> list[str]:
    """Where geardyn's numbers differ from the paper's, in words, computed from the summary."""
    out = []
    t2, t3 = s.get("table2", {}), s.get("table3", {})
    from .paper import PAPER_TABLE2, PAPER_TABLE3

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
                f"-> {t3[name]['II']['residual_kurtosis']:.2f}). Residual kurtoses are ratios "
                "of tiny sideband energies and depend on the damping values the paper does not "
                "give (geardyn's are documented defaults) and on the crack model (PEM or FE).")
        for m in ("I", "II"):
            cf, pcf = t2[name][m]["crest_factor"], PAPER_TABLE2[name][m]["crest_factor"]
            if abs(cf - pcf) > 0.3 * pcf:
                out.append(
                    f"Crest factor of the {title.split(' [')[0]}, model {m}: {cf:.2f} against "
                    f"the paper's {pcf:.2f}. The crest factor is set by the sharpest peak of the "
                    "TSA, i.e. by the crack event's size relative to the mesh vibration, which "
                    "depends on the crack's stiffness loss and the undocumented damping.")
        for m in ("I", "II"):
            pk, ppk = t3[name][m]["pm_kurtosis"], PAPER_TABLE3[name][m]["pm_kurtosis"]
            if abs(pk - ppk) > 0.3 * ppk:
                out.append(
                    f"Phase-modulation kurtosis of the {title.split(' [')[0]}, model {m}: "
                    f"{pk:.2f} against {ppk:.2f}.")
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


def write_results_netcdf(path: Path, result, case: Case) -> None:
    """Everything in one NetCDF-4 file (groups), written atomically.

    Groups: ``stiffness/healthy``, ``stiffness/cracked``, ``simulation/model_<M>_<state>``,
    ``diagnostics/model_<M>_<state>``; the root holds the summary (JSON) and the case (TOML).
    """
    import xarray as xr

    root = xr.Dataset(attrs={"title": "geardyn: Xue & Howard (2018) case study",
                             "summary_json": json.dumps(json_safe(result.summary)),
                             "case_toml": case_to_toml(case),
                             "geardyn_version": dict(_versions()).get("geardyn", "")})
    with atomic_path(path, suffix=".nc") as tmp:
        root.to_netcdf(tmp, engine="h5netcdf", mode="w")
        for state, m in result.maps.items():
            m.to_dataset().to_netcdf(tmp, engine="h5netcdf", mode="a",
                                     group=f"stiffness/{state}")
        for (model, state), ds in result.sims.items():
            ds.to_netcdf(tmp, engine="h5netcdf", mode="a",
                         group=f"simulation/model_{model}_{state}")
        for (model, state), diag in result.diagnoses.items():
            _diagnosis_dataset(diag).to_netcdf(tmp, engine="h5netcdf", mode="a",
                                               group=f"diagnostics/model_{model}_{state}")


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


def report_stage(case: Case, out: Path, result) -> None:
    """Assemble ``report.html`` (self-contained) and ``results.nc``; PNGs into ``figures/``."""
    from .paper import CONDITION_METRICS, PAPER_TABLE2, PAPER_TABLE3, SIGNAL_KEYS

    s = result.summary
    method = case.stiffness.method
    rep = Report("geardyn: the Xue & Howard (2018) case study", out,
                 subtitle=f"case '{case.name}': {case.description} | stiffness by "
                          f"{'finite elements' if method == 'fe' else 'the potential energy method'}"
                          f"{' | QUICK run (shorter records)' if result.quick else ''}")
    F = result.figures

    def fig(name: str, caption: str) -> None:
        if name in F:
            rep.figure(F[name], name, caption)

    # ---------------------------------------------------------------- summary
    rep.heading("Summary")
    val = s.get("validation", [])
    n_pass = sum(v["pass"] for v in val)
    rep.paragraph(
        f"geardyn reproduced the paper's case study: {n_pass} of {len(val)} comparisons with the "
        "paper's values are within their tolerance (table at the end). Under the input torque the "
        f"bearings open the centre distance by {s.get('centre_distance_change_mm', float('nan')):.4f} "
        f"mm (paper: about 1.07 mm), the operating pressure angle is "
        f"{s.get('operating_pressure_angle_deg', float('nan')):.3f} deg (paper: 21.18 deg) and the "
        f"contact ratio {s.get('contact_ratio', {}).get('physical', float('nan')):.4f} "
        f"({s.get('contact_ratio', {}).get('paper_eq8', float('nan')):.4f} by the paper's eq. 8; "
        "paper: 1.43). The crack shows at about "
        f"{s.get('crack_angle_deg', float('nan')):.0f} deg of pinion rotation (paper: about 170 deg).")
    if result.quick:
        rep.note("This is a --quick run: shorter records (fewer revolutions averaged). Run "
                 "'geardyn run' without --quick for the full study.")
    for n in result.notes:
        rep.note(n)

    # ---------------------------------------------------------------- case
    rep.heading("The case and every assumption")
    rep.paragraph("Every value of the case with its source. Values marked 'geardyn default' "
                  "(in amber) are not given by the paper; the source says what geardyn chose "
                  "and why.")
    rows = _case_rows(case)
    rep.table(["key", "value (SI)", "source"], rows, left_columns=3,
              classes=[["", "", "assume" if r[2].startswith("geardyn") else ""] for r in rows])

    rep.heading("Errata in the paper that geardyn corrects")
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
                          o["single_contact_fraction"], o["normal_backlash_m"] * 1e6])
    rep.table(["centre distance", "d' [mm]", "pressure angle [deg]", "contact ratio",
               "contact ratio (eq. 8)", "single-contact fraction", "normal backlash [um]"],
              grows, caption="Operating geometry (eqs. 4, 6, 8)")

    # ---------------------------------------------------------------- stiffness
    rep.heading("Mesh stiffness K(theta, d) (Figs. 5, 6)")
    how = (f"2-D finite elements of the real tooth (plane {case.stiffness.fe.plane})"
           if method == "fe" else
           "potential energy (Hertz, bending, shear, axial compression over the exact involute "
           "+ trochoid tooth, fillet-foundation of Sainsot et al.)")
    rep.paragraph(
        f"Method: {how}, face width {case.pair.face_width * 1e3:g} mm, "
        f"E = {case.material.youngs_modulus / 1e9:g} GPa. The map covers centre distance "
        f"changes {case.stiffness.centre_distance_min * 1e3:g} to "
        f"{case.stiffness.centre_distance_max * 1e3:g} mm on {case.stiffness.centre_distances} "
        "grid lines with boundary-fitted nodes.")
    mm = s.get("mean_mesh_stiffness_N_per_m", {})
    if mm:
        rep.table(["centre distance change", "mean k_mb [N/m]"], list(mm.items()),
                  caption="Mean mesh stiffness over a revolution (healthy)")
    fig("fig_fe_mesh", "Finite-element mesh of the cracked tooth (zoom).")
    fig("fig5_stiffness", "Fig. 5a analogue: combined torsional mesh stiffness K_t [N m/rad] "
                          "against pinion rolling angle for centre distance changes 0, 0.5, 1 mm.")
    fig("fig5_load_sharing", "Fig. 5b analogue: load sharing ratio of one tooth pair.")
    fig("fig6_crack", "Fig. 6 analogue: healthy (K00) and cracked (KC005, KC105) stiffness.")

    # ---------------------------------------------------------------- dynamics
    rep.heading("Dynamics, model I and model II (Figs. 8-10)")
    sims = s.get("simulations", {})
    srows = []
    for key, v in sims.items():
        srows.append([key.replace("_", " "), v.get("mean_centre_distance_change_m", 0) * 1e3,
                      v.get("mean_pressure_angle_deg"), v.get("mean_contact_ratio"),
                      v.get("mean_contact_ratio_eq8"), v.get("mean_pinion_speed_rad_s"),
                      v.get("mean_transmission_error_rad"), v.get("steps_iterating_fraction"),
                      (v.get("max_residual_before_m") or float("nan")) * 1e6])
    rep.table(["run", "mean d' - d [mm]", "pressure angle [deg]", "contact ratio",
               "contact ratio (eq. 8)", "pinion speed [rad/s]", "mean TE [rad]",
               "steps iterating [-]", "max |b1 - b2| before [um]"], srows,
              caption="Simulated records (means over the recorded time)")
    fig("fig8_design_parameters", "Fig. 8 analogue: centre distance change, operating pressure "
                                  "angle and contact ratio of model II around a crack event.")
    fig("fig9_iteration", "Fig. 9 analogue: |b1 - b2| before and after the iteration, the "
                          "number of iterations and the mesh stiffness used.")
    fig("fig10_stiffness", "Fig. 10 analogue: mesh stiffness used by model I, K_m(theta), and "
                           "by model II, K_m(theta, d).")

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
            rows2.append([title if metric == "mean" else "", metric.replace("_", " "),
                          PAPER_TABLE2[name]["I"][metric], t2[name]["I"][metric],
                          PAPER_TABLE2[name]["II"][metric], t2[name]["II"][metric]])
    rep.table(["signal", "statistic", "paper, model I", "geardyn, model I", "paper, model II",
               "geardyn, model II"], rows2, left_columns=2,
              caption="Table 2: statistics of the TSA (STD ddof 0, skewness g1, Pearson "
                      "kurtosis, crest factor max|x - mean|/STD)")
    fig("fig12_spectra", "Fig. 12 analogue: RMS order spectra of the TSAs in dB; dotted lines "
                         "mark the mesh harmonics.")
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
            rows3.append([title if metric == "envelope_kurtosis" else "", label,
                          PAPER_TABLE3[name]["I"][metric], t3[name]["I"][metric],
                          PAPER_TABLE3[name]["II"][metric], t3[name]["II"][metric]])
    rep.table(["signal", "quantity", "paper, model I", "geardyn, model I", "paper, model II",
               "geardyn, model II"], rows3, left_columns=2,
              caption="Table 3: kurtoses of the demodulated signals and of the residual")

    cm = s.get("condition_metrics", {})
    if cm:
        rep.heading("Crack detection: condition metrics, healthy against cracked", level=3)
        rep.paragraph("Condition metrics of the TSA (MATLAB gearConditionMetrics names; NA4* "
                      "uses the healthy record's residual variance as baseline). The crack counts "
                      "as detected by a metric when the cracked value exceeds the healthy one by "
                      "more than 50%.")
        rows4, cls4 = [], []
        for name in SIGNAL_KEYS.values():
            for m in ("I", "II"):
                h, c = cm[name][m]["healthy"], cm[name][m]["cracked"]
                for k in CONDITION_METRICS:
                    ratio = c[k] / h[k] if h[k] else float("nan")
                    det = bool(ratio > 1.5)
                    rows4.append([f"{name.replace('_', ' ')}, model {m}" if k == "FM0" else "",
                                  k, h[k], c[k], ratio, "detected" if det else "-"])
                    cls4.append(["", "", "", "", "", "pass" if det else ""])
        rep.table(["signal, model", "metric", "healthy", "cracked", "cracked / healthy",
                   "crack"], rows4, left_columns=2, classes=cls4)

    # ---------------------------------------------------------------- validation
    rep.heading("Paper vs geardyn")
    vrows = [[v["quantity"], v["paper"], v["geardyn"], v["tolerance"],
              "pass" if v["pass"] else "FAIL", v.get("note", "")] for v in val]
    rep.table(["quantity", "paper", "geardyn", "tolerance", "result", "note"], vrows,
              left_columns=1, left=(5,), classes=[["", "", "", "", "pass" if v["pass"] else "fail", ""]
                                       for v in val])
    rep.heading("Where geardyn disagrees with the paper, and why")
    rep.bullets(_disagreements(s))

    # ---------------------------------------------------------------- run details
    rep.heading("Run details")
    times = [[k, v] for k, v in result.seconds.items()]
    rep.table(["stage", "wall time [s]"], times, caption="Time per stage")
    rep.table(["package", "version"], _versions(), caption="Versions")
    rep.paragraph(f"Command line: {' '.join(sys.argv) or '(library call)'}. Outputs: "
                  "report.html (this file), results.nc (maps, records and diagnostics with "
                  "units), summary.json, figures/*.png, geometry.json, case.toml.")
    rep.heading("Citations")
    cites = list(CITATIONS)
    for m in result.maps.values():
        c = m.attrs.get("citations")
        for text in (json.loads(c) if isinstance(c, str) else (c or [])):
            if text not in cites:
                cites.append(text)
    rep.bullets(cites)
    rep.write(footer=f"geardyn {dict(_versions()).get('geardyn', '')}.")
    write_results_netcdf(out / "results.nc", result, case)
    s["figures"] = sorted(p.name for p in rep.figures)
