"""``geardyn run``'s stiffness stage draws the Fig. 6 analogue (healthy against faulty mesh
stiffness) for any fault, not only a crack: a spall case's report shows where its map falls
below the healthy one. The curves are evaluated here and drawn from plain arrays
(:mod:`geardyn.line_figure`), the PNG equal to :func:`geardyn.stiffness.plots.fig_crack`'s."""

from __future__ import annotations

import warnings
from pathlib import Path

import numpy as np

from geardyn.config import load_case

EXAMPLES = Path(__file__).resolve().parents[2] / "examples" / "faults"


def _stage(case, tmp_path):
    from geardyn.studies.paper import stiffness_stage
    from geardyn.studies.paper_result import StudyResult

    result = StudyResult(out=tmp_path)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        stiffness_stage(case, tmp_path, result)
    return result


def test_a_spall_case_gets_the_healthy_against_faulty_figure(tmp_path):
    from geardyn.stiffness.plots import crack_angle, crack_curves, fig_crack
    from geardyn.studies.paper_result import render_png

    case = load_case(EXAMPLES / "spall.toml").with_overrides(
        {"stiffness.method": "pem", "stiffness.centre_distances": 5})
    assert case.crack is None or not case.crack.active
    result = _stage(case, tmp_path)
    assert "fig6_crack" in result.figures
    healthy, faulty = result.maps["healthy"], result.maps["cracked"]
    # the figure is fig_crack of the two maps, with the legend's word for a non-crack fault
    expected = render_png(fig_crack(healthy, faulty, faulty="faulty"))
    assert result.figures["fig6_crack"].png == expected
    spec = crack_curves(healthy, faulty, faulty="faulty")
    assert [line["label"].split(" (")[1].split(",")[0] for line in spec["lines"]] == \
        ["healthy", "faulty", "faulty"]
    # centred on the spall: the faulty map is lower there than the healthy one
    th = crack_angle(healthy, faulty, 0.0)
    assert faulty(th, 0.0) < healthy(th, 0.0) * (1 - 1e-3)
    mid = spec["x"][spec["x"].size // 2]
    assert abs(mid - np.degrees(th)) < 2 * (spec["x"][1] - spec["x"][0])
    # no crack angle is claimed for a spall
    assert "crack_angle_in_stiffness_deg" not in result.summary


def test_a_healthy_case_gets_no_faulty_figure(tmp_path):
    import geardyn

    case = geardyn.paper_case().with_overrides(
        {"crack.enabled": False, "stiffness.method": "pem", "stiffness.centre_distances": 5})
    result = _stage(case, tmp_path)
    assert "fig5_stiffness" in result.figures and "fig6_crack" not in result.figures
