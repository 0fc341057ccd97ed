"""``geardyn geometry --centre-distance-change`` refuses centres closer than the zero-backlash
distance (negative backlash: the teeth would interpenetrate) and names the option in mm; the
library keeps evaluating such centre distances for the stiffness maps' grid."""

from __future__ import annotations

import json
import math
import os

import pytest

from geardyn import Gear, GearPair, paper_case
from geardyn.stiffness import centre_distance_grid

from ._cli_fork import run_geardyn


def run(*args, tmp_path=None):
    env = dict(os.environ)
    if tmp_path is not None:
        env["GEARDYN_CACHE_DIR"] = str(tmp_path / "cache")
    return run_geardyn(["geometry", *args], capture_output=True, text=True, timeout=120, env=env)


def _one_error_line(r) -> str:
    assert r.returncode == 2, (r.stdout, r.stderr)
    assert "Traceback" not in r.stderr + r.stdout
    lines = [ln for ln in r.stderr.splitlines() if ln.strip()]
    assert len(lines) == 1, r.stderr
    return lines[0]


def test_smallest_change_is_the_zero_backlash_one():
    mk = {"module": 0.004, "pressure_angle": math.radians(20)}
    pairs = [paper_case().gear_pair(),
             GearPair(Gear(teeth=17, profile_shift=0.4, **mk), Gear(teeth=41, profile_shift=0.3, **mk)),
             GearPair(Gear(teeth=30, profile_shift=-0.3, **mk), Gear(teeth=50, **mk))]
    for pair in pairs:
        lo = pair.min_centre_distance_change()
        assert abs(lo) < 1e-15  # the design centre distance is the zero-backlash one
        assert pair.operating(lo, check=False).normal_backlash == pytest.approx(0.0, abs=1e-15)
        assert pair.operating(lo - 1e-6, check=False).normal_backlash < 0
        assert pair.operating(lo + 1e-6, check=False).normal_backlash > 0


def test_library_still_evaluates_the_maps_grid_below_the_design_distance():
    """The default [stiffness] grid starts at -0.5 mm (negative backlash, on purpose): the
    shared GearPair.operating must not refuse it."""
    case = paper_case()
    pair = case.gear_pair()
    dd = centre_distance_grid(case)
    assert dd[0] == pytest.approx(-0.5e-3)
    for d in dd:
        op = pair.operating(float(d))  # check=True: only the contact-ratio check
        assert op.contact_ratio >= 1
    assert pair.operating(-0.5e-3).normal_backlash == pytest.approx(-337.28e-6, abs=0.01e-6)


@pytest.mark.parametrize("typed", ["-0.5mm", "-5mm", "-0.0005"])
def test_negative_backlash_is_refused_naming_option_value_backlash_and_limit(typed):
    pair = paper_case().gear_pair()
    dd = -0.5e-3 if typed in ("-0.5mm", "-0.0005") else -5e-3
    jn = pair.operating(dd, check=False).normal_backlash
    line = _one_error_line(run(f"--centre-distance-change={typed}"))
    assert line.startswith("error: --centre-distance-change: got ")
    assert f"got {dd * 1e3:g} mm;" in line
    assert f"normal backlash of {jn * 1e6:.2f} um" in line
    assert "a change >= 0.0000 mm, the one giving zero backlash" in line
    assert "interpenetrate" in line
    assert "centre_distance_change:" not in line


def test_centres_closer_than_the_base_radii_are_refused_the_same_way():
    line = _one_error_line(run("-d", "-10mm"))
    assert "--centre-distance-change: got -10 mm;" in line
    assert "a change >= 0.0000 mm" in line and "closer than r_b1 + r_b2" in line


def test_json_is_refused_too():
    r = run("-d", "-0.5mm", "--json")
    assert "--centre-distance-change" in _one_error_line(r)
    assert r.stdout == ""


def test_contact_ratio_refusal_names_the_option_in_mm():
    pair = paper_case().gear_pair()
    line = _one_error_line(run("--centre-distance-change=10mm"))
    assert "--centre-distance-change: got 10 mm;" in line
    assert "contact ratio >= 1" in line
    assert f"the largest allowed change is {pair.max_centre_distance_change() * 1e3:.4f} mm" in line
    assert "centre_distance_change:" not in line and "0.01" not in line


@pytest.mark.parametrize("typed", ["0mm", "-0mm", "1.07mm"])
def test_zero_and_positive_backlash_still_print(typed):
    r = run("-d", typed, "--json")
    assert r.returncode == 0, r.stderr
    s = json.loads(r.stdout)
    assert s["operating"]["normal_backlash_m"] >= -1e-15  # rounding of the zero at 0 mm
    assert s["operating"]["contact_ratio"]["physical"] < 2


def test_table_names_single_and_double_contact_for_an_ordinary_pair():
    r = run("-d", "1.07mm")
    assert r.returncode == 0, r.stderr
    assert "single / double contact fraction" in r.stdout
    assert "0.5802 / 0.4198" in r.stdout
    assert "note:" not in r.stdout


def test_a_contact_ratio_above_2_says_two_or_three_pairs():
    """40/40 teeth at 14.5 deg: a valid high-contact-ratio pair (2.05 at zero backlash)."""
    mk = {"module": 0.006, "pressure_angle": math.radians(14.5)}
    op = GearPair(Gear(teeth=40, **mk), Gear(teeth=40, **mk)).operating(0.0)
    assert 2 < op.contact_ratio < 3
    r = run("--set", "pinion.teeth=40", "--set", "gear.teeth=40",
            "--set", "pair.pressure_angle=14.5deg")
    assert r.returncode == 0, r.stderr
    out = " ".join(r.stdout.split())
    assert "single / double" not in out
    assert (f"2-pair / 3-pair contact fraction │ {op.single_contact_fraction:.4f} / "
            f"{op.double_contact_fraction:.4f}") in out
    assert f"note: contact ratio {op.contact_ratio:.4f} >= 2" in out
    assert "2 or 3 tooth pairs share the load" in out


def test_static_te_refuses_the_same_centre_distances(tmp_path):
    """``geardyn static-te --centre-distance-change`` takes the same operating point as
    ``geometry``: a negative backlash is refused before any map is built (the QA saw it accepted
    down to the map's range)."""
    env = {**os.environ, "GEARDYN_CACHE_DIR": str(tmp_path / "cache")}
    r = run_geardyn(["static-te", "--stiffness", "pem", "--centre-distance-change", "-0.5 mm",
                     "--out", str(tmp_path / "te.nc")], capture_output=True, text=True,
                    timeout=120, env=env)
    line = _one_error_line(r)
    assert line.startswith("error: --centre-distance-change: got -0.5 mm;") and \
        "interpenetrate" in line, line
    assert not (tmp_path / "te.nc").exists() and not (tmp_path / "cache").exists()
