"""The forked CLI runner of the tests (``tests/_cli_fork.py``) behaves as ``python -m geardyn``:
the same exit code, standard output and standard error, the environment and working folder it
is given, a timeout that kills, and a real subprocess where a library reads the environment at
import time."""

from __future__ import annotations

import os
import subprocess
import sys

import numpy as np
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
    """A command far longer than its timeout is killed when the timeout expires: 600 s of
    settling (not recorded, so the command holds 275 MB) took 17.7 s as a fresh command on the
    2-core machine (2026-11-27). The default 1 s record finished within 0.3 s in a warm fork
    server and the timeout never fired; a long record would hold gigabytes (60 s: 2.4 GB)."""
    long = ["simulate", "--stiffness", "pem", "--set", "simulation.settle_time=600 s",
            "--set", "simulation.record_time=0.01 s", "--out", str(tmp_path / "s.nc")]
    with pytest.raises(subprocess.TimeoutExpired):
        r = run_geardyn(long, timeout=1.0)
        pytest.fail(f"finished within 1 s: exit {r.returncode}, {r.stderr[-2000:]}")
    assert not (tmp_path / "s.nc").exists()  # killed before it wrote its result
    assert run_geardyn(["--version"], timeout=60).returncode == 0  # the server still serves


def test_import_time_variables_fall_back_to_a_subprocess():
    assert _forkable(dict(os.environ))
    assert not _forkable({**os.environ, "NUMBA_DISABLE_JIT": "1"})
    assert not _forkable({**os.environ, "PYTHONHASHSEED": "1"})
    assert _forkable({**os.environ, "PYTHONPATH": "/somewhere", "GEARDYN_PROGRESS": "1"})
    assert not _forkable({**os.environ, "HDF5_PLUGIN_PATH": "/my/plugins"})


@pytest.mark.slow
def test_a_kernel_run_written_to_netcdf_is_the_same_as_from_a_fresh_interpreter(tmp_path):
    """What the server loads before forking (numba's registries, pint, dask.distributed, which
    xarray imports to write NetCDF) changes nothing a command computes or writes: a short
    ``simulate`` (the compiled time-step kernel, units, a NetCDF record) forked and fresh give
    the same exit code, output and variables, bit for bit."""
    import xarray as xr

    short = ["simulate", "--stiffness", "pem", "--force",
             "--set", "simulation.settle_time=0.002 s", "--set", "simulation.record_time=0.004 s",
             "--set", "stiffness.centre_distances=11", "--set", "stiffness.nodes_per_segment=8"]
    env = {**os.environ, "COLUMNS": "72", "GEARDYN_PROGRESS": "0"}
    # names of one length: the output names the file, and rich wraps the path at 72 columns
    # (where depends on tmp_path's length; with names of different lengths the two outputs
    # once wrapped at different places, "f" + "resh.nc")
    forked = run_geardyn([*short, "--out", str(tmp_path / "forked.nc")], env=env, cwd=tmp_path,
                         timeout=300)
    fresh = subprocess.run([sys.executable, "-m", "geardyn", *short, "--out",
                            str(tmp_path / "fresh_.nc")], capture_output=True, text=True, env=env,
                           cwd=tmp_path, timeout=300, stdin=subprocess.DEVNULL)
    assert forked.returncode == fresh.returncode == 0, (forked.stderr, fresh.stderr)
    assert forked.stdout.replace("forked", "X") == fresh.stdout.replace("fresh_", "X")
    with xr.open_dataset(tmp_path / "forked.nc") as a, xr.open_dataset(tmp_path / "fresh_.nc") as b:
        assert sorted(a.variables) == sorted(b.variables) and a.sizes["time"] > 10
        for name in a.variables:
            np.testing.assert_array_equal(a[name].values, b[name].values, err_msg=name)
            assert a[name].attrs == b[name].attrs, name
