"""The TOML writer (tomli-w, issue 17.2) and control characters refused at input (issue 19.4)."""

from __future__ import annotations

import string
import tomllib

import pytest

from geardyn.config import Case, case_to_toml, load_case, paper_case

from ._cli import assert_clean_error, cli

PRINTABLE = "".join(chr(i) for i in range(0x20, 0x7f)) + "\t"
NON_ASCII = "Zürich µm ° Ω — “quotes” ‘x’ 齿轮 שלום 🙂 \u00a0 \u2028 \ufeff é"
CONTROLS = [chr(i) for i in range(0x20) if i != 9] + ["\x7f", "\x85", "\x9b"]


def test_every_printable_and_non_ascii_string_round_trips(tmp_path):
    base = paper_case()
    prov = dict(base.provenance)
    prov["pair.module"] = PRINTABLE + NON_ASCII
    prov["pinion.mass"] = '"""' + "'''" + "\\u0000 \\n" + '\\"'
    case = base.model_copy(update={"name": PRINTABLE, "description": NON_ASCII + PRINTABLE,
                                   "provenance": prov})
    text = case_to_toml(case)
    data = tomllib.loads(text)  # the writer's text is valid TOML
    assert data["name"] == PRINTABLE and data["description"] == NON_ASCII + PRINTABLE
    assert data["pair"]["module"]["source"] == PRINTABLE + NON_ASCII
    p = tmp_path / "case.toml"
    p.write_text(text, encoding="utf-8")
    back = load_case(p)
    assert back == case
    assert back.provenance["pinion.mass"] == prov["pinion.mass"]


def test_writer_is_tomli_w(monkeypatch):
    """case_to_toml hands the escaping to tomli-w (the hand-written escaper wrote a DEL that
    tomllib then rejected)."""
    import tomli_w

    calls = []
    real = tomli_w.dumps
    monkeypatch.setattr(tomli_w, "dumps", lambda obj, **kw: calls.append(obj) or real(obj, **kw))
    case_to_toml(paper_case())
    assert calls and calls[0]["pair"]["module"] == {"value": "0.006 m",
                                                    "source": "paper Table 1"}


@pytest.mark.parametrize("ch", CONTROLS, ids=[f"U+{ord(c):04X}" for c in CONTROLS])
def test_control_characters_in_user_strings_are_refused_in_files(tmp_path, ch):
    esc = f"\\u{ord(ch):04X}"
    for field, text in [("description", f'description = "a{esc}b"\n'),
                        ("name", f'name = "a{esc}b"\n'),
                        ("pinion.mass.source",
                         f'[pinion]\nmass = {{ value = "0.7 kg", source = "x{esc}" }}\n')]:
        p = tmp_path / "ctl.toml"
        p.write_text(text, encoding="utf-8")
        assert_clean_error(cli("config", "validate", str(p)), field, "control characters",
                           f"U+{ord(ch):04X}")


@pytest.mark.parametrize("ch", ["\x01", "\x7f", "\x1b"])
def test_control_characters_in_set_values_are_refused(ch):
    assert_clean_error(cli("config", "show", "--set", f'name="a{ch}b"'), "name",
                       "control characters")
    assert_clean_error(cli("config", "show", "--set", f"description=a{ch}b"), "description")


def test_control_characters_refused_in_the_model_too():
    with pytest.raises(ValueError, match="control characters"):
        Case.model_validate({**paper_case().model_dump(), "name": "a\x7fb"})


def test_tab_and_printable_text_are_accepted():
    c = paper_case(['description="a\tb ' + string.ascii_letters + ' µ°"'])
    assert c.description.startswith("a\tb")


def test_non_utf8_bytes_in_a_set_value_are_refused():
    """A command-line byte that is not UTF-8 arrives as a lone surrogate: refused at input (it
    used to fail with UnicodeEncodeError after the work, when the case was saved)."""
    line = assert_clean_error(cli("config", "show", "--set", "name=a\udcffb"), "name", "UTF-8")
    assert "position 1" in line


def test_a_file_path_with_control_characters_gives_a_printable_source(tmp_path):
    p = tmp_path / "odd\nname.toml"
    p.write_text('[pinion]\nteeth = 25\n', encoding="utf-8")
    c = load_case(p)
    assert "\n" not in c.provenance["pinion.teeth"] and "odd?name" in c.provenance["pinion.teeth"]
    back = tmp_path / "back.toml"
    back.write_text(case_to_toml(c), encoding="utf-8")
    assert load_case(back) == c
