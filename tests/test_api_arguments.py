"""Bad arguments to the public Python API are refused by name (QA walkthrough).

Each call below used to fail deep inside numpy, pathlib or the standard library (AttributeError,
TypeError, ValueError, KeyError), or returned NaN or an empty result. Now each raises
:class:`geardyn.errors.InputError` whose ``field`` is the argument's name and whose message
names the argument, the value and what is allowed. Two inputs are accepted instead: a single
override string (``paper_case("pinion.teeth=25")``) and a torque with a unit in the static
transmission error (``"100 N m"``, as in a case file).
"""

from __future__ import annotations

import math

import numpy as np
import pytest

import geardyn
from geardyn.errors import InputError
from geardyn.geometry import centre_distance_from_displacements
from geardyn.static_te import static_te_curves, static_te_of_case
from geardyn.stiffness import StiffnessMap, build_map

NAN = float("nan")


@pytest.fixture(scope="module")
def case():
    return geardyn.paper_case()


@pytest.fixture(scope="module")
def pair(case):
    return case.gear_pair()


@pytest.fixture(scope="module")
def kmap(pair):
    """A small table map over one mesh cycle (no load shares: equal shares)."""
    th = np.linspace(0.0, pair.mesh_angle, 40, endpoint=False)
    return StiffnessMap.from_table(pair, th, 3e8 + 1e8 * np.cos(th * pair.pinion.teeth),
                                   n_seg=4)


def _refused(call, field: str, exc_type=InputError) -> InputError:
    """``call()`` raises ``exc_type`` for ``field``, named first in its one-line message."""
    with pytest.raises(exc_type) as info:
        call()
    err = info.value
    assert err.field == field
    assert str(err).startswith(f"{field}: got ")
    assert "allowed: " in str(err)
    return err


# ------------------------------------------------------------------------- geometry
def test_gear_pair_refuses_what_is_not_a_gear(pair):
    _refused(lambda: geardyn.GearPair("x", pair.gear), "pinion")
    _refused(lambda: geardyn.GearPair(pair.pinion, None), "gear")


def test_gear_refuses_a_unit_string():
    err = _refused(lambda: geardyn.Gear(teeth=20, module="3 mm", pressure_angle=0.349),
                   "module")
    assert "m" in err.allowed


@pytest.mark.parametrize("value", ["1 mm", None, [0.001]])
def test_operating_refuses_non_numbers(pair, value):
    _refused(lambda: pair.operating(value), "centre_distance_change")


def test_operating_takes_numpy_numbers(pair):
    assert pair.operating(np.float32(0.0)).contact_ratio == pair.operating(0.0).contact_ratio
    assert pair.operating(np.array(0.0)).centre_distance == pair.design_centre_distance


@pytest.mark.parametrize("theta", [NAN, math.inf, "0.1", 1e30])
def test_contact_points_refuses_bad_angles(pair, theta):
    _refused(lambda: pair.contact_points(theta), "theta")


def test_contact_points_refuses_bad_margin(pair):
    _refused(lambda: pair.contact_points(0.0, margin=NAN), "margin")
    _refused(lambda: pair.contact_points(0.0, margin=-1.0), "margin")


@pytest.mark.parametrize("kw,field", [({"n_involute": -5}, "n_involute"),
                                      ({"n_involute": 0}, "n_involute"),
                                      ({"n_involute": 2.5}, "n_involute"),
                                      ({"n_fillet": 0}, "n_fillet"),
                                      ({"n_fillet": True}, "n_fillet")])
def test_outline_refuses_bad_point_counts(pair, kw, field):
    _refused(lambda: pair.gear.outline(**kw), field)


def test_outline_smallest_counts(pair):
    o = pair.gear.outline(n_involute=2, n_fillet=2)
    assert o.involute.shape == (2, 2) and o.fillet.shape == (2, 2)


@pytest.mark.parametrize("radius", [NAN, math.inf, "0.07"])
def test_thickness_at_refuses_non_finite_radius(pair, radius):
    _refused(lambda: pair.gear.thickness_at(radius), "radius")


@pytest.mark.parametrize("y_p,y_g,field", [("a", 0.0, "y_p"), (NAN, 0.0, "y_p"),
                                           (0.0, math.inf, "y_g"),
                                           (np.array([0.0, NAN]), 0.0, "y_p"),
                                           (0.0, np.array(["a"]), "y_g")])
