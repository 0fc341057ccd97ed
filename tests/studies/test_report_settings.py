"""The report and summary.json state the settings a run used: ``--quick``'s shorter records and
coarser maps among the numerical differences and in the case table, a faults list, a count and
an unset value as readable text with units, each citation once."""

from __future__ import annotations

import html
import json
import re
from pathlib import Path
from types import SimpleNamespace

import pytest

import geardyn
from geardyn.config import load_case
from geardyn.studies import paper
from geardyn.studies.paper_report import (
    CITATIONS,
    _case_table_rows,
    _difference_text,
    case_sections,
    citations,
    used_case,
)
from geardyn.studies.report import Report

SPALL = Path(__file__).resolve().parents[2] / "examples" / "faults" / "spall.toml"

#: What a user reads as a Python leftover rather than a value.
LEFTOVERS = ("None", "[{", "{'", "'}", "100000000.0", "True", "False", "69000000000.0")


def _summary(tmp_path, case, *, quick: bool, stiffness: str | None = None) -> dict:
    """summary.json as :func:`~geardyn.studies.paper.run_paper_study` writes it before its first
    stage (the stages patched away: no map, no simulation)."""
    with pytest.MonkeyPatch.context() as mp:
        mp.setattr(paper, "STAGES", [])
        paper.run_paper_study(case, tmp_path, quick=quick, stiffness=stiffness)
    return json.loads((tmp_path / "summary.json").read_text())


def _text(rep: Report) -> str:
    """The report's body as a user reads it: tags dropped, cells separated by " | "."""
    body = rep.html().split("</style>", 1)[1]
    text = html.unescape(re.sub(r"<[^>]+>", " | ", body))
    return re.sub(r"(\s*\|\s*)+", " | ", text)


def test_quick_settings_are_numerical_differences_of_the_paper_case(tmp_path):
    s = _summary(tmp_path / "q", geardyn.paper_case(), quick=True)
    assert s["paper_case"] is True and s["differences_from_paper"] == []  # physics unchanged
    rows = {d["key"]: d for d in s["numerical_differences"]}
    assert rows["simulation.record_time"] == {"key": "simulation.record_time", "paper": 1.0,
                                              "case": 0.3, "without_quick": 1.0}
    assert rows["simulation.settle_time"]["case"] == 0.1
    assert rows["stiffness.centre_distances"]["case"] == paper.QUICK_CENTRE_DISTANCES == 11
    assert rows["stiffness.fe.refinement"]["case"] == paper.QUICK_REFINEMENT == 0.5
    assert {d["key"]: d["used"] for d in s["quick_settings"]} == {
        "simulation.record_time": 0.3, "simulation.settle_time": 0.1,
        "stiffness.centre_distances": 11, "stiffness.fe.refinement": 0.5}
    # case.toml stays the user's case
    written = load_case(tmp_path / "q" / "case.toml")
    assert written.simulation.record_time == 1.0 and written.stiffness.centre_distances == 31
    # without --quick: nothing
    full = _summary(tmp_path / "f", geardyn.paper_case(), quick=False)
    assert full["numerical_differences"] == [] and full["quick_settings"] == []


def test_quick_settings_of_a_pem_fault_case(tmp_path):
    s = _summary(tmp_path, load_case(SPALL), quick=True, stiffness="pem")
    assert s["paper_case"] is False
    assert [d["key"] for d in s["differences_from_paper"]] == ["crack.enabled", "faults"]
    keys = [d["key"] for d in s["numerical_differences"]]
    # the FE refinement is not coarsened for the PEM (it is not used)
    assert set(keys) == {"stiffness.method", "stiffness.centre_distances",
                         "simulation.settle_time", "simulation.record_time"}


def test_the_case_table_shows_the_quick_values_used(tmp_path):
    case = geardyn.paper_case()
    s = _summary(tmp_path, case, quick=True)
    rows = {k: v for k, v, _ in _case_table_rows(case, [], used=used_case(case, s))}
    assert rows["simulation.record_time"] == "1 s; used with --quick: 0.3 s"
    assert rows["simulation.settle_time"] == "0.5 s; used with --quick: 0.1 s"
    assert rows["stiffness.centre_distances"] == "31; used with --quick: 11"
    assert rows["stiffness.fe.refinement"] == "1; used with --quick: 0.5"
    assert rows["simulation.dt"] == "1e-05 s"  # not changed: as it is
    rep = Report("t", tmp_path)
    case_sections(rep, case, s)
    text = _text(rep)
    assert ("simulation.record_time | 1 s | 0.3 s (--quick; the case: 1 s)" in text)
    assert ("--quick shortened the records and coarsened the stiffness maps: "
            "stiffness.centre_distances = 11 (the case: 31), stiffness.fe.refinement = 0.5 (the "
            "case: 1), simulation.settle_time = 0.1 s (the case: 0.5 s), "
            "simulation.record_time = 0.3 s (the case: 1 s).") in text


