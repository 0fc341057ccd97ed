"""Units that cannot lie (issue 17.1) and bounded unit parsing (issue 13), a test per dimension
family, through :func:`geardyn.units.to_si` and the real CLI."""

from __future__ import annotations

import math
import tomllib

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from geardyn.config import paper_case
from geardyn.errors import InputError
from geardyn.units import DIMENSIONS, parse_angular_velocity, parse_frequency, to_si

from ._cli import assert_clean_error, cli, cli_proc

TWO_PI = 2 * math.pi

# (dimension, accepted strings with their SI value by hand, refused strings)
FAMILIES = {
    "length": ([("6 mm", 6e-3), ("0.1 um", 1e-7), ("2.5 cm", 0.025), ("0.006", 0.006)],
               ["6 kg", "6 mm rad", "6 mm %", "20 percent"]),
    "angle": ([("20 deg", 20 * math.pi / 180), ("0.3 rad", 0.3), ("0.25 turn", math.pi / 2),
               ("20°", 20 * math.pi / 180)],
              ["20 percent", "20 %", "20 m/m", "20 Hz", "20 deg/s", "20 ppm"]),
    "angular velocity": ([("1090 rpm", 1090 * TWO_PI / 60), ("18.17 Hz", 18.17 * TWO_PI),
                          ("114.14 rad/s", 114.14), ("6540 deg/s", 6540 * math.pi / 180),
                          ("1 kHz", 1000 * TWO_PI), ("2 rps", 2 * TWO_PI)],
                         ["100 1/s", "100 s^-1", "100 rad", "100 m/s", "5 percent"]),
    "frequency": ([("20 kHz", 2e4), ("50 Hz", 50.0), ("1000 1/s", 1000.0), ("2 MHz", 2e6)],
                  ["1000 rpm", "100 rad/s", "1 s", "10 deg/s"]),
    "mass": ([("0.7 kg", 0.7), ("700 g", 0.7)], ["0.7 kg rad", "0.7 N", "7 %"]),
    "inertia": ([("0.0025 kg m^2", 0.0025), ("25 kg cm^2", 0.0025), ("2500 kg*mm**2", 0.0025)],
                ["0.0025 kg m", "0.0025 kg m^2/rad"]),
    "stiffness": ([("1e6 N/m", 1e6), ("1 kN/mm", 1e6)], ["1e6 N m/rad", "1e6 N"]),
    "damping": ([("84 N s/m", 84.0), ("84 kg/s", 84.0)], ["84 N/m"]),
    "torsional stiffness": ([("1e5 N m/rad", 1e5), ("1e5 N m", 1e5),
                             ("1 N m/deg", 180 / math.pi)], ["1e5 N m rad", "1e5 N/m"]),
    "torsional damping": ([("0.87 N m s/rad", 0.87), ("0.87 N m s", 0.87)], ["0.87 N m"]),
    "torque": ([("100 N m", 100.0), ("0.1 kN m", 100.0), ("100 J", 100.0)],
               ["100 N m/rad", "100 N"]),
    "pressure": ([("69 GPa", 69e9), ("69000 MPa", 69e9), ("69e3 N/mm^2", 69e9)], ["69 GN"]),
    "time": ([("1e-5 s", 1e-5), ("10 us", 1e-5), ("0.5 ms", 5e-4)], ["1 Hz", "1 m"]),
    "quadratic torque coefficient": ([("0.0077 N m s^2", 0.0077),
                                      ("0.0077 N m s^2/rad^2", 0.0077)],
                                     ["0.0077 N m s^2 rad"]),
    "density": ([("2700 kg/m^3", 2700.0), ("2.7 g/cm^3", 2700.0)], ["2700 kg/m^2"]),
    "acceleration": ([("9.80665 m/s^2", 9.80665), ("1 g_n", 9.80665)], ["1 m/s"]),
    "dimensionless": ([("0.05", 0.05), ("5 %", 0.05), ("5 percent", 0.05)], ["5 deg", "5 m"]),
}


def test_every_dimension_has_a_family_test():
    assert set(FAMILIES) == set(DIMENSIONS)


