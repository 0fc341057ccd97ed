"""``geardyn measure`` as a user runs it, then ``geardyn diagnose`` on its files as on measured
data (tachometer channel, no hint that the file came from geardyn)."""

from __future__ import annotations

import json
import os
import sys

import pytest
import xarray as xr

from .._cli_fork import run_geardyn

pytestmark = pytest.mark.slow  # each command starts a Python process (seconds under load)

GEARDYN = [sys.executable, "-m", "geardyn"]
SHORT = ["--stiffness", "pem", "--set", "simulation.settle_time=0.05",
         "--set", "simulation.record_time=0.25", "--set", "stiffness.centre_distances=6",
         "--set", "stiffness.nodes_per_segment=8"]


def run(*args, cache, cwd=None):
    env = {**os.environ, "GEARDYN_CACHE_DIR": str(cache)}
    return run_geardyn(list(args), capture_output=True, text=True, env=env,
                       timeout=600, cwd=cwd)


@pytest.mark.slow
def test_measure_writes_three_formats_and_diagnose_reads_them(tmp_path):
    out = tmp_path / "rec.nc"
    r = run("measure", "--model", "I", "--no-crack", "--out", str(out), "--csv", "--mat", *SHORT,
            cache=tmp_path / "c")
    assert r.returncode == 0, r.stderr
    assert "12500 samples at 50000 Hz" in r.stdout
    with xr.open_dataset(out, engine="h5netcdf") as ds:
        assert ds.sizes["time"] == 12_500 and ds.attrs["fs"] == 50_000.0
        assert ds.attrs["simulation_model"] == "I" and ds.attrs["stiffness_cracked"] == 0
        assert set(ds.data_vars) == {"acc", "acc_g", "tach"}
        # every numeric attribute with its unit beside it, as fs (a user audit, 2026-11-27)
        assert ds.attrs["noise_rms_units"] == "m/s^2" and ds.attrs["snr_requested_units"] == "dB"
        for k in ("lead_in", "tail", "tach_jitter", "start_time_in_simulation"):
            assert ds.attrs[f"{k}_units"] == "s", k
        assert ds.attrs["input_sample_rate_units"] == "Hz"
    kurt = {}
    for name, extra in (("rec.nc", []), ("rec.csv", ["--fs", "50000"]), ("rec.mat", [])):
        d = tmp_path / f"diag-{name}"
        r = run("diagnose", str(tmp_path / name), "--signal", "acc", "--tach", "tach", "--teeth",
                "23", "--no-figures", "-o", str(d), *extra, cache=tmp_path / "c")
        assert r.returncode == 0, r.stderr
        metrics = json.loads((d / "metrics.json").read_text())
        sig = metrics["signals"]["acc"]
        assert sig["n_averages"] >= 3
        kurt[name] = sig["kurtosis"]["tsa"]
    assert kurt["rec.csv"] == pytest.approx(kurt["rec.nc"], rel=1e-9)
    assert kurt["rec.mat"] == pytest.approx(kurt["rec.nc"], rel=1e-9)

    # the CSV and MATLAB copies are formats, not inputs: the same command without them is up
    # to date (it was refused as "csv True -> False", a user audit of 2026-11-27), and with
    # them again, where they were removed, writes them from the record, as the run wrote them
    import numpy as np
    from scipy.io import loadmat

    csv, mat = (tmp_path / "rec.csv").read_bytes(), loadmat(tmp_path / "rec.mat")
    base = ["measure", "--model", "I", "--no-crack", "--out", str(out), *SHORT]
    again = run(*base, cache=tmp_path / "c")
    assert again.returncode == 0 and "up to date (same inputs)" in again.stderr, again.stderr
    (tmp_path / "rec.csv").unlink()
    (tmp_path / "rec.mat").unlink()
    nc = out.read_bytes()
    again = run(*base, "--csv", "--mat", cache=tmp_path / "c")
    assert again.returncode == 0, again.stderr
    assert "wrote" in again.stderr and out.read_bytes() == nc  # the record itself untouched
    assert (tmp_path / "rec.csv").read_bytes() == csv
    mat2 = loadmat(tmp_path / "rec.mat")
    for key in ("time", "acc", "acc_g", "tach", "fs"):
        np.testing.assert_array_equal(mat2[key], mat[key], err_msg=key)
    for field in mat["attrs"].dtype.names:  # numbers stay numbers when read back from NetCDF
        a, b = mat["attrs"][0, 0][field], mat2["attrs"][0, 0][field]
        assert a.dtype == b.dtype and np.array_equal(a, b), field


@pytest.mark.parametrize("setting, field", [
    ("measurement.fs=5000", "measurement.fs"),
    ("measurement.snr=-3", "measurement.snr"),
    ("measurement.antialias_cutoff=40000", "measurement.antialias_cutoff"),
])
def test_measure_refuses_bad_chain_settings_before_simulating(tmp_path, setting, field):
    out = tmp_path / "x.nc"
    r = run("measure", "--set", setting, "-o", str(out), *SHORT, cache=tmp_path / "c")
    assert r.returncode == 2
    assert field in r.stderr and "Traceback" not in r.stderr
    assert not out.exists()
