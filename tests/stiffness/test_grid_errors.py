"""A profile-shifted pair at its design centre distance, and a map grid the pair cannot run at,
as a user meets them (QA walkthrough): the rounding of the zero-backlash centre distance (-1e-17
m) refused the pair's own design; the map's interference error named the model's argument
instead of the case's field and gave no way out."""

from __future__ import annotations

import pytest

import geardyn
from geardyn.cache import Cache
from geardyn.errors import GeometryError
from geardyn.stiffness import build_map

from .._cli_fork import run_geardyn

SHIFTED = {"pinion.teeth": 17, "pinion.profile_shift": 0.8, "stiffness.method": "pem",
           "stiffness.centre_distances": 6, "stiffness.nodes_per_segment": 8}


def test_the_design_centre_distance_of_a_shifted_pair_is_accepted():
    r = run_geardyn(["geometry", "--set", "pinion.teeth=17", "--set", "pinion.profile_shift=0.8"],
                    capture_output=True, text=True, timeout=120)
    assert r.returncode == 0, r.stderr
    # a real approach of the centres is still refused
    r = run_geardyn(["geometry", "--set", "pinion.teeth=17", "--set", "pinion.profile_shift=0.8",
                     "--centre-distance-change", "-0.001 mm"], capture_output=True, text=True,
                    timeout=120)
    assert r.returncode == 2 and "zero backlash" in r.stderr, r.stderr


def test_a_grid_into_interference_names_the_field_and_the_limit(tmp_path):
    case = geardyn.paper_case(SHIFTED)
    cache = Cache(tmp_path / "cache")
    with pytest.raises(GeometryError) as exc:
        build_map(case, cracked=False, cache=cache)
    e = exc.value
    assert e.field == "stiffness.centre_distance_min" and e.value == "-0.5 mm"
    assert "--set stiffness.centre_distance_min=\"-0.26 mm\"" in e.allowed, e.allowed
    # the suggested start works; a hundredth of a millimetre lower does not
    m = build_map(case.with_overrides({"stiffness.centre_distance_min": -0.26e-3}),
                  cracked=False, cache=cache)
    assert m.dd[0] == pytest.approx(-0.26e-3)
    with pytest.raises(GeometryError):
        build_map(case.with_overrides({"stiffness.centre_distance_min": -0.27e-3}),
                  cracked=False, cache=cache)