def test_centre_distance_from_displacements_refuses_bad_values(pair, y_p, y_g, field):
    _refused(lambda: centre_distance_from_displacements(pair, y_p, y_g), field)


def test_centre_distance_from_displacements_pair_and_arrays(pair):
    _refused(lambda: centre_distance_from_displacements("pair", 0.0, 0.0), "pair")
    d = centre_distance_from_displacements(pair, [0.0, 0.0], 0.0)
    np.testing.assert_allclose(d, pair.design_centre_distance, rtol=1e-15)


def test_operating_geometry_documents_base_pitch():
    assert "base_pitch :" in geardyn.OperatingGeometry.__doc__


# ------------------------------------------------------------------------- config
def test_load_case_refuses_a_number_as_path():
    _refused(lambda: geardyn.load_case(123), "path")


@pytest.mark.parametrize("value", [5, b"pinion.teeth=25", [5], {5: 1}])
def test_overrides_of_the_wrong_type(case, value):
    _refused(lambda: case.with_overrides(value), "overrides")
    _refused(lambda: geardyn.paper_case(value), "overrides")


def test_parse_overrides_refuses_non_strings():
    _refused(lambda: geardyn.config.parse_overrides(7), "overrides")
    _refused(lambda: geardyn.config.parse_overrides({"pinion.teeth": 25}), "overrides")


def test_a_single_override_string_is_one_override(case):
    """Accepted (not iterated character by character): the same as a one-element list."""
    one = geardyn.paper_case("pinion.teeth=25")
    assert one.pinion.teeth == 25
    assert one == geardyn.paper_case(["pinion.teeth=25"])
    assert case.with_overrides("pinion.teeth=25").pinion.teeth == 25
    assert geardyn.config.parse_overrides("pinion.teeth=25") == {"pinion.teeth": 25}


# ------------------------------------------------------------------------- stiffness map
def test_map_refuses_unknown_variable_and_slot(kmap):
    err = _refused(lambda: kmap(0.0, variable="foo"), "variable")
    assert "'k_mb'" in err.allowed
    _refused(lambda: kmap(0.0, slot=0), "slot")


@pytest.mark.parametrize("theta", ["a", None, [NAN], math.inf])
def test_map_refuses_bad_angles(kmap, theta):
    _refused(lambda: kmap(theta), "theta")


def test_map_refuses_bad_centre_distances(kmap):
    _refused(lambda: kmap(0.0, "zero"), "dd")
    _refused(lambda: kmap(0.0, None), "dd")
    _refused(lambda: kmap(np.zeros(3), np.zeros(2)), "dd")


def test_map_evaluation_unchanged(kmap):
    th = np.linspace(0.0, 1.0, 7)
    assert np.all(np.isfinite(kmap(th)))
    assert kmap(0.3) == float(kmap(np.array([0.3]))[0])


def test_map_evaluation_broadcasts_without_a_warning(kmap):
    """theta and dd broadcast against each other (a scalar, arrays of one shape, a read-only
    array) with no warning: NumPy 2 warned "future versions will not create a writeable array
    from broadcast_array" when the map asked whether ``np.broadcast_arrays``' views were
    writeable (seen by API users, 2026-11-27)."""
    import warnings

    th = np.linspace(0.0, 1.0, 7)
    read_only = th.copy()
    read_only.flags.writeable = False
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        a = kmap(th)
        b = kmap(th, np.zeros(7))
        c = kmap(read_only, 0.0)
        grid = kmap(0.3, np.zeros((2, 3)))
        one = kmap(np.array([0.3]), 0.0)
    np.testing.assert_array_equal(a, b)
    np.testing.assert_array_equal(a, c)
    assert grid.shape == (2, 3) and np.all(grid == kmap(0.3))
    assert one.shape == (1,) and one[0] == kmap(0.3)
    assert not read_only.flags.writeable  # the caller's array is left as it was


@pytest.mark.parametrize("n_theta", [-1, 0, 2.0])
def test_regular_refuses_bad_counts(kmap, n_theta):
    _refused(lambda: kmap.regular(n_theta=n_theta), "n_theta")


