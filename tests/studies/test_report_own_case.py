"""The report of a case that is not the paper's says what is true of that case: notes carried
over from the shipped case are marked as its, switched-off sections as not used, the faulty
state named by its fault, undefined and not-computed values by one word each."""

from __future__ import annotations

from pathlib import Path

import geardyn
from geardyn.config import load_case
from geardyn.studies.paper_report import (
    _case_table_rows,
    _condition_metrics_section,
    _faulty_words,
    model_comparison_statements,
)
from geardyn.studies.paper_values import CONDITION_METRICS, SIGNAL_KEYS, SIGNAL_TITLES
from geardyn.studies.report import Report

SPALL = Path(__file__).resolve().parents[2] / "examples" / "faults" / "spall.toml"


def _rows(case, changed):
    return {k: (v, s) for k, v, s in _case_table_rows(case, changed)}


def test_shipped_notes_are_marked_where_the_case_changed_what_they_describe():
    ref = geardyn.paper_case()
    shipped = _rows(ref, [])
    assert "172.2 deg" in shipped["crack.tooth"][1]
    assert not any("note of the shipped case" in s for _, s in shipped.values())
    case = geardyn.paper_case({"pinion.teeth": 25, "gear.teeth": 31})
    rows = _rows(case, ["pinion.teeth", "gear.teeth"])
    # the shipped case's own tooth counts, read from it, are named in the mark
    was = f"pinion.teeth = {ref.pinion.teeth}, gear.teeth = {ref.gear.teeth}"
    assert rows["crack.tooth"][1].endswith(
        f"[note of the shipped case, for its {was}: not about this case]")
    # a citation that does not depend on the teeth stays as it is
    assert rows["pair.module"][1] == shipped["pair.module"][1]
    assert rows["pinion.teeth"][0] == "25"


def test_notes_quoting_the_papers_operating_point_are_marked_for_another_load():
    """"0.012 N m s/rad reproduces the paper's 1.07 mm" stood unmarked in the report of a case
    whose torque and bearings give 0.35 mm (a user audit, 2026-11-27)."""
    case = geardyn.paper_case({"motor.torque": "60 N m"})
    rows = _rows(case, ["motor.torque"])
    for key in ("pinion.torsional_damping", "stiffness.centre_distance_min"):
        assert "1.07 mm" in rows[key][1]
        assert rows[key][1].endswith("[note of the shipped case, for its motor.torque = 100.0: "
                                     "not about this case]"), rows[key][1]


def test_a_switched_off_section_is_shown_as_not_used():
    case = load_case(SPALL)
    assert case.crack.enabled is False
    rows = _rows(case, ["crack.enabled", "faults", "stiffness.method"])
    for key in ("crack.gear", "crack.tooth", "crack.depth", "crack.angle", "crack.limit_line"):
        assert rows[key][1].startswith("not used (crack.enabled = false)"), key
    assert rows["crack.enabled"][0] == "false"  # as TOML writes it
    assert not rows["faults"][1].startswith("not used")


def test_the_faulty_state_is_named_by_the_fault(tmp_path):
    assert _faulty_words(geardyn.paper_case()) == ("cracked", "crack")
    spall = load_case(SPALL)
    words = _faulty_words(spall)
    assert words == ("faulty", "fault")
    one = {"healthy": dict.fromkeys(CONDITION_METRICS, 1.0),
           "cracked": dict.fromkeys(CONDITION_METRICS, 2.0)}
    cm = {name: {"I": one, "II": one} for name in SIGNAL_KEYS.values()}
    rep = Report("t", tmp_path)
    _condition_metrics_section(rep, cm, {}, words)
    html = rep.html()
    assert "Fault detection: condition metrics, healthy against faulty" in html
    assert "crack" not in html.lower()
    mc = {"cracked": {"static_centre_distance_change_mm": 1.0, "signals": {
        "v_yg": {"rms_ii_minus_i_static": 0.01, "rms_ii_minus_i": 1.0,
                 "explained_fraction": 0.99, "top_share": 0.2}}}}
    said = model_comparison_statements(mc, "fe", "faulty")
    assert said[0].startswith("Faulty pair: ")


def test_transmission_error_is_labelled_with_the_base_radius_ratio():
    # the simulation records' own definition (geardyn.dynamics), true for unequal gears
    assert SIGNAL_TITLES["transmission_error"] == ("transmission error theta_p - (r_b2/r_b1) "
                                                   "theta_g [rad]")
