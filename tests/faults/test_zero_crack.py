"""A root crack of zero depth is the healthy tooth (issue 15 item 5), so a sweep over crack depth
can start at 0 mm and compare every size with the healthy gear in one axis."""

from __future__ import annotations

import warnings

import numpy as np
import pytest

import geardyn
from geardyn.cache import cache_key
from geardyn.stiffness import build_map, map_inputs
from geardyn.stiffness.fe.model import _crack_of
from geardyn.studies.sweep import parse_sweep

from .._cli_fork import run_geardyn

SMALL = {"stiffness.method": "pem", "stiffness.centre_distances": 3,
         "stiffness.nodes_per_segment": 12}


def test_the_case_names_its_crack_only_where_it_changes_the_stiffness():
    """``Case.active_crack``: the crack where enabled and deeper than zero, else None (the test
    that the study, the reports and the map keys ask through it)."""
    case = geardyn.paper_case(SMALL)
    assert case.active_crack is case.crack and case.crack.depth > 0
    for off in ({"crack.depth": 0.0}, {"crack.enabled": False}):
        other = geardyn.paper_case({**SMALL, **off})
        assert other.crack is not None and other.active_crack is None
    assert case.model_copy(update={"crack": None}).active_crack is None
    assert "active_crack" not in case.model_dump()  # derived, not a field of the case file


def test_zero_depth_gives_the_healthy_map_bit_for_bit():
    zero = geardyn.paper_case({**SMALL, "crack.depth": 0.0})
    healthy = geardyn.paper_case({**SMALL, "crack.enabled": False})
    assert zero.crack.enabled and not zero.crack.active
    assert geardyn.paper_case(SMALL).crack.active
    # the same map inputs, hence the same cache entry
    assert cache_key(map_inputs(zero, "pem", True)) == cache_key(map_inputs(healthy, "pem", False))
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        a = build_map(zero, method="pem", cracked=True)
        b = build_map(healthy, method="pem", cracked=False)
        c = build_map(geardyn.paper_case({**SMALL, "crack.depth": 1e-4}), method="pem",
                      cracked=True)
    va, vb, vc = (m.arrays().values for m in (a, b, c))
    assert np.array_equal(va, vb)
    # and the smallest crack is a small change, not a jump (continuity at zero size)
    assert 0 < np.max(np.abs(vc - vb) / vb) < 0.01
    # the FE model builds no cracked body for it
    assert _crack_of(zero, True) is None


@pytest.mark.slow  # two CLI subprocesses
def test_zero_depth_is_accepted_by_validation_and_sweeps_negative_is_refused(tmp_path):
    for depth, code in (("0 mm", 0), ("-1 mm", 2)):
        f = tmp_path / "case.toml"
        f.write_text(f'extends = "xue_howard"\n[crack]\ndepth = "{depth}"\n')
        r = run_geardyn(["config", "validate", str(f)],
                        capture_output=True, text=True, timeout=120)
        assert r.returncode == code, r.stdout + r.stderr
        assert "Traceback" not in r.stderr
    assert "crack.depth" in r.stderr
    sw = parse_sweep('name = "z"\nbase = "xue_howard"\n[axes]\n'
                     'crack.depth = ["0 mm", "1 mm"]\n')
    plan = sw.plan()
    cases = [sw.base_case.with_overrides(plan.overrides(i)) for i in range(plan.n_runs)]
    assert [c.crack.active for c in cases] == [False, True]