@pytest.mark.parametrize("n_seg", [-1, 0, 1])
def test_from_table_refuses_bad_n_seg(pair, n_seg):
    th = np.linspace(0.0, pair.mesh_angle, 8, endpoint=False)
    _refused(lambda: StiffnessMap.from_table(pair, th, np.full(8, 1e8), n_seg=n_seg), "n_seg")


def test_build_map_refuses_what_is_not_a_case():
    _refused(lambda: build_map("notacase"), "case")


# ------------------------------------------------------------------------- static TE
def test_static_te_takes_a_torque_with_a_unit(case, kmap):
    """As the case files do: '100 N m' is 100 N m, '0.1 kN m' too."""
    kw = dict(stiffness_map=kmap, errors=False, n=16)
    plain = static_te_of_case(case, 100.0, **kw)
    for text in ("100 N m", "0.1 kN m"):
        ds = static_te_of_case(case, text, **kw)
        assert ds.attrs["torque"] == pytest.approx(100.0, rel=1e-12)
        np.testing.assert_allclose(ds["transmission_error"], plain["transmission_error"],
                                   rtol=1e-12)
    both = static_te_curves(case, "100 N m", centre_distance_change="0 mm", **kw)
    assert list(both["torque"].values) == [0.0, 100.0]


@pytest.mark.parametrize("torque", ["100 m", "lots", [100.0], b"100"])
def test_static_te_refuses_bad_torques(case, kmap, torque):
    _refused(lambda: static_te_of_case(case, torque, stiffness_map=kmap, errors=False, n=16),
             "torque")


@pytest.mark.parametrize("flag", ["errors", "cracked"])
@pytest.mark.parametrize("value", ["no", "yes", 1, None])
def test_static_te_flags_are_booleans(case, kmap, flag, value):
    """``errors="no"`` was taken as True (a user audit, 2026-11-27)."""
    _refused(lambda: static_te_of_case(case, 1.0, stiffness_map=kmap, n=16, **{flag: value}),
             flag)
    _refused(lambda: static_te_curves(case, 1.0, stiffness_map=kmap, n=16, **{flag: value}),
             flag)


#: a cheap PEM case with the pinion's manufacturing errors (so that ``errors`` matters)
ERRORS_CASE = {"stiffness.method": "pem", "stiffness.centre_distances": 3,
               "stiffness.nodes_per_segment": 6, "modifications.pinion.grade": 6,
               "modifications.pinion.seed": 1, "modifications.pinion.tip_relief": "10 um",
               "modifications.pinion.runout": "8 um"}


def test_static_te_of_case_is_its_parts_with_the_documented_defaults():
    """``static_te_of_case(case)`` is :func:`static_transmission_error` of the healthy map
    at the motor torque with the case's modifications over 2048 angles (its documented
    defaults), and hands every argument on: computed here from those parts, bit for bit."""
    from geardyn.modifications import ToothModifications
    from geardyn.static_te import static_transmission_error

    case = geardyn.paper_case().with_overrides(ERRORS_CASE)
    healthy = build_map(case, cracked=False)
    mods = ToothModifications.from_case(case)
    ref = static_transmission_error(healthy, case.motor.torque, modifications=mods)
    got = static_te_of_case(case)
    assert got["transmission_error"].size == 2048
    np.testing.assert_array_equal(got["transmission_error"], ref["transmission_error"])
    assert got.attrs["torque"] == case.motor.torque
    # the defaults are seen: perfect involutes, or the cracked map, give another TE
    for other in (static_te_of_case(case, errors=False, stiffness_map=healthy),
                  static_te_of_case(case, cracked=True)):
        assert not np.allclose(other["transmission_error"], ref["transmission_error"])
    theta = np.linspace(0.0, 0.3, 7)
    got = static_te_of_case(case, "50 N m", stiffness_map=healthy, theta=theta,
                            centre_distance_change="0.2 mm")
    ref = static_transmission_error(healthy, 50.0, modifications=mods, theta=theta,
                                    centre_distance_change=0.2e-3)
    np.testing.assert_array_equal(got["theta"], theta)
    np.testing.assert_array_equal(got["transmission_error"], ref["transmission_error"])
    plain = static_transmission_error(healthy, 50.0, modifications=mods, theta=theta)
    assert not np.allclose(got["transmission_error"], plain["transmission_error"])
    assert static_te_of_case(case, stiffness_map=healthy, n=16)["transmission_error"].size == 16


