"""Case files: loading, units, provenance, overrides and clear errors."""

from __future__ import annotations

import json
import math

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from geardyn import DataFileError, InputError, load_case, paper_case
from geardyn.config import case_schema, case_to_toml, parse_overrides
from geardyn.units import to_si


def test_paper_case_values_in_si():
    c = paper_case()
    assert c.pair.module == pytest.approx(0.006)
    assert c.pair.pressure_angle == pytest.approx(math.radians(20))
    assert c.material.youngs_modulus == pytest.approx(69e9)
    assert c.pinion.inertia == pytest.approx(0.0025)
    assert c.pinion.bearing_stiffness == pytest.approx(1e6)
    assert c.motor.torque == pytest.approx(100.0)
    assert c.load.speed == pytest.approx(114.14)
    assert c.simulation.tolerance == pytest.approx(1e-7)
    assert c.crack is not None and c.crack.depth == pytest.approx(5e-3)


def test_every_paper_case_value_has_a_source():
    c = paper_case()
    assert c.provenance["pair.module"] == "paper Table 1"
    assert "Chaari" in c.provenance["motor.inertia"]
    assert "geardyn default" in c.provenance["pair.face_width"]
    assert len(c.provenance) >= 50


@pytest.mark.parametrize(("text", "dim", "si"), [
    ("6 mm", "length", 0.006), ("20 deg", "angle", math.radians(20)), ("1e6 N/m", "stiffness", 1e6),
    ("100 N m", "torque", 100.0), ("0.0025 kg m^2", "inertia", 0.0025),
    ("1090 rpm", "angular velocity", 1090 * 2 * math.pi / 60), ("0.1 um", "length", 1e-7),
    (3.5, "length", 3.5), ("69 GPa", "pressure", 69e9),
])
def test_unit_strings(text, dim, si):
    assert to_si(text, dim, "x") == pytest.approx(si, rel=1e-12)


def test_round_trip_through_toml(tmp_path):
    c = paper_case(["pinion.teeth=25", "simulation.dt=5e-6 s"])
    p = tmp_path / "case.toml"
    p.write_text(case_to_toml(c))
    c2 = load_case(p)
    assert c2 == c
    assert c2.provenance == c.provenance
    # an override replaces the paper's source by its origin (issue 13: it used to be dropped)
    assert c2.provenance["pinion.teeth"] == "--set"
    assert c2.provenance["pair.module"] == "paper Table 1"


def test_overrides_parse_toml_values():
    assert parse_overrides(["a.b=25", "c=5e-6 s", "d=false", 'e="x y"']) == {
        "a.b": 25, "c": "5e-6 s", "d": False, "e": "x y"}
    c = paper_case({"crack.enabled": False})
    assert c.crack is not None and not c.crack.enabled


@pytest.mark.parametrize(("override", "field", "words"), [
    ("pinion.teeth=-3", "pinion.teeth", "greater than or equal to 5"),
    ("pinion.teeth=22.5", "pinion.teeth", "integer"),
    ("pinion.tooth=3", "pinion.tooth", "Allowed keys in pinion"),
    ("pair.pressure_angle=50 deg", "pair.pressure_angle", "(0, 35] deg"),
    ("pinion.mass=0.7 m", "pinion.mass", "mass"),
    ("simulation.dt=abc", "simulation.dt", "time"),
    ("nonsense=1", "nonsense", "Allowed keys"),
])
def test_bad_values_name_field_value_and_allowed(override, field, words):
    with pytest.raises(InputError) as exc:
        paper_case([override])
    assert exc.value.field == field
    assert words in str(exc.value)
    assert override.split("=", 1)[1].strip() in str(exc.value)  # the value as written


def test_bad_files(tmp_path):
    with pytest.raises(DataFileError, match="no such file"):
        load_case(tmp_path / "missing.toml")
    bad = tmp_path / "bad.toml"
    bad.write_text("[pair\nmodule = 3")
    with pytest.raises(DataFileError, match="not valid TOML"):
        load_case(bad)
    truncated = tmp_path / "trunc.toml"
    truncated.write_text(case_to_toml(paper_case())[:200])
    with pytest.raises((DataFileError, InputError)):
        load_case(truncated)


def test_schema_is_json_with_units():
    s = json.loads(case_schema())
    assert "pair" in s["properties"]
    assert '"x-unit": "m"' in case_schema()


@settings(max_examples=150, deadline=None)
@given(key=st.sampled_from(["pinion.teeth", "pair.module", "pinion.mass", "simulation.dt",
                            "crack.depth", "stiffness.centre_distances", "load.law"]),
       value=st.one_of(st.integers(-10**6, 10**6), st.floats(allow_nan=True),
                       st.text(max_size=12), st.booleans()))
def test_any_override_ends_in_a_case_or_a_clean_error(key, value):
    try:
        c = paper_case({key: value})
    except InputError as exc:
        assert exc.field and exc.allowed
    else:
        assert c.pinion.teeth >= 5
