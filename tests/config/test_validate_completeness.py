"""``geardyn config validate`` runs every check that ``simulate`` and ``measure`` make before
their first time step (QA: ``simulation.dt=5``, ``measurement.fs="10 Hz"`` and
``measurement.snr=-500`` were "valid", then refused by the commands), says what it cannot check
without an FE map, and a value set to what the case already has is no modification (QA:
``--set crack.depth="5 mm"`` marked the paper's case "(modified)")."""

from __future__ import annotations

import os
import tomllib
from pathlib import Path

import pytest
import tomli_w

from geardyn.cache import Cache
from geardyn.case_checks import check_case
from geardyn.config import case_to_toml, load_case, paper_case
from geardyn.errors import InputError

from .._cli_fork import run_geardyn
from ._cli import HANG_GUARD, assert_clean_error

PEM = 'stiffness.method="pem"'
CASE = str(Path(__file__).resolve().parents[2] / "src" / "geardyn" / "cases" / "xue_howard.toml")


def _geardyn(*args, cache_dir=None, cwd=None):
    env = dict(os.environ)
    if cache_dir is not None:
        env["GEARDYN_CACHE_DIR"] = str(cache_dir)
    return run_geardyn(list(args), env=env, cwd=cwd, timeout=HANG_GUARD)


def _sets(overrides):
    return [a for o in overrides for a in ("--set", o)]


# ---------------------------------------------------------------- the QA's commands
@pytest.mark.parametrize(("override", "field"), [
    ("simulation.dt=5", "simulation.dt"),
    ('measurement.fs="10 Hz"', "measurement.fs"),
    ("measurement.snr=-500", "measurement.snr"),
])
def test_the_qa_values_are_refused_for_the_shipped_case_without_an_fe_map(tmp_path, override,
                                                                         field):
    """The paper's case uses the FE method; an empty cache has no map, and these still fail."""
    r = _geardyn("config", "validate", CASE, "--set", override,
                 cache_dir=tmp_path / "cache")
    line = assert_clean_error(r, field)
    if field == "measurement.fs":
        assert "got '10 Hz'" in line  # the value as written
    assert not (tmp_path / "cache").exists() or not any((tmp_path / "cache").rglob("*.nc"))


def test_the_shipped_case_says_what_it_could_not_check_without_its_fe_map(tmp_path):
    r = _geardyn("config", "validate", CASE,
                 cache_dir=tmp_path / "cache")
    assert r.returncode == 0, r.stderr
    text = " ".join(r.stdout.split())
    assert text.startswith("valid:")
    assert "not checked: the FE map of this case is not in the cache" in text
    assert "time-step limit from the largest mesh stiffness" in text
    assert "geardyn stiffness" in text


def test_the_help_says_what_validate_does_not_check():
    r = _geardyn("config", "validate", "--help")
    assert r.returncode == 0, r.stderr
    text = " ".join(r.stdout.replace("│", " ").split())
    assert "every check that 'geardyn simulate' and 'geardyn measure' make before their first " \
           "time step, except FE computations" in text
    assert "Not checked: what only a simulation shows" in text
    assert "the checks that need the FE map run only if the map is in the cache" in text


# ---------------------------------------------------------------- validate == the commands
# (overrides of the paper's case with the PEM map, the command that refuses them before its
# first time step, the field named)
REFUSED = [
    (["simulation.dt=5"], "simulate", "simulation.dt"),
    (["simulation.dt=3e-5"], "simulate", "simulation.dt"),  # needs the map's largest stiffness
    (["mesh.friction_coefficient=0.1"], "simulate", "mesh.friction_coefficient"),
    (['stiffness.centre_distance_max="0.5 mm"'], "simulate", "stiffness.centre_distance_max"),
    (["motor.profile_times=[1.0, 0.5]", "motor.profile_speeds=[100.0, 120.0]"], "simulate",
     "motor.profile_times"),
    (['simulation.dynamics="transverse"', 'simulation.integrator="hht"'], "simulate",
     "simulation.integrator"),
    (['simulation.dynamics="transverse"', "pinion.bearing_stiffness_x=1e12"], "simulate",
     "simulation.dt"),  # the transverse model's x bearing mode
    (['measurement.fs="10 Hz"'], "measure", "measurement.fs"),
    (["measurement.snr=-500"], "measure", "measurement.snr"),
    # refused by measure only after the simulation before (the rate against 1/(dt decimation))
    (['measurement.fs="33.3333 kHz"'], "measure", "measurement.fs"),
    (["simulation.decimation=3"], "measure", "measurement.fs"),
]
_IDS = [" ".join(o) for o, _, _ in REFUSED]


@pytest.mark.parametrize(("overrides", "command", "field"), REFUSED, ids=_IDS)
def test_validate_refuses_what_the_commands_refuse(overrides, command, field):
    r = _geardyn("config", "validate", CASE, *_sets([PEM, *overrides]))
    assert_clean_error(r, f"error: {field}: got ")


@pytest.mark.slow
@pytest.mark.parametrize(("overrides", "command", "field"), REFUSED, ids=_IDS)
def test_the_commands_refuse_them_with_the_same_message(tmp_path, overrides, command, field):
    """The same field and the same 'allowed' text from the command (which refuses before its
    first time step: no output written) as from validate."""
    sets = _sets([PEM, *overrides])
    v = assert_clean_error(_geardyn("config", "validate", CASE, *sets))
    out = tmp_path / "out.nc"
    c = assert_clean_error(_geardyn(command, *sets, "--out", str(out), cwd=tmp_path))
    assert c.split(": got ")[0] == v.split(": got ")[0] == f"error: {field}"
    assert c.split("; allowed: ", 1)[1] == v.split("; allowed: ", 1)[1]
    assert not out.exists()