def test_static_te_refuses_a_misspelt_argument_by_its_own_name_before_any_map(case,
                                                                              monkeypatch):
    """A misspelt keyword (or a bad centre-distance change) is refused before a map is built,
    and the error names ``static_te_of_case``, not the function it hands over to (which it
    named, after building the map, until 2026-11-28)."""
    import geardyn.stiffness

    def no_map(*args, **kwargs):
        raise AssertionError("a map was built")

    monkeypatch.setattr(geardyn.stiffness, "build_map", no_map)
    with pytest.raises(TypeError, match=r"static_te_of_case\(\) got an unexpected keyword "
                                        r"argument 'centre_distance'"):
        static_te_of_case(case, 1.0, centre_distance="0.5 mm")
    _refused(lambda: static_te_of_case(case, 1.0, centre_distance_change="0.5 N"),
             "centre_distance_change")


def test_static_te_refuses_what_is_not_a_case(kmap):
    _refused(lambda: static_te_of_case("case", 1.0, stiffness_map=kmap), "case")


@pytest.mark.parametrize("n", [0, -3, 2.5])
def test_static_te_refuses_bad_point_counts(case, kmap, n):
    _refused(lambda: static_te_of_case(case, 1.0, stiffness_map=kmap, errors=False, n=n), "n")


# ------------------------------------------- a second user audit (2026-11-27), the API's side
SMALL = {"stiffness.method": "pem", "stiffness.centre_distances": 3,
         "stiffness.nodes_per_segment": 6, "simulation.record_time": "0.05 s",
         "simulation.settle_time": "0.01 s"}


def test_map_method_in_any_case_and_flags_that_are_not_bools(case):
    small = case.with_overrides(SMALL)
    assert build_map(small, method=" PEM ", cracked=False).attrs["method"] == "pem"
    for kwargs, field in (({"method": "xyz"}, "method"), ({"cracked": "no"}, "cracked"),
                          ({"cracked": 1}, "cracked")):
        with pytest.raises(InputError) as info:
            build_map(small, **kwargs)
        assert info.value.field == field, str(info.value)
    from geardyn.dynamics import simulate

    with pytest.raises(InputError) as info:
        simulate(small, cracked="no")  # "no" is not taken for True
    assert info.value.field == "cracked"


def test_measure_refuses_what_is_not_a_case():
    from geardyn.studies.measure import measure

    with pytest.raises(InputError) as info:
        measure("x")
    assert info.value.field == "case" and "not a str" in str(info.value)


def test_diagnose_file_takes_a_rate_with_its_unit_and_names_a_missing_file(tmp_path):
    from geardyn.diagnostics import diagnose_file
    from geardyn.errors import DataFileError

    fs, f_shaft, z = 20_000.0, 20.0, 23
    t = np.arange(int(2.0 * fs)) / fs
    acc = np.sin(2 * np.pi * z * f_shaft * t) + 0.3 * np.sin(2 * np.pi * 2 * z * f_shaft * t)
    tach = (np.mod(f_shaft * t, 1.0) < 0.05).astype(float)  # one pulse a revolution
    path = tmp_path / "syn.csv"
    np.savetxt(path, np.column_stack([acc, tach]), delimiter=",", header="acc,tach", comments="")
    opts = {"signals": ["acc"], "tach": "tach", "teeth": z}
    a = diagnose_file(path, fs="20 kHz", **opts).to_dict()["signals"]["acc"]
    b = diagnose_file(path, fs=fs, **opts).to_dict()["signals"]["acc"]
    assert a["n_averages"] == b["n_averages"] >= 30
    assert a["kurtosis"] == b["kurtosis"]
    with pytest.raises(InputError) as info:
        diagnose_file(path, fs="20 rpm", **opts)  # a speed, not a sample rate
    assert info.value.field == "fs"
    with pytest.raises(DataFileError):  # the file first, not "signals: got None"
        diagnose_file(tmp_path / "missing.csv")


