"""``geardyn config schema`` describes the case *file* format that ``load_case`` reads: top-level
``extends``, ``{ value, source }`` tables, partial files over a base, unit strings (QA: every
shipped case file failed the schema with ``'extends' was unexpected``).

The checks use the ``jsonschema`` package (Draft 2020-12, the dialect pydantic writes), a test
dependency of geardyn (pyproject.toml's ``test`` extra).
"""

from __future__ import annotations

import json
import tomllib
from pathlib import Path

import jsonschema
import pytest

from geardyn.config import case_schema, case_to_toml, load_case, paper_case
from geardyn.errors import DataFileError, InputError

from ._cli import cli_proc

ROOT = Path(__file__).resolve().parents[2]


def _case_files() -> list[Path]:
    """Shipped case files: the package's cases and the examples' TOML files, not sweep specs."""
    files = sorted((ROOT / "src" / "geardyn" / "cases").glob("*.toml")) \
        + sorted((ROOT / "examples").rglob("*.toml"))
    return [f for f in files if not f.name.startswith("sweep_")]


CASE_FILES = _case_files()


@pytest.fixture(scope="module")
def validator():
    schema = json.loads(case_schema())
    cls = jsonschema.validators.validator_for(schema)
    cls.check_schema(schema)  # a valid JSON schema of its declared draft
    assert cls is jsonschema.Draft202012Validator
    return cls(schema)


def _errors(validator, data) -> list[str]:
    return [e.message for e in validator.iter_errors(data)]


def test_the_shipped_case_files_are_found():
    names = {str(f.relative_to(ROOT)) for f in CASE_FILES}
    assert "src/geardyn/cases/xue_howard.toml" in names
    assert "examples/measure/case.toml" in names and "examples/faults/spall.toml" in names
    assert len(names) >= 10
    assert not any("sweep_" in n for n in names)


@pytest.mark.parametrize("path", CASE_FILES, ids=lambda p: str(p.relative_to(ROOT)))
def test_every_shipped_case_file_validates(validator, path):
    load_case(path)  # a case file geardyn accepts ...
    data = tomllib.loads(path.read_text(encoding="utf-8"))
    assert _errors(validator, data) == []  # ... and so does the schema


def test_written_and_shown_cases_validate(validator):
    assert _errors(validator, tomllib.loads(case_to_toml(paper_case()))) == []
    r = cli_proc("config", "show", "--set", "pinion.teeth=25", "--set", 'load.speed="1090 rpm"')
    assert r.returncode == 0, r.stderr
    assert _errors(validator, tomllib.loads(r.stdout)) == []  # with its si and origin keys


def test_the_command_prints_the_file_schema():
    r = cli_proc("config", "schema")
    assert r.returncode == 0, r.stderr
    schema = json.loads(r.stdout)
    assert schema == json.loads(case_schema())
    assert schema["title"] == "Case"
    assert "extends" in schema["properties"]
    assert "required" not in schema  # a partial file may omit every section
    # quantities: a number in SI or a string with a unit, as the model's schema says
    module = schema["$defs"]["PairConfig"]["properties"]["module"]["anyOf"][0]
    assert module["x-unit"] == "m" and {"type": "string"} in module["anyOf"]


