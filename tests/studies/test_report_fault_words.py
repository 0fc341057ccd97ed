"""The report of a user's case names what it found by what the case holds: a crack, a fault,
faults, or nothing for a healthy pair; its title lists a faults list by type and place."""

from __future__ import annotations

from pathlib import Path

import geardyn
from geardyn.config import load_case
from geardyn.studies.paper_report import _fault_word, _own_case_title
from geardyn.studies.paper_values import case_differences

EXAMPLES = Path(__file__).resolve().parents[2] / "examples" / "faults"


def test_what_the_envelope_peak_locates():
    assert _fault_word(geardyn.paper_case()) == "crack"
    assert _fault_word(geardyn.paper_case({"crack.enabled": False})) == ""
    assert _fault_word(geardyn.paper_case({"crack.depth": 0.0})) == ""   # zero size: healthy
    assert _fault_word(load_case(EXAMPLES / "spall.toml")) == "fault"
    assert _fault_word(load_case(EXAMPLES / "two_faults.toml")) == "faults"


def test_title_lists_faults_by_type_and_place():
    case = load_case(EXAMPLES / "spall.toml")
    title, _ = _own_case_title(case, case_differences(case)[0])
    assert "faults = [spall on pinion tooth 11]" in title
    assert "None" not in title and "{" not in title


def test_the_differences_table_shows_the_fields_a_fault_sets():
    from geardyn.studies.paper_report import _set_fields

    faults = [{"type": "breakage", "gear": "pinion", "tooth": 11, "depth": None,
               "height": 0.002},
              {"type": "spall", "tooth": 3, "width": None, "length": 0.001}]
    assert _set_fields(faults) == ("type = breakage, gear = pinion, tooth = 11, height = 0.002; "
                                   "type = spall, tooth = 3, length = 0.001")
    assert _set_fields(True) is True and _set_fields(None) is None and _set_fields([]) == []
