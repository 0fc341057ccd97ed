"""What a new user meets first: --version, -h everywhere, clean help texts, case-insensitive
choices, one stiffness default (the case's), Python warnings as one clean line (issue 13)."""

from __future__ import annotations

import os
import re
import signal
import subprocess
import sys
import time

import numpy as np
import pytest

import geardyn

from .._cli_fork import run_geardyn

GEARDYN = [sys.executable, "-m", "geardyn"]
COMMANDS = [["run"], ["geometry"], ["stiffness"], ["simulate"], ["diagnose"], ["sweep"],
            ["config"], ["config", "show"], ["config", "validate"], ["config", "schema"]]


def run(*args, env=None, **kw):
    return run_geardyn(list(args), capture_output=True, text=True, timeout=300,
                       env={**os.environ, "COLUMNS": "80", **(env or {})}, **kw)


@pytest.mark.parametrize("flag", ["--version", "-V"])
def test_version(flag):
    r = run(flag)
    assert r.returncode == 0, r.stderr
    assert r.stdout.strip() == f"geardyn {geardyn.__version__}"


# the top-level help in the fast tier, every subcommand's (20 subprocesses) in the slow tier
@pytest.mark.parametrize("command", [[]] + [pytest.param(c, marks=pytest.mark.slow) for c in COMMANDS],
                         ids=lambda c: " ".join(c) or "geardyn")
def test_short_help_on_every_command_without_bool_metavars_or_stray_spaces(command):
    short, long_ = run(*command, "-h"), run(*command, "--help")
    assert short.returncode == 0 and long_.returncode == 0, short.stderr
    assert short.stdout == long_.stdout and "Usage:" in short.stdout
    text = short.stdout
    assert "<bool>" not in text
    # no space before punctuation (rich markup used to eat "[s]" in "pulse times [s].")
    assert not re.search(r"\w \.(\s|$)", text), text
    assert "{file}" not in text and "{sweep_file}" not in text  # arguments named in capitals


def test_units_in_square_brackets_survive_in_help():
    r = run("diagnose", "-h")
    assert "pulse times [s]" in " ".join(r.stdout.replace("│", " ").split())


@pytest.mark.slow
def test_choices_are_case_insensitive(tmp_path):
    env = {"GEARDYN_CACHE_DIR": str(tmp_path / "c")}
    short = ["--set", "simulation.settle_time=0.002", "--set", "simulation.record_time=0.004",
             "--set", "stiffness.centre_distances=6", "--set", "stiffness.nodes_per_segment=8"]
    r = run("simulate", "--model", "ii", "--stiffness", "PEM", "-o", str(tmp_path / "s.nc"),
            *short, env=env)
    assert r.returncode == 0, r.stderr
    assert "model II" in r.stdout
    bad = run("run", "--stiffness", "magic", "--out", str(tmp_path / "unused"))
    assert bad.returncode == 2 and "--stiffness" in bad.stderr and "any case" in bad.stderr
    assert not (tmp_path / "unused").exists()


@pytest.mark.slow
@pytest.mark.parametrize(("case_method", "option", "processes", "expected"), [
    ("fe", [], "1", "fe map, healthy"),
    ("fe", [], "0", "fe map, faulty bodies first"),
    ("pem", [], "0", "pem map, healthy"),
    ("pem", ["--method", "FE"], "1", "fe map, healthy"),
])
def test_stiffness_uses_the_case_method_unless_told(tmp_path, case_method, option, processes,
                                                    expected):
    """The first stage the command starts names the method (read from the readiness file, then
    the command is stopped: no need to build an FE map to know which method it builds). In one
    process (``GEARDYN_FE_PROCESSES=0``) the FE map's faulty bodies come first."""
    ready = tmp_path / "ready"
    env = {**os.environ, "GEARDYN_CACHE_DIR": str(tmp_path / "c"),
           "GEARDYN_TEST_READY_FILE": str(ready), "GEARDYN_FE_PROCESSES": processes}
    p = subprocess.Popen(GEARDYN + ["stiffness", "--out", str(tmp_path / "k"), "--set",
                                    f"stiffness.method={case_method}", *option],
                         env=env, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    t0 = time.time()
    while not (ready.exists() and ready.read_text().strip()):
        assert p.poll() is None, p.communicate()[1]
        assert time.time() - t0 < 120
        time.sleep(0.02)
    p.send_signal(signal.SIGINT)
    p.communicate(timeout=120)
    assert ready.read_text().splitlines()[0] == expected


@pytest.mark.slow
def test_python_warnings_are_one_clean_line(tmp_path):
    """A diagnostics warning (too few revolutions to average) is printed as "warning (...): ..."
    on one line, without the source path and code line Python's default shows."""
    t = np.linspace(0, 0.1, 3000, endpoint=False)  # 1.8 revolutions
    th = 2 * np.pi * 18 * t
    np.savetxt(tmp_path / "m.csv", np.column_stack([t, th, np.cos(23 * th)]), delimiter=",",
               header="t,angle,acc", comments="")
    r = run("diagnose", str(tmp_path / "m.csv"), "--time", "t", "--angle", "angle", "--signal",
            "acc", "--no-figures", "--set", "diagnostics.samples_per_rev=512",
            env={"GEARDYN_CACHE_DIR": str(tmp_path / "c")})
    warn = [ln for ln in r.stderr.splitlines() if ln.startswith("warning")]
    assert r.returncode == 0, r.stderr
    assert any("revolution" in ln for ln in warn), r.stderr
    assert ".py:" not in r.stderr and "warnings.warn" not in r.stderr
    assert all(len(ln) < 500 for ln in warn)


@pytest.mark.parametrize("value", ["2", "yes"])
def test_a_bad_second_process_setting_is_a_user_error_before_any_output(tmp_path, value):
    """``GEARDYN_FE_PROCESSES`` (read by every ``geardyn run`` since the figures may use a
    second process): a bad value exits 2 with one line naming it, before the folder exists."""
    out = tmp_path / "out"
    r = run_geardyn(["run", "--quick", "--stiffness", "pem", "--out", str(out)],
                    capture_output=True, text=True, timeout=300,
                    env={**os.environ, "GEARDYN_FE_PROCESSES": value,
                         "GEARDYN_CACHE_DIR": str(tmp_path / "cache")})
    assert r.returncode == 2, r.stderr
    assert "GEARDYN_FE_PROCESSES" in r.stderr and repr(value) in r.stderr
    assert "Traceback" not in r.stderr and "internal error" not in r.stderr
    assert len(r.stderr.strip().splitlines()) == 1, r.stderr
    assert not out.exists()
