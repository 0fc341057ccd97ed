"""The global attributes of a simulation record: every numeric one has its ``<name>_units`` (SI)
unless it is a count or a flag (listed here); a speed-controlled run says what it simulated
(``input_law``, ``target_speed``); ``simulate`` checks its arguments' types and accepts the
model's name in any case, as the CLI's ``--model``."""

from __future__ import annotations

import numbers

import numpy as np
import pytest

from geardyn.dynamics import simulate
from geardyn.errors import InputError

from ._support import geometric_map, short_case

#: Numeric attributes that are counts or 0/1 flags: no unit.
COUNTS_AND_FLAGS = frozenset({
    "pinion_teeth", "gear_teeth",        # teeth
    "decimation",                        # steps per recorded sample
    "max_iterations",                    # re-solves allowed in a step
    "steps_without_fixed_point",         # steps
    "complete", "output_law_calibrated", "stiffness_cracked",  # 0/1 flags
})

#: Expected units of the attributes this file was written for (others: any non-empty string).
EXPECTED = {
    "dt": "s", "settle_time": "s", "record_time": "s", "max_time_step": "s",
    "static_mesh_force": "N", "static_centre_distance_change": "m",
    "representative_mesh_stiffness": "N/m", "highest_natural_frequency": "Hz",
    "mesh_frequency": "Hz", "target_speed": "rad/s", "tolerance": "m", "rtol": "1",
    "hht_alpha": "1", "mesh_damping": "N s/m", "friction_coefficient": "1",
    "initial_speed": "rad/s",
}

SHORT = {"simulation.record_time": 0.002, "simulation.settle_time": 0.0}
#: Everything that adds attributes: tooth errors, ripple and a speed profile (the ripple and
#: the profile are not combined since 2026-11-27: the ripple is a fixed-frequency torque)
EXTRAS = {"modifications.gear.runout": "8 um", "motor.ripple": 0.02}
PROFILE = {"modifications.gear.runout": "8 um", "motor.profile_times": [0.0, 0.001],
           "motor.profile_speeds": [114.14, 120.0]}


def _numeric(value) -> bool:
    return isinstance(value, numbers.Number | np.number) and not isinstance(value, bool | str)


def _missing_units(attrs: dict) -> list[str]:
    return sorted(name for name, value in attrs.items()
                  if _numeric(value) and not name.endswith("_units")
                  and name not in COUNTS_AND_FLAGS
                  and not (isinstance(attrs.get(f"{name}_units"), str)
                           and attrs[f"{name}_units"].strip()))


@pytest.mark.parametrize("model,dynamics,extras", [
    ("I", "six_dof", False), ("I-static", "six_dof", "ripple"), ("II", "six_dof", "profile"),
    ("II", "six_dof", "ripple"), ("II", "transverse", False), ("I", "transverse", "ripple"),
    ("I", "transverse", "profile")])
def test_every_numeric_attribute_has_its_units(model, dynamics, extras):
    over = dict(SHORT, **({"ripple": EXTRAS, "profile": PROFILE}.get(extras) or {}))
    if dynamics == "transverse":
        over.update({"simulation.dynamics": "transverse", "mesh.friction_coefficient": 0.05})
    case = short_case(**over)
    ds = simulate(case, geometric_map(case.gear_pair()), model=model)
    assert ds.attrs.get("dynamics", "six_dof") == dynamics
    if extras:
        assert {"input_torque_ripple" if extras == "ripple" else "speed_profile",
                "tooth_errors"} <= set(ds.attrs)
    assert _missing_units(ds.attrs) == []
    for name, unit in EXPECTED.items():
        if name in ds.attrs:
            assert ds.attrs[f"{name}_units"] == unit, name
    # counts and flags really are integers (a quantity may not hide in the list)
    for name in COUNTS_AND_FLAGS & set(ds.attrs):
        assert isinstance(ds.attrs[name], int | np.integer), name
    # the damping values carry their units in the text
    assert "N m s/rad" in ds.attrs["damping"] and "N s/m" in ds.attrs["damping"]


def test_a_speed_controlled_run_says_what_it_simulated():
    """The drive and its target are in ``input_law`` / ``target_speed`` (not only in
    ``speed_profile``): the record of a ramp to 150 rad/s does not claim a constant torque and
    a 114.14 rad/s target."""
    case = short_case(**SHORT, **{"motor.profile_times": [0.0, 0.001],
                                  "motor.profile_speeds": [114.14, 150.0],
                                  "motor.drive_gain": 5.0})
    ds = simulate(case, geometric_map(case.gear_pair()), model="I")
    a = ds.attrs
    assert a["target_speed"] == 150.0 and a["target_speed_units"] == "rad/s"
    assert a["initial_speed"] == pytest.approx(114.14) and a["initial_speed_units"] == "rad/s"
    assert "w_target(t) - w_m" in a["input_law"] and "5 N m s/rad" in a["input_law"]
    assert "final 150 rad/s" in a["input_law"] and "integral" in a["input_law"]
    assert a["input_law"].startswith("constant T = 100 N m + ")
    # without a profile: unchanged
    plain = simulate(short_case(**SHORT), geometric_map(case.gear_pair()), model="I").attrs
    assert plain["input_law"] == "constant T = 100 N m"
    assert plain["target_speed"] == pytest.approx(114.14) and "initial_speed" not in plain


@pytest.fixture(scope="module")
def case_and_map():
    case = short_case(**{"simulation.record_time": 0.0005, "simulation.settle_time": 0.0})
    return case, geometric_map(case.gear_pair())


@pytest.mark.parametrize("args,field", [
    (("not a case", "map"), "case"), ((None, "map"), "case"), (("map", "map"), "case"),
    (("case", "x"), "stiffness_map"), (("case", 3.0), "stiffness_map"),
    (("map", "case"), "case")])
def test_arguments_of_the_wrong_type_are_refused_by_name(case_and_map, args, field):
    case, smap = case_and_map
    real = {"case": case, "map": smap}
    call = [real.get(a, a) if isinstance(a, str) else a for a in args]
    with pytest.raises(InputError) as info:
        simulate(*call)
    assert info.value.field == field
    assert "geardyn" in info.value.allowed


@pytest.mark.parametrize("bad", ["III", "", 2, ["II"]])
def test_bad_model_names_are_refused_by_name(case_and_map, bad):
    case, smap = case_and_map
    with pytest.raises(InputError) as info:
        simulate(case, smap, model=bad)
    assert info.value.field == "model" and "(any case)" in info.value.allowed


@pytest.mark.parametrize("given,name", [("ii", "II"), ("i-static", "I-static"), (" I ", "I")])
def test_the_model_name_is_accepted_in_any_case_as_by_the_cli(case_and_map, given, name):
    case, smap = case_and_map
    ds = simulate(case, smap, model=given)
    assert ds.attrs["model"] == name
    tr = simulate(case.with_overrides({"simulation.dynamics": "transverse"}), smap, model=given)
    assert tr.attrs["model"] == name and tr.attrs["dynamics"] == "transverse"
