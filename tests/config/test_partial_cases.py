"""Partial case files over a base case (issue 13), through ``geardyn config`` and the library."""

from __future__ import annotations

import math
import tomllib

import pytest

from geardyn.config import load_case, paper_case

from ._cli import assert_clean_error, cli


def _write(path, text):
    path.write_text(text, encoding="utf-8")
    return path


def test_a_partial_file_extends_the_paper_case(tmp_path):
    """Only the changed value is given: today this failed with 'required field is missing'."""
    p = _write(tmp_path / "shallow.toml", '[crack]\ndepth = "2 mm"\n')
    r = cli("config", "validate", str(p))
    assert r.exit_code == 0, r.output
    assert "valid" in r.stdout
    c = load_case(p)
    paper = paper_case()
    assert c.crack.depth == pytest.approx(2e-3, rel=1e-15)
    assert c.pair == paper.pair and c.pinion == paper.pinion and c.load == paper.load
    # provenance: base values keep their source, the file's value names the file
    assert c.provenance["pair.module"] == "paper Table 1"
    assert c.provenance["crack.depth"] == str(p)
    # the case keeps its own name, not the paper's
    assert c.name == "shallow" and "xue_howard" in c.description
    assert "Xue & Howard (2018) case study" not in c.description


def test_explicit_extends_and_own_sources(tmp_path):
    p = _write(tmp_path / "mine.toml", 'extends = "xue_howard"\nname = "my rig"\n'
               '[pinion]\nteeth = { value = 25, source = "rig drawing 7" }\n')
    c = load_case(p)
    assert c.name == "my rig" and c.pinion.teeth == 25 and c.gear.teeth == 23
    assert c.provenance["pinion.teeth"] == "rig drawing 7"
    assert c.provenance["gear.teeth"] == "paper Table 1"


def test_extends_a_file_relative_to_the_extending_file(tmp_path):
    sub = tmp_path / "bases"
    sub.mkdir()
    base = _write(sub / "base.toml", '[pinion]\nteeth = 25\n[load]\nspeed = "1000 rpm"\n')
    top = _write(sub / "top.toml", 'extends = "base.toml"\n[crack]\ndepth = "1 mm"\n')
    c = load_case(top)
    assert c.pinion.teeth == 25 and c.crack.depth == pytest.approx(1e-3)
    assert c.load.speed == pytest.approx(1000 * 2 * math.pi / 60, rel=1e-12)
    assert c.provenance["pinion.teeth"] == str(base)  # from the base file, named as such
    assert c.provenance["crack.depth"] == str(top)
    assert c.provenance["pair.module"] == "paper Table 1"
    assert c.name == "top"


def test_extends_cycle_is_refused(tmp_path):
    _write(tmp_path / "a.toml", 'extends = "b.toml"\n')
    _write(tmp_path / "b.toml", 'extends = "a.toml"\n')
    assert_clean_error(cli("config", "validate", str(tmp_path / "a.toml")), "extends", "cycle")
    _write(tmp_path / "self.toml", 'extends = "self.toml"\n')
    assert_clean_error(cli("config", "validate", str(tmp_path / "self.toml")), "cycle")


def test_extends_unknown_names_the_choices(tmp_path):
    p = _write(tmp_path / "x.toml", 'extends = "xue_haward"\n')
    assert_clean_error(cli("config", "validate", str(p)), "extends", "xue_howard")
    p = _write(tmp_path / "y.toml", 'extends = 3\n')
    assert_clean_error(cli("config", "validate", str(p)), "extends")


def test_extends_false_is_a_complete_case(tmp_path):
    p = _write(tmp_path / "alone.toml", 'extends = false\n[crack]\ndepth = "2 mm"\n')
    assert_clean_error(cli("config", "validate", str(p)), "missing")


@pytest.mark.parametrize(("text", "override"), [
    ("[pinion]\ntooth = 3\n", "pinion.tooth=3"),
    ("[pinon]\nteeth = 3\n", "pinon=3"),
    ("[stiffness.fe]\nmesh_sise = \"1 mm\"\n", "stiffness.fe.mesh_sise=1"),
])
def test_misspelt_key_gets_the_same_message_as_set(tmp_path, text, override):
    p = _write(tmp_path / "typo.toml", text)
    from_file = assert_clean_error(cli("config", "validate", str(p)), "unknown key",
                                   "Allowed keys")
    from_set = assert_clean_error(cli("config", "show", "--set", override), "unknown key")
    assert from_file.split("allowed:", 1)[1] == from_set.split("allowed:", 1)[1]
    assert "more problem" not in from_file  # one problem, not '(and 11 more problems)'


def test_set_overrides_are_marked_with_their_origin():
    r = cli("config", "show", "--set", "pinion.teeth=25")
    assert r.exit_code == 0, r.output
    data = tomllib.loads(r.stdout)
    assert data["pinion"]["teeth"] == {"value": 25, "source": "--set", "origin": "--set"}
    assert data["gear"]["teeth"]["source"] == "paper Table 1"
    assert data["gear"]["teeth"]["origin"] == "geardyn/cases/xue_howard.toml"
    assert data["name"] == "xue_howard (modified)"  # no longer the paper's case by name
    c = paper_case(["pinion.teeth=25"])
    assert c.provenance["pinion.teeth"] == "--set"


def test_a_case_without_crack_round_trips_without_regaining_the_base_crack(tmp_path):
    from geardyn.config import Case, case_to_toml

    data = paper_case().model_dump(exclude={"crack"})
    c = Case.model_validate(data)
    assert c.crack is None
    p = _write(tmp_path / "nocrack.toml", case_to_toml(c))
    c2 = load_case(p)
    assert c2.crack is None
    assert c2.pinion == c.pinion and c2.simulation == c.simulation


def test_misspelt_key_in_a_value_source_table_is_named(tmp_path):
    p = _write(tmp_path / "t.toml", '[pinion]\nmass = { value = "0.7 kg", sorce = "x", '
                                    'source = "y" }\n')
    assert_clean_error(cli("config", "validate", str(p)), "pinion.mass.sorce", "unknown key")
