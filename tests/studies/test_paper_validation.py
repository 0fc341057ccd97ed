"""Consistency checks and comparisons with the paper: tolerances that can fail, honest splits.

Fast tests on hand-made summaries; the end-to-end run is ``test_paper_run.py``.
"""

from __future__ import annotations

import ast
import copy
import math
import re
import tomllib
from pathlib import Path

import numpy as np
import pytest

from geardyn.config import paper_case
from geardyn.studies.paper_validation import (
    SHAPE_FACTOR,
    STD_FACTOR,
    absolute_row,
    consistency_checks,
    factor_row,
    paper_comparisons,
    validation_tables,
)
from geardyn.studies.paper_values import PAPER_TABLE2, PAPER_TABLE3, case_differences

SRC = Path(__file__).resolve().parents[2] / "src" / "geardyn"


# ------------------------------------------------------------------ tolerances
@pytest.mark.parametrize(("ratio", "ok"), [(1.0, True), (2.0, True), (0.5, True), (1.999, True),
                                           (2.01, False), (0.499, False), (0.1, False),
                                           (0.0, False), (-1.0, False), (math.nan, False),
                                           (math.inf, False)])
def test_factor_tolerance_is_symmetric_in_log_ratio(ratio, ok):
    """'Within a factor of 2' accepts paper/2 .. 2 paper, not 0 .. 2 paper (the old rule
    |x - p| <= p accepted 0 and 0.1 p)."""
    assert factor_row("q", 3.2e-5, 3.2e-5 * ratio, 2.0, source="s")["pass"] is ok


def test_absolute_tolerance_and_nan():
    assert absolute_row("q", 1.07, 1.085, 0.02, source="s")["pass"]
    assert not absolute_row("q", 1.07, 1.095, 0.02, source="s")["pass"]
    assert not absolute_row("q", 1.07, math.nan, 0.02, source="s")["pass"]


# ------------------------------------------------------------------ comparisons
def _tables(scale: dict[str, float] | None = None):
    t2 = copy.deepcopy(PAPER_TABLE2)
    t3 = copy.deepcopy(PAPER_TABLE3)
    for stat, f in (scale or {}).items():
        for t in (t2, t3):
            for sig in t.values():
                for row in sig.values():
                    if stat in row:
                        row[stat] *= f
    return t2, t3


def test_the_papers_own_tables_pass_every_comparison():
    rows = paper_comparisons(*_tables())
    assert len(rows) == 42  # 7 statistics x 3 signals x 2 models
    assert all(r["pass"] for r in rows)
    assert {r["statistic"] for r in rows} == {"std", "kurtosis", "crest_factor",
                                              "envelope_kurtosis", "am_kurtosis", "pm_kurtosis",
                                              "residual_kurtosis"}


@pytest.mark.parametrize(("stat", "factor", "bad"), [
    ("std", 1.0 / STD_FACTOR * 0.98, True), ("std", STD_FACTOR * 1.02, True),
    ("std", 0.55, False), ("crest_factor", 0.55, True),  # the crest factors 3.4-4.9 vs 6-7.5
    ("pm_kurtosis", 2.0, True), ("envelope_kurtosis", 1.0 / SHAPE_FACTOR * 1.01, False),
])
def test_comparisons_fail_outside_their_tolerance(stat, factor, bad):
    rows = paper_comparisons(*_tables({stat: factor}))
    mine = [r for r in rows if r["statistic"] == stat]
    others = [r for r in rows if r["statistic"] != stat]
    assert len(mine) == 6 and all(r["pass"] for r in others)
    assert all(r["pass"] is (not bad) for r in mine)


