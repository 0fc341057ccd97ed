"""``geardyn config show`` in the units written and ``config validate`` running every check that
needs no simulation (issue 13)."""

from __future__ import annotations

import math
import tomllib

import pytest

from geardyn.case_checks import check_case
from geardyn.config import load_case, paper_case
from geardyn.errors import InputError

from ._cli import assert_clean_error, cli


def _case(tmp_path, text, name="c.toml"):
    p = tmp_path / name
    p.write_text(text, encoding="utf-8")
    return p


def test_show_prints_values_as_written_with_si_beside():
    r = cli("config", "show")
    assert r.exit_code == 0, r.output
    assert "0.3490658503988659" not in r.stdout  # was '0.3490658503988659 rad'
    data = tomllib.loads(r.stdout)
    pa = data["pair"]["pressure_angle"]
    assert pa["value"] == "20 deg" and pa["si"] == "0.3490658504 rad"
    assert pa["source"] == "paper Table 1" and pa["origin"] == "geardyn/cases/xue_howard.toml"
    assert data["pair"]["module"] == {"value": "6 mm", "si": "0.006 m",
                                      "source": "paper Table 1",
                                      "origin": "geardyn/cases/xue_howard.toml"}
    assert data["simulation"]["decimation"]["origin"] == "default"


def test_show_output_loads_back_to_the_same_case(tmp_path):
    r = cli("config", "show", "--set", "pinion.teeth=25", "--set", 'load.speed="1090 rpm"')
    assert r.exit_code == 0, r.output
    p = _case(tmp_path, r.stdout, "shown.toml")
    again = load_case(p)
    want = paper_case(["pinion.teeth=25", 'load.speed="1090 rpm"'])
    assert again.model_dump(exclude={"provenance"}) == want.model_dump(exclude={"provenance"})
    assert again.provenance["pinion.teeth"] == "--set"
    assert again.load.speed == pytest.approx(1090 * 2 * math.pi / 60, rel=1e-15)


def test_show_of_a_partial_file_marks_its_values(tmp_path):
    p = _case(tmp_path, 'name = "rig"\n[pair]\npressure_angle = "25 deg"\n')
    r = cli("config", "show", "--config", str(p))
    assert r.exit_code == 0, r.output
    data = tomllib.loads(r.stdout)
    assert data["name"] == "rig"
    assert data["pair"]["pressure_angle"]["value"] == "25 deg"
    assert data["pair"]["pressure_angle"]["origin"] == str(p)
    assert data["pair"]["module"]["origin"] == "geardyn/cases/xue_howard.toml"


@pytest.mark.parametrize(("text", "field"), [
    ('[crack]\ndepth = "50 mm"\n', "crack.depth"),                       # passed before
    ('[crack]\ndepth = "50 mm"\n[stiffness]\nmethod = "pem"\n', "crack.depth"),
    ('[stiffness.fe]\nmesh_size = "5 mm"\n', "stiffness.fe.mesh_size"),
    ('[stiffness]\ncentre_distance_max = "10 mm"\n', "stiffness.centre_distance_max"),
    ('[crack]\ntooth = 23\n', "crack.tooth"),
    ('[simulation]\nsettle_time = "1e6 s"\n', "simulation.settle_time"),
])
def test_validate_runs_the_physical_checks(tmp_path, text, field):
    p = _case(tmp_path, text)
    assert_clean_error(cli("config", "validate", str(p)), field)


def test_validate_accepts_the_paper_case_and_a_valid_partial_case(tmp_path):
    check_case(paper_case())
    p = _case(tmp_path, '[crack]\ndepth = "3 mm"\n')
    r = cli("config", "validate", str(p))
    assert r.exit_code == 0, r.output
    assert "valid" in r.stdout


def test_check_case_names_the_field():
    with pytest.raises(InputError) as exc:
        check_case(paper_case(['crack.depth="50 mm"']))
    assert exc.value.field == "crack.depth"