@pytest.mark.parametrize("dimension", sorted(FAMILIES))
def test_dimension_family(dimension):
    accepted, refused = FAMILIES[dimension]
    for text, si in accepted:
        assert to_si(text, dimension, "x") == pytest.approx(si, rel=1e-12), text
    for text in refused:
        with pytest.raises(InputError) as exc:
            to_si(text, dimension, "x")
        msg = str(exc.value)
        assert exc.value.field == "x" and text in msg
        assert DIMENSIONS[dimension].units in msg  # the allowed units are named
        assert len(msg) < 500


def test_issue_17_numbers_through_the_cli():
    """``load.speed="18.17 Hz"`` is 114.2 rad/s (it was taken as 18.17 rad/s), ``1090 rpm`` is
    114.1 rad/s, and ``config show`` states the 2 pi."""
    assert paper_case(['load.speed="18.17 Hz"']).load.speed == pytest.approx(114.165, abs=1e-3)
    assert paper_case(['load.speed="1090 rpm"']).load.speed == pytest.approx(114.145, abs=1e-3)
    r = cli("config", "show", "--set", 'load.speed="18.17 Hz"')
    assert r.exit_code == 0, r.output
    speed = tomllib.loads(r.stdout)["load"]["speed"]
    assert speed["value"] == "18.17 Hz" and speed["origin"] == "--set"
    assert speed["si"].startswith("114.16547") and "2 pi" in speed["si"]


@pytest.mark.parametrize("value", ['"20 percent"', '"20 %"', '"0.2"'.replace("0.2", "20 Hz")])
def test_crack_angle_in_percent_is_refused_through_the_cli(value):
    line = assert_clean_error(cli("config", "show", "--set", f"crack.angle={value}"),
                              "crack.angle", "deg or rad")
    assert value.strip('"') in line


def test_frequency_and_angular_velocity_helpers():
    assert parse_frequency("20 kHz") == 2e4
    assert parse_frequency(5000) == 5000.0
    for bad in ("1000 rpm", "-5 Hz", "0", "fast"):
        with pytest.raises(InputError, match="--fs"):
            parse_frequency(bad)
    assert parse_angular_velocity("18.17 Hz", "w") == pytest.approx(18.17 * TWO_PI, rel=1e-12)
    with pytest.raises(InputError, match="ambiguous"):
        parse_angular_velocity("100 1/s", "w")


def test_bare_numbers_stay_si():
    assert to_si("0.3490658503988659", "angle", "x") == 0.3490658503988659
    assert to_si(114.14, "angular velocity", "x") == 114.14
    assert paper_case(["pair.pressure_angle=0.3"]).pair.pressure_angle == 0.3


BOMBS = ["10**10**10 mm", "10^10^10 mm", "1 mm**10**10", "1 m^999", "1 m^2^2", "1e999999 mm",
         "9" * 5000 + " mm", "1 " + "m*" * 500 + "m", "1 (mm)", "1 mm)", "__import__('os') mm",
         "1 mm; 2", "nan mm", "inf", "-inf m", "1e300 GPa", "1 " + "x" * 200]


@pytest.mark.parametrize("text", BOMBS, ids=range(len(BOMBS)))
def test_unit_bombs_are_refused_quickly(text):
    with pytest.raises(InputError) as exc:
        to_si(text, "length", "pair.module")
    assert len(str(exc.value)) < 500


@pytest.mark.timeout(60)
def test_unit_bomb_through_the_cli_in_process(tmp_path):
    assert_clean_error(cli("simulate", "--set", 'pair.module="10**10**10 mm"', "--out",
                           str(tmp_path / "o.nc")), "pair.module", "10**10**10 mm")


@pytest.mark.slow
def test_unit_bomb_through_the_cli_does_not_hang(tmp_path):
    """``--set pair.module="10**10**10 mm"`` hung (killed at 15 s) before the bounded grammar."""
    r = cli_proc("simulate", "--set", 'pair.module="10**10**10 mm"', "--out",
                 str(tmp_path / "o.nc"))
    assert_clean_error(r, "pair.module", "10**10**10 mm")