# ------------------------------------------------------------------ consistency checks
def _summary() -> dict:
    t2, t3 = _tables()
    return {
        "design": {"centre_distance_mm": 138.0, "contact_ratio": 1.5916,
                   "base_radius_sum_mm": 129.6776},
        "static": {"centre_distance_change_mm": 1.0852, "pressure_angle_deg": 21.1941,
                   "contact_ratio": 1.4175, "contact_ratio_eq8": 1.4286},
        "simulations": {"model_II_cracked": {
            "mean_centre_distance_change_m": 1.0851e-3, "mean_pressure_angle_deg": 21.1941,
            "mean_pinion_speed_rad_s": 114.1401, "mean_transmission_error_rad": 0.0478}},
        "calibrated_speed_rad_s": 114.14, "crack_angle_deg": 182.7,
        "crack_angle_in_stiffness_deg": 178.0, "crack_angle_resolution_deg": 360 / 23,
        "table2": t2, "table3": t3}


def test_checks_are_not_validation_and_the_split_follows_the_case():
    s = _summary()
    paper = validation_tables(s, paper_case=True)
    assert paper["validation"] is paper["comparisons"] and len(paper["comparisons"]) == 42
    names = " ".join(r["quantity"] for r in paper["checks"])
    for q in ("design centre distance", "static centre distance change", "mean pinion speed",
              "crack seen in the TSA at"):
        assert q in names
    assert not any(q in " ".join(r["quantity"] for r in paper["comparisons"])
                   for q in ("centre distance", "pinion speed", "crack"))
    own = validation_tables(s, paper_case=False)
    assert own["comparisons"] == [] and own["validation"] == []
    own_names = " ".join(r["quantity"] for r in own["checks"])
    assert "design centre distance" not in own_names and "at [deg]" not in own_names
    assert "record mean centre distance change" in own_names  # still checked, any case
    assert all(r["pass"] for r in paper["checks"] + own["checks"])


def test_checks_can_fail():
    s = _summary()
    s["simulations"]["model_II_cracked"]["mean_centre_distance_change_m"] = 1.2e-3
    s["simulations"]["model_II_cracked"]["mean_pinion_speed_rad_s"] = 114.2
    s["crack_angle_deg"] = 210.0
    bad = {r["quantity"] for r in consistency_checks(s, paper_case=True) if not r["pass"]}
    assert any("record mean centre distance" in q for q in bad)
    assert any("pinion speed" in q for q in bad)
    assert any("offset from where the cracked map" in q for q in bad)


def _offset_rows(rows: list) -> dict:
    return {r["quantity"].split(":")[0]: r for r in rows if "offset from where" in r["quantity"]}


def test_another_pinion_fault_is_located_in_the_tsa_too():
    """A spall or breakage on the pinion (no crack): the envelope's peak is checked against the
    fault's event angle (where its map falls furthest below the healthy one) within the
    envelope's resolution; not for a fault that recurs once per gear revolution, nor where the
    maps did not locate the fault; a crack keeps its own row. Values: the spall example of
    2026-11-27 (``--quick --stiffness pem``: 170.5 deg in the TSA, 169.3 deg in the maps)."""
    s = _summary()
    del s["crack_angle_in_stiffness_deg"]
    s.update(crack_angle_deg=170.5, fault_event_angle_deg=169.3, fault_event_period_deg=360.0)
    rows = _offset_rows(consistency_checks(s, paper_case=False))
    assert set(rows) == {"fault seen in the TSA"} and rows["fault seen in the TSA"]["pass"]
    assert rows["fault seen in the TSA"]["geardyn"] == pytest.approx(1.2)
    s["crack_angle_deg"] = 169.3 + 360 / 23 + 0.1  # beyond the resolution
    assert not _offset_rows(consistency_checks(s, paper_case=False))["fault seen in the TSA"][
        "pass"]
    s["crack_angle_deg"] = 359.0  # across 0 deg: -10.3 deg, within
    s["fault_event_angle_deg"] = 9.3
    row = _offset_rows(consistency_checks(s, paper_case=False))["fault seen in the TSA"]
    assert row["pass"] and row["geardyn"] == pytest.approx(-10.3)
    s["fault_event_period_deg"] = 446.4  # a gear tooth: once per gear revolution
    assert _offset_rows(consistency_checks(s, paper_case=False)) == {}
    s["fault_event_period_deg"] = 360.0
    del s["fault_event_angle_deg"]  # not located by the maps
    assert _offset_rows(consistency_checks(s, paper_case=False)) == {}
    crack = _summary()
    crack.update(fault_event_angle_deg=100.0, fault_event_period_deg=360.0)
    assert set(_offset_rows(consistency_checks(crack, paper_case=False))) == {
        "crack seen in the TSA"}


