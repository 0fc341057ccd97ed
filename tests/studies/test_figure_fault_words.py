"""The study's figures name the faulty pair by its fault: a spall's report must not draw
"crack events" or a "cracked" pair (the QA walkthrough's finding, left open before)."""

from __future__ import annotations

import numpy as np
import xarray as xr

import geardyn
from geardyn.config import load_case
from geardyn.stiffness import build_map
from geardyn.stiffness.plots import fig_crack
from geardyn.studies import paper_figures as pf
from geardyn.studies.paper_values import faulty_words

from .test_report_own_case import SPALL


def _texts(fig) -> list[str]:
    out = []
    for ax in fig.axes:
        out.append(ax.get_title())
        legend = ax.get_legend()
        if legend is not None:
            out += [t.get_text() for t in legend.get_texts()]
    out += [t.get_text() for leg in fig.legends for t in leg.get_texts()]
    return out


def _record(n: int = 2000) -> xr.Dataset:
    t = np.arange(n) * 1e-4  # [s]
    theta = 50.0 * t  # [rad]
    zero = np.zeros(n)
    return xr.Dataset({"theta_p": ("time", theta), "centre_distance_change": ("time", zero),
                       "pressure_angle": ("time", zero + 0.35), "contact_ratio": ("time", zero + 1.6),
                       "contact_ratio_eq8": ("time", zero + 1.7)}, coords={"time": t})


def test_the_words_follow_the_case():
    assert faulty_words(geardyn.paper_case()) == ("cracked", "crack")
    assert faulty_words(load_case(SPALL)) == ("faulty", "fault")


def test_fig8_marks_the_faults_events():
    ds = _record()
    titles = _texts(pf.fig8_design_parameters(ds, 1.0, (0.0, 0.2), fault="fault"))
    assert "model II (fault events dashed)" in titles
    assert not any("crack" in t for t in titles)
    # the paper's case keeps its words
    assert "model II (crack events dashed)" in _texts(pf.fig8_design_parameters(ds, 1.0,
                                                                                (0.0, 0.2)))


def test_measured_tsa_and_model_comparison_name_the_faulty_pair():
    tsas = {(v, s): np.sin(np.linspace(0, 6, 256)) for v in pf.MEASURED_STYLE
            for s in ("healthy", "cracked")}
    titles = _texts(pf.fig_measured_tsa(tsas, "II", faulty="faulty"))
    assert any("model II, faulty: TSA" in t for t in titles), titles
    assert not any("cracked" in t for t in titles)
    row = {"rms_ii_minus_i": 0.01, "rms_ii_minus_i_static": 0.001}
    comparison = {st: {"signals": {"v_yg": row, "omega_p": row}} for st in ("cracked", "healthy")}
    titles = _texts(pf.fig_model_comparison(comparison, faulty="faulty"))
    assert any(t.startswith("faulty pair:") for t in titles), titles
    assert any(t.startswith("healthy pair:") for t in titles)
    assert not any("cracked" in t for t in titles)


def test_fig6_names_a_map_with_other_faults_faulty():
    case = geardyn.paper_case({"stiffness.method": "pem", "stiffness.centre_distances": 3,
                               "stiffness.nodes_per_segment": 8})
    healthy, cracked = build_map(case, cracked=False), build_map(case, cracked=True)
    texts = _texts(fig_crack(healthy, cracked, faulty="faulty", n=200))
    assert any(t.startswith("Healthy and faulty mesh stiffness") for t in texts), texts
    assert not any("(cracked" in t for t in texts)
    assert any("(cracked" in t for t in _texts(fig_crack(healthy, cracked, n=200)))


def test_fig6_says_a_crack_on_the_gear_is_on_the_gear():
    """Its axis runs past 360 deg of pinion angle when the crack passes near 360 deg; nothing
    said the crack was on the gear (QA walkthrough)."""
    from .test_report_own_case import SPALL

    gear_crack = SPALL.with_name("root_crack_gear.toml")
    over = ['stiffness.method="pem"', "stiffness.centre_distances=4",
            "stiffness.nodes_per_segment=8"]
    case = load_case(gear_crack, over)
    healthy, cracked = build_map(case, cracked=False), build_map(case, cracked=True)
    assert "fault on the gear" in _texts(fig_crack(healthy, cracked, n=200))[0]
    pinion = geardyn.paper_case(over)
    assert "gear)" not in _texts(fig_crack(build_map(pinion, cracked=False),
                                           build_map(pinion, cracked=True), n=200))[0]