def test_diagnose_file_refuses_a_tach_for_a_simulation_record(case, tmp_path):
    from geardyn.diagnostics import diagnose_file
    from geardyn.dynamics import simulate
    from geardyn.io import write_netcdf_atomic

    rec = tmp_path / "sim.nc"
    write_netcdf_atomic(simulate(case.with_overrides(SMALL)), rec)
    for kwargs, field in (({"tach": "omega_p"}, "tach"), ({"angle": "theta_g"}, "angle")):
        with pytest.raises(InputError) as info:
            diagnose_file(rec, **kwargs)
        assert info.value.field == field and "exact pinion angle" in info.value.allowed


def test_numpy_scalars_are_the_numbers_they_hold():
    """A sweep over ``np.arange`` gives NumPy scalars: ``pinion.teeth = np.int64(23)`` was
    refused as "got 23; allowed: a valid integer" (a user audit, 2026-11-27). Non-integral
    values are still refused."""
    import geardyn

    c = geardyn.paper_case({"pinion.teeth": np.int64(25), "motor.torque": np.float32(90.0),
                            "simulation.decimation": np.int32(2)})
    assert (c.pinion.teeth, c.motor.torque, c.simulation.decimation) == (25, 90.0, 2)
    assert type(c.pinion.teeth) is int
    again = geardyn.paper_case().with_overrides({"pinion.teeth": np.int64(25)})
    assert again.pinion.teeth == 25 and type(again.pinion.teeth) is int
    _refused(lambda: geardyn.paper_case({"pinion.teeth": np.float64(25.5)}), "pinion.teeth")


def test_a_case_hashes_as_its_values():
    """``hash(case)`` raised "unhashable type: 'list'" (pydantic's frozen hash over the list
    fields), so a case could not key a dict or an lru_cache (a user audit, 2026-11-27)."""
    import functools

    import geardyn

    a, b = geardyn.paper_case(), geardyn.paper_case()
    assert a == b and hash(a) == hash(b) and len({a, b}) == 1
    c = a.with_overrides({"motor.torque": "90 N m"})
    assert c != a and hash(c) != hash(a)

    @functools.lru_cache
    def torque(case):
        return case.motor.torque

    assert torque(a) == torque(b) == 100.0 and torque.cache_info().hits == 1
    assert hash(a.measurement) == hash(b.measurement)  # a section with list fields


def test_an_entry_of_an_empty_list_says_the_list_is_empty():
    """"allowed: an index in [0, -1] of the list" for faults.0.width on a case without faults (a
    user audit, 2026-11-27)."""
    import geardyn

    err = _refused(lambda: geardyn.paper_case().with_overrides({"faults.0.width": "3 mm"}),
                   "faults.0")
    assert "an entry of faults, which is empty in this case" in err.allowed


def test_maps_and_diagnoses_print_as_one_line(kmap):
    """Their dataclass reprs printed every array (6,800 and 10,000 characters: a user audit)."""
    import geardyn

    text = repr(kmap)
    assert text.startswith("StiffnessMap(method=") and len(text) < 300 and "\n" not in text
    assert f"{kmap.dd.size} centre distance changes" in text and "N/m)" in text
    th = np.linspace(0.0, 2 * np.pi * 10, 20_000)
    d = geardyn.diagnose({"v": np.cos(23 * th)}, teeth=23, angle=th, samples_per_rev=256)
    text = repr(d)
    assert text.startswith("DiagnosisResult(teeth=23") and len(text) < 300
    assert "v (10 revolutions" in text


def test_every_variable_of_a_map_dataset_has_a_unit(kmap):
    """``node`` and ``slot_tooth`` had none (a user audit, 2026-11-27)."""
    ds = kmap.to_dataset()
    missing = [n for n, v in {**ds.data_vars, **ds.coords}.items() if "units" not in v.attrs]
    assert missing == []


def test_a_ripple_with_a_speed_profile_is_refused():
    """The ripple is a fixed-frequency torque (ripple_order x load.speed): in a run-up to
    145 rad/s it sat at order 4.8 instead of 6 (a user audit, 2026-11-27). Either alone is
    accepted."""
    import geardyn

    profile = {"motor.profile_times": [0.5, 1.0], "motor.profile_speeds": [114.14, 150.0]}
    err = _refused(lambda: geardyn.paper_case({**profile, "motor.ripple": 0.02}), "motor.ripple")
    assert "would not follow the run-up" in err.allowed
    geardyn.paper_case(profile)
    geardyn.paper_case({"motor.ripple": 0.02, "motor.ripple_order": 6})
