"""The shipped transverse examples through the CLI (examples are tests): ``geardyn simulate`` on
examples/transverse/case.toml and ``geardyn sweep`` over the coefficient of friction."""

from __future__ import annotations

import os
from pathlib import Path

import numpy as np
import pytest

from .._cli_fork import run_geardyn

ROOT = Path(__file__).resolve().parents[2]
EXAMPLES = ROOT / "examples" / "transverse"


def _run(args, tmp_path, timeout=600):
    env = {**os.environ, "GEARDYN_CACHE_DIR": str(tmp_path / "cache")}
    return run_geardyn([*args], capture_output=True,
                       text=True, env=env, timeout=timeout, cwd=tmp_path)


@pytest.mark.slow
def test_simulate_the_example_case(tmp_path):
    """The record of the example case holds the transverse variables with units, the friction
    dissipates over the run and moves the centres across the line of action."""
    import xarray as xr

    out = tmp_path / "t.nc"
    r = _run(["simulate", "--config", str(EXAMPLES / "case.toml"), "--stiffness", "pem",
              "--set", "simulation.record_time=0.05 s", "--set", "simulation.settle_time=0.05 s",
              "--set", "stiffness.centre_distances=11", "--out", str(out)], tmp_path)
    assert r.returncode == 0, r.stderr
    with xr.open_dataset(out) as ds:
        assert ds.attrs["dynamics"] == "transverse"
        assert ds.attrs["friction_coefficient"] == 0.06
        assert ds["x_p"].attrs["units"] == "m"
        assert ds["x_p"].std() > 1e-6                      # friction drives x (about 24 um)
        assert float(ds["friction_power"].mean()) < 0


@pytest.mark.slow
def test_sweep_over_the_friction_coefficient(tmp_path):
    """The example sweep: 4 coefficients x models I-static / II; the centre distance's
    fluctuation grows with the friction (the x motion lies almost along the line of centres)."""
    from geardyn.studies.sweep import open_sweep

    store = tmp_path / "friction.zarr"
    r = _run(["sweep", str(EXAMPLES / "sweep_friction.toml"), "--out", str(store)], tmp_path,
             timeout=900)
    assert r.returncode == 0, r.stderr
    ds = open_sweep(store).load()
    assert np.all(ds.status.values == 1)
    for model in ("I-static", "II"):
        sel = ds["simulation.model"].values == model
        mu = ds["mesh.friction_coefficient"].values[sel]
        dd = ds["centre_distance_change__std"].values[sel][np.argsort(mu)]
        assert np.all(np.diff(dd) > 0), (model, dd)