def test_a_fault_case_reads_without_python_leftovers(tmp_path):
    case = load_case(SPALL).with_overrides({"stiffness.method": "pem"})
    s = _summary(tmp_path, load_case(SPALL), quick=True, stiffness="pem")
    rows = {k: v for k, v, _ in _case_table_rows(case, ["crack.enabled", "faults"])}
    assert rows["faults"] == ("type = spall, gear = pinion, tooth = 11, depth = 0.0001 m, "
                              "width = 0.006 m, start = 0.02 m, length = 0.003 m")
    assert rows["simulation.max_steps"] == "100,000,000 steps"
    # the paper's case has no faults list: its only fault is the [crack] section's
    paper_faults = _difference_text("faults", None, geardyn.paper_case())
    assert paper_faults == "none besides the [crack] section's 5 mm root crack on pinion tooth 11"
    assert _difference_text("faults", None, geardyn.paper_case({"crack.enabled": False})) == "none"
    rep = Report("t", tmp_path)
    case_sections(rep, case, s)
    text = _text(rep)
    assert f"faults | {paper_faults} | type = spall, gear = pinion, tooth = 11" in text
    assert "crack.enabled | true | false" in text
    assert "simulation.max_steps | 100,000,000 steps" in text
    assert "simulation.record_time | 1 s; used with --quick: 0.3 s" in text
    for leftover in LEFTOVERS:
        assert leftover not in text, leftover


def test_fault_values_are_rounded_to_their_significant_digits():
    rows = {k: v for k, v, _ in _case_table_rows(load_case(SPALL.parent / "wear.toml"), [])}
    assert "depth = 3e-05 m" in rows["faults"] and "999999" not in rows["faults"]


def test_each_work_is_cited_once_in_its_full_form():
    from geardyn.stiffness.pem.mesh_map import CITATIONS as PEM
    from geardyn.stiffness.pem.mesh_map import FAULT_CITATIONS

    maps = [SimpleNamespace(attrs={"citations": list(PEM)}),
            SimpleNamespace(attrs={"citations": json.dumps([*PEM, *FAULT_CITATIONS])})]
    cites = citations(maps)
    for author in ("Yang", "Tian", "Sainsot", "Ma", "Chen", "Mohammed"):
        hits = [c for c in cites if c.startswith(f"{author},") or c.startswith(f"{author} ")]
        assert len(hits) == 1, hits
        assert hits[0] in CITATIONS  # the full form
    # works the report's list does not hold are kept, once
    assert sum(c.startswith("PHM-BGU") for c in cites) == 1
    assert sum(c.startswith("Chaari, Baccar") for c in cites) == 1  # 2008, not the 2012 one
    assert len(cites) == len(set(cites)) == len(CITATIONS) + 2


def test_the_case_table_gives_every_number_its_unit_and_angles_in_degrees_too():
    """A user audit (2026-11-27): the case table read "0.3490658503988659 rad", "True",
    "69000000000.0 Pa" and "[3000.0]" (no unit). Units come from the field's dimension or, for
    plain numbers, from the unit its description states; case.toml keeps every digit."""
    rows = {k: v for k, v, _ in _case_table_rows(geardyn.paper_case(), [])}
    assert rows["pair.pressure_angle"] == "0.3490658504 rad (20 deg)"
    assert rows["crack.angle"] == "0.7853981634 rad (45 deg)"
    assert rows["motor.ripple_phase"] == "0 rad"  # no "(0 deg)" for a zero
    assert rows["material.youngs_modulus"] == "6.9e+10 Pa"
    assert rows["pinion.bearing_stiffness"] == "1000000 N/m"
    assert rows["crack.enabled"] == "true" and rows["stiffness.body_torsion"] == "false"
    assert rows["measurement.mode_frequencies"] == "[3000] Hz"
    assert rows["measurement.mode_gains"] == "[[0.05, 0.1]] (m/s^2)/N"
    assert rows["measurement.mode_damping_ratios"] == "[0.05]"  # [-]: dimensionless
    assert rows["measurement.snr"] == "20 dB"
    assert rows["diagnostics.bandwidth"] == "11 orders"
    assert rows["pinion.teeth"] == "23" and rows["pair.addendum_coefficient"] == "1"
    assert rows["stiffness.centre_distances"] == "31"  # not the bracketed key names
