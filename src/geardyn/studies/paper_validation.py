"""Consistency checks and comparisons with the paper, computed from a study's summary.

Two kinds of rows, kept apart because only the second can tell whether geardyn's stiffness and
dynamics reproduce Xue & Howard (2018):

*consistency checks*
    Quantities fixed by the inputs, the geometry, the static balance or a calibration: the
    design centre distance and contact ratio (Table 1's inputs give them), the static centre
    distance change, pressure angle and contact ratio (torque balance on the bearings, eq. 4),
    the record means (the mean bearing force balances the input torque whatever the mesh
    stiffness), the mean pinion speed (the output load law is calibrated to it) and where the
    crack shows (geardyn chose the cracked tooth). They catch broken plumbing, not wrong
    physics, and are **not counted as validation**.
*comparisons with the paper*
    Statistics of the simulated, synchronously averaged signals (Tables 2 and 3), which depend
    on the mesh stiffness and the dynamics. The paper states no uncertainty, so the tolerances
    are geardyn's, fixed before comparing and symmetric in the log-ratio (a factor ``f`` accepts
    ``paper / f`` to ``paper * f``): the paper does not give its damping values, and a standard
    deviation scales with the response amplitude, so STD is compared within a factor of 2;
    kurtoses and crest factors describe the waveform's shape, not its size, and are compared
    within a factor of 1.25.

Every row is a dict with ``quantity``, ``reference`` (the value compared with), ``source``,
``geardyn``, ``tolerance`` (a number), ``tolerance_kind`` (``"absolute"`` or ``"factor"``),
``tolerance_text``, ``pass`` and ``note``; comparison rows also carry ``paper`` (= reference),
``table``, ``signal``, ``model`` and ``statistic``.
"""

from __future__ import annotations

import math

from .paper_values import PAPER_TABLE2, PAPER_TABLE3, PAPER_VALUES

__all__ = ["absolute_row", "factor_row", "consistency_checks", "paper_comparisons",
           "validation_tables", "STD_FACTOR", "SHAPE_FACTOR", "COMPARED"]

#: Tolerance factor of the Table 2 standard deviations (either way).
STD_FACTOR = 2.0
#: Tolerance factor of the shape statistics: kurtoses and crest factors (either way).
SHAPE_FACTOR = 1.25

#: What is compared: (table, statistic, label, factor).
COMPARED = (
    ("Table 2", "std", "STD", STD_FACTOR),
    ("Table 2", "kurtosis", "kurtosis", SHAPE_FACTOR),
    ("Table 2", "crest_factor", "crest factor", SHAPE_FACTOR),
    ("Table 3", "envelope_kurtosis", "envelope kurtosis", SHAPE_FACTOR),
    ("Table 3", "am_kurtosis", "AM kurtosis", SHAPE_FACTOR),
    ("Table 3", "pm_kurtosis", "PM kurtosis", SHAPE_FACTOR),
    ("Table 3", "residual_kurtosis", "residual kurtosis (text of Fig. 13)", SHAPE_FACTOR),
)


def _finite(x) -> bool:
    return isinstance(x, (int, float)) and not isinstance(x, bool) and math.isfinite(x)


def absolute_row(quantity: str, reference: float, value: float, tolerance: float, *,
                 source: str, note: str = "", unit: str = "") -> dict:
    """A row that passes when ``|value - reference| <= tolerance``."""
    ok = _finite(value) and _finite(reference) and abs(value - reference) <= tolerance
    return {"quantity": quantity, "reference": reference, "source": source, "geardyn": value,
            "tolerance": tolerance, "tolerance_kind": "absolute",
            "tolerance_text": f"+/- {tolerance:.3g}{(' ' + unit) if unit else ''}",
            "pass": bool(ok), "note": note}


def factor_row(quantity: str, reference: float, value: float, factor: float, *, source: str,
               note: str = "") -> dict:
    """A row that passes when ``|ln(value / reference)| <= ln(factor)``: within a factor either
    way (a zero, negative or non-finite value fails)."""
    ok = (_finite(value) and _finite(reference) and value > 0 and reference > 0
          and abs(math.log(value / reference)) <= math.log(factor) * (1 + 1e-12))
    return {"quantity": quantity, "reference": reference, "source": source, "geardyn": value,
            "tolerance": factor, "tolerance_kind": "factor",
            "tolerance_text": f"factor {factor:g} either way ({reference / factor:.3g} to "
                              f"{reference * factor:.3g})",
            "pass": bool(ok), "note": note}


