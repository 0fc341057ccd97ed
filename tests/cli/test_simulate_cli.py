"""``geardyn simulate`` as a user runs it: files, summary, errors, partial records."""

from __future__ import annotations

import os
import sys

import pytest
import xarray as xr

from .._cli_fork import run_geardyn

GEARDYN = [sys.executable, "-m", "geardyn"]
SHORT = ["--set", "simulation.settle_time=0.002", "--set", "simulation.record_time=0.004",
         "--set", "stiffness.centre_distances=6", "--set", "stiffness.nodes_per_segment=8",
         "--set", "stiffness.method=pem"]


def run(*args, cache):
    env = {**os.environ, "GEARDYN_CACHE_DIR": str(cache)}
    return run_geardyn(list(args), capture_output=True, text=True, env=env,
                       timeout=300)


@pytest.mark.slow
def test_simulate_writes_netcdf_and_mat(tmp_path):
    out = tmp_path / "sim.nc"
    r = run("simulate", "--model", "II", "--out", str(out), "--mat", *SHORT, cache=tmp_path / "c")
    assert r.returncode == 0, r.stderr
    assert "model II" in r.stdout and "contact ratio" in r.stdout and "um" in r.stdout
    assert (tmp_path / "sim.mat").stat().st_size > 1000
    with xr.open_dataset(out, engine="h5netcdf") as ds:
        assert ds.attrs["model"] == "II" and ds.attrs["complete"] == 1
        assert ds.sizes["time"] == 400
        assert ds["mesh_force"].attrs["units"] == "N"
        assert ds.attrs["stiffness_cracked"] == 1


@pytest.mark.slow
def test_simulate_model_i_without_crack(tmp_path):
    out = tmp_path / "a.nc"
    r = run("simulate", "-m", "i", "--no-crack", "-o", str(out), *SHORT, cache=tmp_path / "c")
    assert r.returncode == 0, r.stderr
    with xr.open_dataset(out, engine="h5netcdf") as ds:
        assert ds.attrs["model"] == "I" and ds.attrs["stiffness_cracked"] == 0


@pytest.mark.slow
def test_simulate_refuses_bad_input(tmp_path):
    r = run("simulate", "--set", "simulation.dt=1e-4", "-o", str(tmp_path / "x.nc"), *SHORT,
            cache=tmp_path / "c")
    assert r.returncode == 2
    assert "simulation.dt" in r.stderr and "Traceback" not in r.stderr
    assert not (tmp_path / "x.nc").exists()
    r = run("simulate", "--model", "III", cache=tmp_path / "c")
    assert r.returncode == 2 and "--model" in r.stderr


@pytest.mark.slow
def test_simulate_failure_writes_the_partial_record(tmp_path):
    out = tmp_path / "p.nc"
    r = run("simulate", "-m", "II", "-o", str(out), *SHORT,
            "--set", "simulation.settle_time=0", "--set", "simulation.tolerance=1e-18",
            "--set", "simulation.max_iterations=1", cache=tmp_path / "c")
    assert r.returncode == 2, r.stderr
    assert "did not converge" in r.stderr and "t = " in r.stderr
    with xr.open_dataset(out, engine="h5netcdf") as ds:
        assert ds.attrs["complete"] == 0 and ds.sizes["time"] >= 1