def test_a_fault_that_does_not_fit_is_shown_and_its_value_named_as_written():
    """``config show`` shows a case it would refuse, a fault that does not fit its tooth
    included (it exited 2 with no output, a user audit of 2026-11-27), and ``config validate``
    names the value as written with its SI value beside."""
    from pathlib import Path

    spall = str(Path(__file__).resolve().parents[2] / "examples" / "faults" / "spall.toml")
    r = cli("config", "show", "--config", spall, "--set", 'faults.0.width="30 mm"')
    assert r.exit_code == 0, r.output
    assert tomllib.loads(r.stdout)["faults"]["value"][0]["width"] == "30 mm"
    assert "note: this case does not pass 'geardyn config validate': faults[0].width: got " \
           "'30 mm (= 0.03 m)'" in r.stderr.replace("\n", " "), r.stderr
    r = cli("config", "validate", spall, "--set", 'faults.0.width="30 mm"')
    assert_clean_error(r, "faults[0].width")
    assert "got '30 mm (= 0.03 m)'" in r.stderr, r.stderr


def test_show_prints_faults_as_written_and_loads_back(tmp_path):
    """``[[faults]]`` values as the file wrote them ("3 deg", not 0.05235987755982989), and the
    printed case loads back to the same faults."""
    from pathlib import Path

    two = Path(__file__).resolve().parents[2] / "examples" / "faults" / "two_faults.toml"
    r = cli("config", "show", "--config", str(two))
    assert r.exit_code == 0, r.output
    spall = tomllib.loads(r.stdout)["faults"]["value"][0]
    assert spall["roll_length"] == "3 deg" and spall["depth"] == "0.1 mm", spall
    shown = _case(tmp_path, r.stdout, "shown.toml")
    assert load_case(shown).faults == load_case(two).faults


def test_every_command_names_a_faults_value_as_written_and_its_entry_one_way():
    """The commands that run a case (``load_case``, ``simulate``) name a fault's bad value as
    written with its SI value beside, as ``config validate`` does (they echoed the SI value
    alone: ``faults[0].angle: got 1.7453292519943295``), and the type checks name the entry as
    the faults' own checks do (``faults[0].front``, not ``faults.0.front``)."""
    from pathlib import Path

    growth = Path(__file__).resolve().parents[2] / "examples" / "faults" / "crack_growth.toml"
    with pytest.raises(InputError) as err:
        load_case(growth, ['faults.0.angle="100 deg"'])
    assert err.value.field == "faults[0].angle"
    assert err.value.value == f"100 deg (= {math.radians(100)!r} rad)"
    r = cli("simulate", "--config", str(growth), "--set", 'faults.0.depth="-1 mm"', "--out",
            "never.nc")
    assert_clean_error(r, "faults[0].depth")
    assert "got '-1 mm (= -0.001 m)'" in r.stderr, r.stderr
    for key, value, allowed in (("front", "wavy", "'uniform', 'linear' or 'parabolic'"),
                                ("colour", "red", "a known key")):
        with pytest.raises(InputError) as err:
            load_case(growth, [f'faults.0.{key}="{value}"'])
        assert err.value.field == f"faults[0].{key}", err.value
        assert err.value.allowed.startswith(allowed), err.value
    with pytest.raises(InputError, match=r"Allowed keys in faults\[0\]: angle,"):
        load_case(growth, ['faults.0.colour="red"'])


def test_show_says_which_field_of_a_fault_set_gave():
    """``--set faults.0.width`` was shown with the case file as the faults' origin (a user
    audit, 2026-11-27); ``--set motor.torque`` always said --set."""
    from pathlib import Path

    spall = str(Path(__file__).resolve().parents[2] / "examples" / "faults" / "spall.toml")
    r = cli("config", "show", "--config", spall, "--set", 'faults.0.width="4 mm"')
    assert r.exit_code == 0, r.output
    faults = tomllib.loads(r.stdout)["faults"]
    assert faults["origin"] == f"{spall}; faults.0.width from --set"
    assert faults["source"].endswith("; faults.0.width: --set")
    assert faults["value"][0]["width"] == "4 mm"
    r = cli("config", "show", "--config", spall)  # without --set: the file alone
    assert tomllib.loads(r.stdout)["faults"]["origin"] == spall
