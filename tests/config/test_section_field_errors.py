"""A section's own checks (pydantic model validators) name the one field they refuse, with the
value as the user wrote it, not the whole section (a user audit, 2026-11-27: ``stiffness:
got {'method': 'fe', ...… (217 characters)``); and a one-point map over a range is refused
(it silently held the range's lower end, -0.5 mm, at every centre distance)."""

from __future__ import annotations

import numpy as np
import pytest

from geardyn.config import paper_case
from geardyn.errors import InputError
from geardyn.stiffness import centre_distance_grid


@pytest.mark.parametrize(("overrides", "field", "value", "phrase"), [
    ({"stiffness.centre_distance_max": "-1 mm"}, "stiffness.centre_distance_max", "-1 mm",
     ">= stiffness.centre_distance_min (-0.5 mm)"),
    ({"stiffness.centre_distances": 1}, "stiffness.centre_distances", 1,
     "at least 2 over the range [-0.5, 2] mm"),
    ({"stiffness.centre_distance_max": "-0.5 mm"}, "stiffness.centre_distances", 31,
     "1 for the single centre distance change -0.5 mm"),
    ({"stiffness.fe.torques": [100, 50]}, "stiffness.fe.torques", [100, 50],
     "at least two increasing torques"),
    ({"load.law": "table", "load.table_speeds": [2, 1], "load.table_torques": [1, 2]},
     "load.table_speeds", [2, 1], "strictly increasing"),
    ({"load.law": "table"}, "load.table_speeds", None, "the same length >= 2"),
    ({"motor.law": "induction"}, "motor.synchronous_speed", None, "is required with"),
])
def test_the_refused_field_is_named_with_its_value(overrides, field, value, phrase):
    with pytest.raises(InputError) as info:
        paper_case().with_overrides(overrides)
    err = info.value
    assert err.field == field, str(err)
    assert err.value == value, str(err)
    assert phrase in err.allowed, str(err)
    assert "{" not in str(err)  # no section dumped


def test_one_centre_distance_is_a_map_at_that_one_change():
    case = paper_case().with_overrides({"stiffness.centre_distances": 1,
                                        "stiffness.centre_distance_min": "0.3 mm",
                                        "stiffness.centre_distance_max": "0.3 mm"})
    np.testing.assert_allclose(centre_distance_grid(case), [0.3e-3], rtol=0, atol=1e-15)


@pytest.mark.parametrize(("overrides", "field", "words"), [
    ({"measurement.snr": "20 dB"}, "measurement.snr",
     "a plain number, without a unit (Signal-to-noise ratio [dB]"),
    ({"mesh.damping_ratio": "7 %"}, "mesh.damping_ratio",
     "a plain number, without a unit (Mesh damping ratio"),
    ({"crack.gear": "wheel"}, "crack.gear", "'pinion' or 'gear'"),
])
def test_plain_number_and_choice_fields_say_what_they_take(overrides, field, words):
    """A unit in a plain-number field gets the field's own description (its unit or "[-]"),
    not pydantic's "Input should be a valid number, unable to parse string as a number"; a
    choice lists the choices without "Input should be"."""
    with pytest.raises(InputError) as info:
        paper_case().with_overrides(overrides)
    assert info.value.field == field and info.value.allowed.startswith(words), str(info.value)
    assert "Input should be" not in str(info.value)
