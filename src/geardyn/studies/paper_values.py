"""The values Xue & Howard (2018) publish, and how a case differs from theirs.

Data only (no computation on results): the study (:mod:`.paper`), the validation tables
(:mod:`.paper_validation`) and the report (:mod:`.paper_report`) all read from here, so none of
them needs to import another to find a published number.
"""

from __future__ import annotations

from typing import Any

__all__ = ["SIGNAL_KEYS", "SIGNAL_TITLES", "CONDITION_METRICS", "PAPER_TABLE2", "PAPER_TABLE3",
           "PAPER_PM_LEVEL_DEG", "PAPER_VALUES", "NUMERICAL_KEYS", "case_differences",
           "fault_word", "faulty_words", "FAULT_DIP"]

#: The paper's names of the three signals (summary.json keys) by geardyn variable.
SIGNAL_KEYS = {"v_yg": "gear_vertical_velocity", "omega_p": "pinion_angular_velocity",
               "transmission_error": "transmission_error"}

#: Human titles (with units) of the three signals, by summary.json key.
SIGNAL_TITLES = {"gear_vertical_velocity": "output gear vertical velocity [m/s]",
                 "pinion_angular_velocity": "input pinion angular velocity [rad/s]",
                 "transmission_error": "transmission error theta_p - (r_b2/r_b1) theta_g [rad]"}

#: Condition metrics compared healthy against cracked (MATLAB gearConditionMetrics names).
CONDITION_METRICS = ("FM0", "FM4", "M6A", "M8A", "NA4", "NA4star", "EnergyRatio", "Kurtosis")

#: Table 2 of the paper: statistics of the TSA, by signal and model.
PAPER_TABLE2 = {
    "gear_vertical_velocity": {
        "I": {"mean": 0.0, "std": 0.0100, "skewness": -0.07, "kurtosis": 4.56, "crest_factor": 7.39},
        "II": {"mean": 0.0, "std": 0.0127, "skewness": 0.11, "kurtosis": 4.22, "crest_factor": 7.51}},
    "pinion_angular_velocity": {
        "I": {"mean": 114.14, "std": 0.1389, "skewness": 0.04, "kurtosis": 3.21,
              "crest_factor": 5.99},
        "II": {"mean": 114.14, "std": 0.1815, "skewness": -0.13, "kurtosis": 3.11,
               "crest_factor": 6.88}},
    "transmission_error": {
        "I": {"mean": 0.05, "std": 2.6e-5, "skewness": 0.31, "kurtosis": 4.83, "crest_factor": 7.02},
        "II": {"mean": 0.05, "std": 3.2e-5, "skewness": 0.15, "kurtosis": 4.51,
               "crest_factor": 7.04}},
}

#: Table 3 of the paper (kurtoses of envelope, AM and PM) and the residual kurtoses of its text
#: (section 4.2, Fig. 13), by signal and model.
PAPER_TABLE3 = {
    "gear_vertical_velocity": {
        "I": {"envelope_kurtosis": 14.65, "am_kurtosis": 14.25, "pm_kurtosis": 7.98,
              "residual_kurtosis": 62.29},
        "II": {"envelope_kurtosis": 14.28, "am_kurtosis": 12.79, "pm_kurtosis": 6.30,
               "residual_kurtosis": 52.47}},
    "pinion_angular_velocity": {
        "I": {"envelope_kurtosis": 14.73, "am_kurtosis": 14.25, "pm_kurtosis": 7.74,
              "residual_kurtosis": 47.60},
        "II": {"envelope_kurtosis": 14.21, "am_kurtosis": 12.71, "pm_kurtosis": 6.27,
               "residual_kurtosis": 41.43}},
    "transmission_error": {
        "I": {"envelope_kurtosis": 14.84, "am_kurtosis": 14.23, "pm_kurtosis": 8.50,
              "residual_kurtosis": 5.71},
        "II": {"envelope_kurtosis": 13.07, "am_kurtosis": 12.95, "pm_kurtosis": 6.37,
               "residual_kurtosis": 6.04}},
}

#: Phase-modulation levels the paper reads off Figs. 16, 19, 22 [deg].
PAPER_PM_LEVEL_DEG = {"gear_vertical_velocity": {"I": 40.0, "II": -130.0},
                      "pinion_angular_velocity": {"I": -110.0, "II": 80.0},
                      "transmission_error": {"I": 160.0, "II": -10.0}}

#: Values the paper reports, used in the consistency checks (quantity -> (value, where)).
PAPER_VALUES = {
    "design_centre_distance_mm": (138.0, "Table 1"),
    "design_contact_ratio": (1.59, "Table 1"),
    "base_radius_sum_mm": (129.7, "Table 1 ('base radius', erratum 1: the sum of both)"),
    "centre_distance_change_mm": (1.07, "section 4.1, Fig. 8a ('around 1.07 mm')"),
    "operating_pressure_angle_deg": (21.18, "section 4.1, Fig. 8b"),
    "contact_ratio_paper_eq8": (1.43, "section 4.1, Fig. 8c (eq. 8)"),
    "mean_pinion_speed_rad_s": (114.14, "Table 2"),
    "mean_transmission_error_rad": (0.05, "Table 2"),
    "crack_angle_deg": (170.0, "section 4.2, Figs. 11-22 ('around 170 deg')"),
}