# Each text: (accepted by load_case, accepted by the schema) must agree.
ACCEPTED = {
    "one line": 'extends = "xue_howard"\n',
    "partial with units": 'extends = "xue_howard"\n[crack]\ndepth = "3 mm"\n'
                          '[simulation]\ndt = "5e-6 s"\n',
    "no extends (default base)": '[motor]\ntorque = "70 N m"\n',
    "sourced values": 'extends = "xue_howard"\n[pinion]\n'
                      'teeth = { value = 25, source = "drawing 12", note = "rev. B" }\n'
                      'mass = { value = "0.7 kg", source = "scale" }\n',
    "shown by config show": 'extends = "xue_howard"\n[pinion.mass]\nvalue = "0.7 kg"\n'
                            'si = "0.7 kg"\nsource = "scale"\norigin = "--set"\n',
    "provenance table": 'extends = "xue_howard"\n[provenance]\n"pinion.mass" = "scale"\n',
    "faults list": 'extends = "xue_howard"\n[[faults]]\ntype = "spall"\nstart = "20 mm"\n'
                   'length = "3 mm"\nwidth = "6 mm"\ndepth = "0.1 mm"\n',
    "sourced extends": 'extends = { value = "xue_howard", source = "the paper" }\n',
}
REJECTED = {
    "misspelt section": 'extends = "xue_howard"\n[pinon]\nteeth = 25\n',
    "misspelt key": 'extends = "xue_howard"\n[pinion]\nteth = 25\n',
    "misspelt key of a sourced value": 'extends = "xue_howard"\n[pinion]\n'
                                       'teeth = { value = 25, sorce = "x" }\n',
    "misspelt top-level key": 'extend = "xue_howard"\n',
    "text for a whole number": 'extends = "xue_howard"\n[pinion]\nteeth = "many"\n',
    "fraction for a whole number": 'extends = "xue_howard"\n[pinion]\nteeth = 23.5\n',
    "sourced value of the wrong type": 'extends = "xue_howard"\n[pinion]\n'
                                       'teeth = { value = "many", source = "x" }\n',
    "source that is not text": 'extends = "xue_howard"\n[pinion]\n'
                               'teeth = { value = 25, source = 5 }\n',
    "not a choice": 'extends = "xue_howard"\n[simulation]\nmodel = "III"\n',
    "table for a value": 'extends = "xue_howard"\n[crack]\nenabled = { on = true }\n',
    "extends true": 'extends = true\n',
    "extends empty": 'extends = ""\n',
    "complete file without sections": 'extends = false\n[pair]\nmodule = "6 mm"\n',
    "fault without a type": 'extends = "xue_howard"\n[[faults]]\ndepth = "1 mm"\n',
    "sourced value in the faults list": 'extends = "xue_howard"\n[[faults]]\ntype = "spall"\n'
                                        'depth = { value = "0.1 mm", source = "x" }\n',
}


def _loader_accepts(tmp_path, text: str) -> bool:
    p = tmp_path / "case.toml"
    p.write_text(text, encoding="utf-8")
    try:
        load_case(p)
    except (InputError, DataFileError):
        return False
    return True


@pytest.mark.parametrize("name", list(ACCEPTED))
def test_files_the_loader_accepts_validate(validator, tmp_path, name):
    text = ACCEPTED[name]
    assert _loader_accepts(tmp_path, text)
    assert _errors(validator, tomllib.loads(text)) == []


@pytest.mark.parametrize("name", list(REJECTED))
def test_misspelt_keys_and_wrong_types_are_rejected(validator, tmp_path, name):
    text = REJECTED[name]
    assert not _loader_accepts(tmp_path, text)
    assert _errors(validator, tomllib.loads(text)), name


def test_a_complete_file_must_hold_every_required_key(validator):
    data = tomllib.loads(case_to_toml(paper_case()))
    assert data["extends"] is False and _errors(validator, data) == []
    del data["pair"]["module"]
    assert _errors(validator, data)  # extends = false: nothing comes from a base
    data["extends"] = "xue_howard"
    assert _errors(validator, data) == []  # a partial file: module comes from the base
    del data["extends"]  # the default base
    assert _errors(validator, data) == []


def test_the_schema_is_the_same_every_time():
    """pydantic 2.6 (the floor) wrote a field's constraint into the quantity schema it was given,
    so a second call showed ``gt: 0`` on every length (the floors' run found the CLI's schema
    and the in-process one different); each quantity now gets its own copy."""
    from geardyn.config import case_file_schema

    first = json.dumps(case_file_schema(), sort_keys=True)
    assert json.dumps(case_file_schema(), sort_keys=True) == first
    depth = json.loads(first)["$defs"]["CrackConfig"]["properties"]["depth"]["anyOf"][0]
    assert depth["x-unit"] == "m" and "gt" not in depth and "exclusiveMinimum" not in depth
