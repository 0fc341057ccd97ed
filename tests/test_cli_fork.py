"""The forked CLI runner of the tests (``tests/_cli_fork.py``) behaves as ``python -m geardyn``:
the same exit code, standard output and standard error, the environment and working folder it
is given, a timeout that kills, and a real subprocess where a library reads the environment at
import time."""

from __future__ import annotations

import os
import subprocess
import sys

import pytest

from ._cli_fork import _forkable, run_geardyn

CASES = [
    ["--version"],
    ["config", "validate", "no_such_file.toml"],
    ["simulate", "--set", "pinion.bogus=1"],
    ["config", "show", "--set", "motor.torque=70 N m"],
]


@pytest.mark.parametrize("args", CASES, ids=lambda a: " ".join(a))
def test_same_result_as_a_fresh_interpreter(args, tmp_path):
    env = {**os.environ, "COLUMNS": "72"}
    forked = run_geardyn(args, env=env, cwd=tmp_path, timeout=120)
    fresh = subprocess.run([sys.executable, "-m", "geardyn", *args], capture_output=True,
                           text=True, env=env, cwd=tmp_path, timeout=120,
                           stdin=subprocess.DEVNULL)
    assert (forked.returncode, forked.stdout, forked.stderr) == \
        (fresh.returncode, fresh.stdout, fresh.stderr)


def test_environment_and_folder_reach_the_command(tmp_path):
    """The child's environment is the one given (a cache folder read at call time) and a
    relative path resolves in the given folder."""
    (tmp_path / "mine.toml").write_text('[motor]\ntorque = "70 N m"\n')
    r = run_geardyn(["config", "validate", "mine.toml"], cwd=tmp_path, timeout=120)
    assert r.returncode == 0, r.stderr
    r = run_geardyn(["cache", "info"], timeout=120,
                    env={**os.environ, "GEARDYN_CACHE_DIR": str(tmp_path / "c")})
    assert r.returncode == 0 and str(tmp_path / "c") in r.stdout.replace("\n", ""), r.stdout


def test_a_timeout_kills_the_command(tmp_path):
    with pytest.raises(subprocess.TimeoutExpired):
        run_geardyn(["simulate", "--stiffness", "pem", "--out", str(tmp_path / "s.nc")],
                    timeout=0.3)
    assert run_geardyn(["--version"], timeout=60).returncode == 0  # the server still serves


def test_import_time_variables_fall_back_to_a_subprocess():
    assert _forkable(dict(os.environ))
    assert not _forkable({**os.environ, "NUMBA_DISABLE_JIT": "1"})
    assert not _forkable({**os.environ, "PYTHONHASHSEED": "1"})
    assert _forkable({**os.environ, "PYTHONPATH": "/somewhere", "GEARDYN_PROGRESS": "1"})