def consistency_checks(s: dict, *, paper_case: bool) -> list[dict]:
    """The consistency checks of a study summary (see the module docstring).

    Parameters
    ----------
    s : dict
        The study summary (``summary.json``): ``design``, ``static``, ``simulations``,
        ``calibrated_speed_rad_s``, ``crack_angle_deg``, ``crack_angle_in_stiffness_deg``,
        ``crack_angle_resolution_deg``, ``fault_event_angle_deg``, ``fault_event_period_deg``
        are used where present.
    paper_case : bool
        Whether the inputs are the paper's: only then are Table 1 and the paper's static values
        checked.
    """
    rows: list[dict] = []
    pv = PAPER_VALUES
    design, static = s.get("design", {}), s.get("static", {})
    if paper_case and design:
        rows += [
            absolute_row("design centre distance [mm]", pv["design_centre_distance_mm"][0],
                         design["centre_distance_mm"], 1e-6, unit="mm",
                         source=f"paper, {pv['design_centre_distance_mm'][1]}",
                         note="fixed by Table 1's module and tooth numbers"),
            absolute_row("design contact ratio", pv["design_contact_ratio"][0],
                         design["contact_ratio"], 0.005, source="paper, Table 1",
                         note="geometry of Table 1's inputs; the paper quotes 2 decimals"),
            absolute_row("base radius sum [mm]", pv["base_radius_sum_mm"][0],
                         design["base_radius_sum_mm"], 0.05, unit="mm",
                         source=f"paper, {pv['base_radius_sum_mm'][1]}",
                         note="geometry of Table 1's inputs (erratum 1)"),
        ]
    if paper_case and static:
        rows += [
            absolute_row("static centre distance change [mm]", pv["centre_distance_change_mm"][0],
                         static["centre_distance_change_mm"], 0.02, unit="mm",
                         source=f"paper, {pv['centre_distance_change_mm'][1]}",
                         note="static torque balance on the bearings (eq. 4), rigid teeth; "
                              "zero absolute torsional damping (the paper gives no value; "
                              "0.012 N m s/rad gives 1.070 mm)"),
            absolute_row("static operating pressure angle [deg]",
                         pv["operating_pressure_angle_deg"][0], static["pressure_angle_deg"],
                         0.02, unit="deg", source=f"paper, {pv['operating_pressure_angle_deg'][1]}",
                         note="follows from the static centre distance"),
            absolute_row("static contact ratio, paper eq. 8", pv["contact_ratio_paper_eq8"][0],
                         static["contact_ratio_eq8"], 0.005,
                         source=f"paper, {pv['contact_ratio_paper_eq8'][1]}",
                         note=f"follows from the static centre distance; physical value "
                              f"{static.get('contact_ratio', float('nan')):.4f} (erratum 2)"),
        ]
    sim = s.get("simulations", {}).get("model_II_cracked", {})
    if sim and static:
        rows += [
            absolute_row("model II record mean centre distance change [mm]",
                         static["centre_distance_change_mm"],
                         sim["mean_centre_distance_change_m"] * 1e3,
                         0.01 * abs(static["centre_distance_change_mm"]) + 1e-4, unit="mm",
                         source="geardyn's static balance (geometry stage)",
                         note="the mean bearing force balances the input torque whatever the "
                              "mesh stiffness: 1% of the static value"),
            absolute_row("model II record mean pressure angle [deg]",
                         static["pressure_angle_deg"], sim["mean_pressure_angle_deg"], 0.02,
                         unit="deg", source="geardyn's static balance (geometry stage)",
                         note="follows from the mean centre distance"),
        ]
    speed = s.get("calibrated_speed_rad_s")
    if sim and _finite(speed):
        rows.append(absolute_row(
            "model II mean pinion speed [rad/s]", speed, sim["mean_pinion_speed_rad_s"],
            1e-4 * speed, unit="rad/s",
            source="the case's load.speed" + (" (paper, Table 2)" if paper_case else ""),
            note="the output load law is calibrated to this speed: 0.01%"))
    if paper_case and sim:
        rows.append(absolute_row(
            "model II mean transmission error [rad]", pv["mean_transmission_error_rad"][0],
            sim["mean_transmission_error_rad"], 0.005, unit="rad", source="paper, Table 2",
            note="set by the bearing deflections of the static balance (the mesh deflection is "
                 "about 1% of it); Table 2 quotes one significant figure"))
    ca, cs = s.get("crack_angle_deg"), s.get("crack_angle_in_stiffness_deg")
    res = s.get("crack_angle_resolution_deg", 360.0 / 23)
    how = ("the narrowband envelope's peak (median over the signals and models) against the "
           "pinion angle of the largest stiffness loss; tolerance: the envelope's angular "
           "resolution, 360 deg / (2 B + 1) for a band of +/- B orders")
    if _finite(ca) and _finite(cs):
        d = (ca - cs + 180.0) % 360.0 - 180.0
        rows.append(absolute_row(
            "crack seen in the TSA: offset from where the cracked map is weakest [deg]", 0.0, d,
            res, unit="deg", source="geardyn's stiffness maps (stiffness stage)", note=how))
    fe, period = s.get("fault_event_angle_deg"), s.get("fault_event_period_deg")
    if (_finite(ca) and not _finite(cs) and _finite(fe) and _finite(period)
            and abs(period - 360.0) < 1e-9):
        # another fault on the pinion (a spall, a breakage...): the TSA's revolution is the
        # pinion's, so it shows the fault once, where the faulty map falls furthest below the
        # healthy one (at 0 mm: the fault events of Figs. 8-10); a gear-side fault recurs once
        # per gear revolution and is not located by the pinion's TSA
        d = (ca - fe + 180.0) % 360.0 - 180.0
        rows.append(absolute_row(
            "fault seen in the TSA: offset from where the faulty map is weakest [deg]", 0.0, d,
            res, unit="deg", source="geardyn's stiffness maps (stiffness stage, at 0 mm)",
            note=how))
    if paper_case and _finite(ca):
        rows.append(absolute_row(
            "crack seen in the TSA at [deg]", pv["crack_angle_deg"][0], ca, 360.0 / 23,
            unit="deg", source=f"paper, {pv['crack_angle_deg'][1]}",
            note="agreement by choice, not a test: the paper does not number its teeth and "
                 "geardyn cracks tooth 11, which passes the pitch point at 172.2 deg; "
                 "tolerance one tooth pitch"))
    return rows