# ------------------------------------------------------------------ paper case or not
def test_case_differences_separate_inputs_from_numerical_settings():
    assert case_differences(paper_case()) == ([], [])
    inputs, numerical = case_differences(paper_case(["pinion.teeth=25",
                                                     "simulation.record_time=0.2 s"]))
    assert inputs == [{"key": "pinion.teeth", "paper": 23, "case": 25}]
    assert [d["key"] for d in numerical] == ["simulation.record_time"]
    inputs, numerical = case_differences(paper_case(["stiffness.method=pem"]))
    assert inputs == [] and [d["key"] for d in numerical] == ["stiffness.method"]


def test_healthy_baseline_periodicity():
    """A map whose mesh cycles are all alike has a theoretically zero residual baseline; one
    tooth different (e.g. a pitch error) makes the baseline physical."""
    from geardyn.stiffness.map import StiffnessMap
    from geardyn.studies.paper import healthy_baseline_is_periodic

    nc, ns = 23, 4
    cycle = np.array([3e8, 3.2e8, 3.3e8, 3.1e8, 1.8e8, 1.9e8, 1.9e8, 1.8e8])
    k = np.tile(cycle, (2, nc))
    base = {"dd": np.array([0.0, 1e-3]), "phase_a": np.zeros(2), "length_a": np.full(2, 0.1),
            "mesh_angle": 2 * math.pi / nc, "n_cycles": nc, "n_seg": ns, "base_radius": 0.065}
    assert healthy_baseline_is_periodic(StiffnessMap(k_mb=k, **base))
    k2 = k.copy()
    k2[:, 5 * 2 * ns + 1] *= 1.01
    assert not healthy_baseline_is_periodic(StiffnessMap(k_mb=k2, **base))


# ------------------------------------------------------------------ architecture
def _imports(path: Path) -> list[tuple[int, str, list[str]]]:
    tree = ast.parse(path.read_text())
    return [(n.level, n.module or "", [a.name for a in n.names])
            for n in ast.walk(tree) if isinstance(n, ast.ImportFrom)]


def test_report_never_imports_the_study():
    """One way only: studies/paper.py runs the report stage; the report, the results, the
    published values, the validation and the figures never import studies/paper.py."""
    for name in ("paper_report", "paper_result", "paper_values", "paper_validation",
                 "paper_figures", "report"):
        for level, module, names in _imports(SRC / "studies" / f"{name}.py"):
            assert not (level == 1 and module == "paper"), name
            assert not (level == 1 and module == "" and "paper" in names), name
            assert module != "geardyn.studies.paper", name


def test_inner_modules_take_the_version_from_the_ground_floor():
    offenders = []
    for path in SRC.rglob("*.py"):
        if path == SRC / "__init__.py":
            continue
        for level, module, names in _imports(path):
            if "__version__" in names and module in ("", "geardyn") and (level >= 1 or
                                                                          module == "geardyn"):
                offenders.append(str(path.relative_to(SRC)))
    assert offenders == []


def test_version_matches_pyproject():
    from geardyn import __version__
    from geardyn._version import __version__ as ground

    meta = tomllib.loads((SRC.parents[1] / "pyproject.toml").read_text())
    assert __version__ == ground == meta["project"]["version"]


def test_report_and_case_cite_no_internal_design_notes():
    """Users don't have design/*.md (docs/ ships with the repository): the report's sources
    (the shipped case, the study's notes) must not cite them."""
    pattern = re.compile(r"design/\w+\.md|(?<![/\w])(dynamics|stiffness)\.md")
    for path in [SRC / "cases" / "xue_howard.toml", *sorted((SRC / "studies").glob("paper*.py"))]:
        assert not pattern.search(path.read_text()), path.name