@pytest.mark.parametrize(("override", "words"), [
    ("pair.module=1e300", "magnitude"),                  # OverflowError before
    ("pinion.teeth=" + "1" * 100_000, "pinion.teeth"),  # ValueError (4300 digits) before
    ("pair.module=" + "1" * 5000, "pair.module"),
    ("pair.module=nan", "finite"),
    ("pair.module=inf", "finite"),
    ("pair.module=-inf", "finite"),
    ('pair.module="1e400 mm"', "finite"),
])
def test_huge_and_non_finite_numbers_are_clean_errors(override, words):
    assert_clean_error(cli("geometry", "--set", override), words)


@pytest.mark.slow
def test_huge_numbers_through_simulate(tmp_path):
    r = cli_proc("simulate", "--set", "pair.module=1e300", "--out", str(tmp_path / "o.nc"))
    assert_clean_error(r, "pair.module")
    r = cli_proc("simulate", "--set", "pinion.teeth=" + "7" * 100_000, "--out",
                 str(tmp_path / "o.nc"))
    assert_clean_error(r, "pinion.teeth")


@pytest.mark.parametrize("fs", ["1000 rpm", "100 rad/s", "-5 Hz", "nan", "10**10**10 Hz"])
def test_diagnose_fs_takes_frequency_units_only(tmp_path, fs):
    data = tmp_path / "rec.csv"
    data.write_text("a,b\n0,1\n1,2\n")
    assert_clean_error(cli("diagnose", str(data), "--fs", fs, "--out", str(tmp_path / "o")),
                       "--fs", "Hz")


_PIECES = ["1", "0", "9", ".", "e", "E", "+", "-", " ", "*", "**", "^", "/", "(", ")", "mm",
           "m", "deg", "rad", "Hz", "kHz", "rpm", "s", "N", "kg", "%", "percent", "GPa", "10",
           "1e308", "µ", "°", "nan", "inf", "_", "·", "x"]


@pytest.mark.timeout(300)
@settings(max_examples=400, deadline=None)
@given(text=st.lists(st.sampled_from(_PIECES), max_size=24).map("".join),
       dimension=st.sampled_from(sorted(DIMENSIONS)))
def test_fuzzed_unit_strings_give_a_number_or_a_clean_error(text, dimension):
    """Any string ends in a finite SI float within the magnitude bound, or an InputError with a
    short message; nothing else (no OverflowError, no pint exception, no hang)."""
    try:
        v = to_si(text, dimension, "f")
    except InputError as exc:
        assert exc.field == "f" and len(str(exc)) < 500
    else:
        assert math.isfinite(v) and abs(v) <= 1e30


def test_the_everyday_unit_table_is_pints_answer():
    """The start-up fast path (``_KNOWN_UNITS``, ``_KNOWN_TARGETS``) equals pint for every entry:
    the table is pint's data, not a second unit system."""
    import math

    from geardyn import units as U

    for name, (factor, root, canon) in U._KNOWN_UNITS.items():
        p_factor, p_root, p_canon = U._pint_unit_root(name)
        assert math.isclose(factor, p_factor, rel_tol=1e-15), name
        assert (tuple(root), canon) == (p_root, p_canon), name
    for dim, (factor, root) in U._KNOWN_TARGETS.items():
        p_factor, p_root = U._pint_target_root(dim)
        assert math.isclose(factor, p_factor, rel_tol=1e-15) and root == p_root, dim
    assert set(U._KNOWN_TARGETS) == set(U.DIMENSIONS)


@pytest.mark.parametrize(("text", "dim", "said"), [
    ("5 deg", "length", "'deg' is an angle, not a length"),
    ("0.3 rad", "length", "'rad' is an angle, not a length"),
    ("2 ms", "length", "'ms' is a time, not a length"),
    ("5 mm", "time", "'mm' is a length, not a time"),
    ("3 Hz", "torque", "'Hz' is a frequency, not a torque"),
])
def test_a_quantity_of_another_kind_is_named_as_such(text, dim, said):
    """"5 deg" for a length read "(this has units no dimension, not a length)" (a user audit,
    2026-11-27): an angle's radians are dropped before the comparison."""
    from geardyn.units import to_si

    with pytest.raises(InputError) as err:
        to_si(text, dim, "f")
    assert err.value.allowed.endswith(f"({said})"), err.value.allowed