#: Case keys that set how finely geardyn computes, not what is computed: a case that differs from
#: the paper's only in these (or in the stiffness method) is still the paper's case.
NUMERICAL_KEYS = frozenset({
    "stiffness.method", "stiffness.centre_distance_min", "stiffness.centre_distance_max",
    "stiffness.centre_distances", "stiffness.nodes_per_segment", "stiffness.fe.refinement",
    "stiffness.fe.teeth_in_model", "simulation.dt", "simulation.settle_time",
    "simulation.record_time", "simulation.decimation", "simulation.rtol",
    "simulation.max_iterations", "simulation.integrator", "simulation.hht_alpha",
    "diagnostics.samples_per_rev",
})


def _flatten(node: Any, prefix: str, out: dict[str, Any]) -> dict[str, Any]:
    if isinstance(node, dict):
        for k, v in node.items():
            _flatten(v, f"{prefix}.{k}" if prefix else k, out)
    else:
        out[prefix] = node
    return out


def _same(a: Any, b: Any) -> bool:
    if isinstance(a, float) and isinstance(b, float):
        return a == b or abs(a - b) <= 1e-12 * max(abs(a), abs(b))
    return a == b


def case_differences(case, reference=None) -> tuple[list[dict], list[dict]]:
    """Where ``case`` differs from the paper's case (or from ``reference``).

    Parameters
    ----------
    case : geardyn.config.Case
    reference : geardyn.config.Case, optional
        Default: :func:`geardyn.config.paper_case`.

    Returns
    -------
    inputs : list of dict
        ``{"key", "paper", "case"}`` for every physical input that differs (SI values): any
        of these makes the case the user's own, not the paper's.
    numerical : list of dict
        The same for the numerical settings of :data:`NUMERICAL_KEYS` (resolution, method).
    """
    from ..config import deep_copy_case_data, paper_case

    ref = reference if reference is not None else paper_case()
    a = _flatten(deep_copy_case_data(ref), "", {})
    b = _flatten(deep_copy_case_data(case), "", {})
    # the FE map's torque as used: omitted means the operating torque (stiffness.fe_torque)
    from ..stiffness import fe_torque

    for flat, c in ((a, ref), (b, case)):
        if "stiffness.fe.torque" in flat or "motor.torque" in flat:
            flat["stiffness.fe.torque"] = fe_torque(c)
    inputs, numerical = [], []
    for key in [*a, *(k for k in b if k not in a)]:
        if key in ("name", "description") or key.startswith("provenance"):
            continue
        pa, pb = a.get(key), b.get(key)
        if _same(pa, pb):
            continue
        row = {"key": key, "paper": pa, "case": pb}
        (numerical if key in NUMERICAL_KEYS else inputs).append(row)
    return inputs, numerical


#: Smallest relative stiffness loss [-] by which the faulty map locates a fault other than a
#: crack (Figs. 8-10 of ``geardyn run`` are centred on its events): below it the fault acts
#: mainly through the excitation (e.g. wear without its stiffness term, whose map equals the
#: healthy one), and the map's lowest point tells nothing of where the fault is.
FAULT_DIP = 1e-3


def fault_word(case) -> str:
    """What the narrowband envelope's peak locates: "crack", "fault", "faults" or "" (a healthy
    pair: the peak then locates nothing)."""
    n = len(getattr(case, "faults", None) or ())
    crack = case.crack is not None and case.crack.active
    if n == 0:
        return "crack" if crack else ""
    return "faults" if n + crack > 1 else "fault"


def fault_gears(case) -> set[str]:
    """The gears ("pinion", "gear") that carry the case's crack and faults."""
    gears = {str(getattr(f, "gear", "pinion") or "pinion") for f in
             (getattr(case, "faults", None) or ())}
    if case.crack is not None and case.crack.active:
        gears.add(str(case.crack.gear))
    return gears


def gear_fault_averaged_out(case) -> str:
    """Why the pinion's TSA cannot locate a fault on the gear, or "" where it can (no gear
    fault, or as many gear teeth as pinion teeth, so the gear's fault recurs once per pinion
    revolution). The TSA averages over pinion revolutions; a gear fault recurs every
    ``360 z2 / z1`` deg of pinion rotation, so it falls at another pinion angle each time."""
    z1, z2 = int(case.pinion.teeth), int(case.gear.teeth)
    if "gear" not in fault_gears(case) or z1 == z2:
        return ""
    return (f"the gear's fault recurs every {360.0 * z2 / z1:.4g} deg of pinion rotation "
            f"({z2} gear teeth to the pinion's {z1}), so the TSA over pinion revolutions "
            "averages it over the revolution instead of showing it at one angle; its "
            "indicators here are those of the pinion's average")


def faulty_words(case) -> tuple[str, str]:
    """``(adjective, noun)`` of the faulty state of the report: ("cracked", "crack") when the
    case's fault is its crack alone, else ("faulty", "fault"). summary.json, results.nc and the
    runs/ files keep the key "cracked" for that state whatever the fault."""
    return ("cracked", "crack") if fault_word(case) == "crack" else ("faulty", "fault")
