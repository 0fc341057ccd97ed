"""The command-line tool as a user runs it: exit codes, messages, no tracebacks."""

from __future__ import annotations

import json
import sys

import pytest

from .._cli_fork import run_geardyn

GEARDYN = [sys.executable, "-m", "geardyn"]


def run(*args, cwd=None, timeout=120):
    return run_geardyn(list(args), capture_output=True, text=True, cwd=cwd,
                       timeout=timeout)


def test_help_lists_commands():
    r = run("--help")
    assert r.returncode == 0
    for cmd in ("run", "geometry", "config"):
        assert cmd in r.stdout


def test_geometry_json_at_operating_point():
    r = run("geometry", "--centre-distance-change", "1.07mm", "--json")
    assert r.returncode == 0, r.stderr
    s = json.loads(r.stdout)
    assert s["operating"]["pressure_angle_deg"] == pytest.approx(21.178, abs=1e-3)
    assert s["operating"]["contact_ratio"]["paper_eq8"] == pytest.approx(1.4308, abs=1e-4)
    assert s["operating"]["contact_ratio"]["physical"] == pytest.approx(1.4198, abs=1e-4)


@pytest.mark.slow
def test_geometry_table():
    r = run("geometry")
    assert r.returncode == 0
    assert "1.5916" in r.stdout and "138.0000" in r.stdout and "[mm]" in r.stdout


@pytest.mark.slow
@pytest.mark.parametrize(("args", "words"), [
    (["geometry", "--set", "pinion.teeth=-3"], "pinion.teeth"),
    (["geometry", "--set", "pinion.teeth=22.5"], "pinion.teeth"),
    (["geometry", "--set", "pinion.tooth=3"], "unknown key"),
    (["geometry", "--set", "pair.pressure_angle=50deg"], "pressure_angle"),
    (["geometry", "--set", "pinion.mass=3 m"], "pinion.mass"),
    (["geometry", "--centre-distance-change", "5mm"], "contact ratio >= 1"),
    (["config", "validate", "/no/such/case.toml"], "no such file"),
    (["run", "--stiffness", "magic", "--out", "unused"], "--stiffness"),
])
def test_bad_input_exits_2_with_one_clear_line(args, words):
    r = run(*args)
    assert r.returncode == 2
    assert words in r.stderr
    assert "Traceback" not in r.stderr + r.stdout


@pytest.mark.slow
def test_config_show_round_trips(tmp_path):
    r = run("config", "show", "--set", "pinion.teeth=25")
    assert r.returncode == 0
    p = tmp_path / "c.toml"
    p.write_text(r.stdout)
    v = run("config", "validate", str(p))
    assert v.returncode == 0 and "valid" in v.stdout
    # the override is marked with its origin (issue 13; it used to lose its provenance)
    assert "[pinion.teeth]\nvalue = 25\nsource = \"--set\"" in r.stdout
    assert 'source = "paper Table 1"' in r.stdout


def test_config_schema():
    r = run("config", "schema")
    assert r.returncode == 0 and json.loads(r.stdout)["title"] == "Case"


@pytest.mark.slow
def test_run_writes_the_geometry_stage(tmp_path):
    out = tmp_path / "out"
    r = run("run", "--out", str(out), "--quick", "--stiffness", "pem", "--set",
            "simulation.record_time=0.1 s", "--set", "diagnostics.samples_per_rev=512",
            timeout=900)
    assert r.returncode == 0, r.stderr
    s = json.loads((out / "summary.json").read_text())
    assert s["centre_distance_change_mm"] == pytest.approx(1.0852, abs=1e-4)
    assert s["contact_ratio"]["paper_eq8"] == pytest.approx(1.4286, abs=1e-4)
    assert (out / "geometry.json").exists() and (out / "case.toml").exists()
    assert not list(out.glob(".*tmp*"))  # no temporary files left behind


@pytest.mark.parametrize("words, cword, expected", [
    ("geardyn ru", 1, ["run"]),
    ("geardyn run --qu", 2, ["--quick"]),
    ("geardyn cache c", 2, ["clear"]),
])
def test_tab_completion_answers_commands_and_options(words, cword, expected):
    """The shell's Tab asks the console script through click's completion protocol (the script
    ``geardyn --install-completion`` installs, which ``--show-completion`` prints)."""
    import os
    import subprocess
    from pathlib import Path

    exe = Path(sys.executable).with_name("geardyn")
    env = dict(os.environ, _GEARDYN_COMPLETE="complete_bash", COMP_WORDS=words,
               COMP_CWORD=str(cword))
    r = subprocess.run([str(exe)], env=env, capture_output=True, text=True, timeout=120)
    assert r.returncode == 0, r.stderr
    assert r.stdout.split() == expected
    script = subprocess.run([str(exe), "--show-completion", "bash"], capture_output=True,
                            text=True, timeout=120)
    assert script.returncode == 0, script.stderr
    assert "_GEARDYN_COMPLETE=complete_bash" in script.stdout