def test_a_valid_pem_case_is_checked_completely():
    r = _geardyn("config", "validate", CASE, "--set", PEM)
    assert r.returncode == 0, r.stderr
    assert r.stdout.startswith("valid:") and "not checked" not in r.stdout
    assert check_case(paper_case([PEM])) == []


# ---------------------------------------------------------------- an FE map in the cache
@pytest.fixture
def fe_cache(tmp_path, monkeypatch):
    """A cache holding the paper case's (cracked) "FE" map, made by the PEM code instead of
    the FE solver (seconds to minutes): what validate does with a map in the cache."""
    import geardyn.stiffness.fe as fe
    from geardyn.stiffness import build_map
    from geardyn.stiffness.pem import pem_map

    def fake_fe_map(case, dd, *, cracked, progress=None, **kw):
        return pem_map(case, dd, cracked=cracked)

    cache = Cache(tmp_path / "cache", enabled=True)
    with monkeypatch.context() as m:
        m.setattr(fe, "fe_map", fake_fe_map)
        build_map(paper_case(), method="fe", cracked=True, cache=cache)
    return cache


def test_a_cached_fe_map_gives_the_exact_time_step_limit(fe_cache, tmp_path):
    assert check_case(paper_case(), cache=fe_cache) == []  # every check ran
    coarse = ["simulation.dt=4e-5", 'measurement.fs="25 kHz"']  # the chain at the step's rate
    with pytest.raises(InputError) as exc:
        check_case(paper_case(coarse), cache=fe_cache)
    assert exc.value.field == "simulation.dt"
    assert "largest mesh stiffness" in exc.value.allowed
    # without the map: only the bound that needs no map (4e-5 s passes it), and a note
    empty = Cache(tmp_path / "empty", enabled=True)
    notes = check_case(paper_case(coarse), cache=empty)
    assert len(notes) == 1 and "time-step limit from the largest mesh stiffness" in notes[0]
    with pytest.raises(InputError, match="without mesh stiffness"):
        check_case(paper_case(["simulation.dt=2e-4"]), cache=empty)
    assert not any((tmp_path / "empty").rglob("*.nc"))  # nothing built or stored


def test_without_an_fe_map_the_static_range_is_still_checked(tmp_path):
    empty = Cache(tmp_path / "empty", enabled=True)
    with pytest.raises(InputError) as exc:
        check_case(paper_case(['stiffness.centre_distance_min="1.5 mm"']), cache=empty)
    assert exc.value.field == "stiffness.centre_distance_min"
    assert "static centre distance" in exc.value.allowed


def test_a_default_measurement_chain_that_measure_would_refuse_is_a_note():
    case = paper_case([PEM, "simulation.decimation=3"])  # 33 kHz < the chain's 50 kHz
    with pytest.raises(InputError, match="measurement.fs"):
        check_case(case)  # the case's own [measurement] section: an error
    notes = check_case(case.model_copy(update={"measurement": None}))
    assert len(notes) == 1 and "measurement.fs" in notes[0] and "geardyn measure" in notes[0]


# ---------------------------------------------------------------- "(modified)"
def _show(*overrides):
    r = _geardyn("config", "show", *_sets(overrides))
    assert r.returncode == 0, r.stderr
    return tomllib.loads(r.stdout)


@pytest.mark.parametrize("overrides", [
    ['crack.depth="5 mm"'],
    ["crack.depth=0.005"],                  # the same length in SI
    ['crack.depth="0.5 cm"', 'pair.pressure_angle="20 deg"'],
    ["simulation.decimation=1"],            # the built-in default, not written in the file
], ids=" ".join)
def test_setting_the_value_the_case_has_is_no_modification(overrides):
    data = _show(*overrides)
    assert data["name"] == "xue_howard"
    assert "[changed by" not in data["description"]
    key = overrides[0].split("=")[0].split(".")
    assert data[key[0]][key[1]]["origin"] == "--set"  # where it was given, all the same
    assert load_case(None, overrides).name == "xue_howard"


def test_only_real_changes_are_named():
    data = _show('crack.depth="5 mm"', 'crack.depth="3 mm"')  # the last one counts
    assert data["name"] == "xue_howard (modified)"
    data = _show('crack.depth="5 mm"', "pinion.teeth=25")
    assert data["name"] == "xue_howard (modified)"
    assert data["description"].endswith("[changed by --set: pinion.teeth]")
    r = _geardyn("config", "validate", CASE, "--set", 'crack.depth="5 mm"', "--set", PEM)
    assert r.returncode == 0 and "(xue_howard (modified), " in r.stdout  # the method changed
    r = _geardyn("config", "validate", CASE, "--set", 'crack.depth="5 mm"',
                 "--set", 'stiffness.method="fe"')
    assert r.returncode == 0 and "(xue_howard, " in r.stdout, r.stdout


def test_a_value_that_completes_a_partial_case_counts_as_a_change(tmp_path):
    """Without the overrides the file is no valid case: every override is a change."""
    p = tmp_path / "c.toml"
    p.write_text('extends = false\nname = "mine"\n' + _complete_without_crack_depth())
    c = load_case(p, ['crack.depth="5 mm"'])
    assert c.name == "mine (modified)" and c.crack.depth == pytest.approx(0.005)
    with pytest.raises(InputError, match="crack.depth"):
        load_case(p)


def _complete_without_crack_depth() -> str:
    data = tomllib.loads(case_to_toml(paper_case()))
    for k in ("name", "description", "extends"):
        data.pop(k)
    del data["crack"]["depth"]
    return tomli_w.dumps(data)