#: Units of the signals of Tables 2 and 3 (their STD and mean have them).
_SIGNAL_UNITS = {"gear_vertical_velocity": "m/s", "pinion_angular_velocity": "rad/s",
                 "transmission_error": "rad"}


def paper_comparisons(table2: dict, table3: dict) -> list[dict]:
    """Comparisons of geardyn's Tables 2 and 3 (cracked pair) with the paper's.

    Parameters
    ----------
    table2, table3 : dict
        ``table[signal][model][statistic]`` as in ``summary.json`` (signals
        ``gear_vertical_velocity``, ``pinion_angular_velocity``, ``transmission_error``; models
        ``"I"``, ``"II"``).

    Returns
    -------
    list of dict
        One row per signal, model and statistic of :data:`COMPARED` found in both.
    """
    rows = []
    for table, stat, label, factor in COMPARED:
        ours_t, paper_t = (table2, PAPER_TABLE2) if table == "Table 2" else (table3, PAPER_TABLE3)
        for sig in paper_t:
            for m in ("I", "II"):
                try:
                    ours, paper = ours_t[sig][m][stat], paper_t[sig][m][stat]
                except (KeyError, TypeError):
                    continue
                why = ("damping values are not in the paper; STD scales with the response "
                       "amplitude" if stat == "std" else "a shape statistic: independent of the "
                       "amplitude")
                # an STD or a mean has the signal's unit; a shape statistic has none (the rows
                # read "Table 2 STD, ... | 0.01 | 0.00667" without one: a user audit)
                unit = _SIGNAL_UNITS.get(sig, "") if stat in ("std", "mean") else ""
                row = factor_row(f"{table} {label}, {sig.replace('_', ' ')}, model {m}"
                                 + (f" [{unit}]" if unit else ""), paper, ours, factor,
                                 source=f"paper, {table}", note=why)
                if unit:
                    row["unit"] = unit
                row.update({"paper": paper, "table": table, "signal": sig, "model": m,
                            "statistic": stat})
                rows.append(row)
    return rows


def validation_tables(s: dict, *, paper_case: bool) -> dict:
    """``{"checks": [...], "comparisons": [...], "validation": [...]}`` for a summary.

    ``validation`` is the list of comparisons with the paper (the rows that count); it is empty
    for a case whose inputs are not the paper's.
    """
    checks = consistency_checks(s, paper_case=paper_case)
    comps = paper_comparisons(s.get("table2", {}), s.get("table3", {})) if paper_case else []
    return {"checks": checks, "comparisons": comps, "validation": comps}
