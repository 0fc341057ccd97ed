"""``geardyn static-te`` and ``geardyn measure`` write one file (and companions): the same
command again finds it up to date, other inputs are refused naming what changed, --force
recomputes, a file geardyn did not write is not replaced (the QA walkthrough found a re-run of
the same static-te refused with "it exists; pass --force", against its own --help). And
static-te of a case whose fault is not a [crack] (a spall) computed the healthy pair and refused
--crack."""

from __future__ import annotations

import os

import pytest
import xarray as xr

from .._cli_fork import run_geardyn

EXAMPLES = os.path.join(os.path.dirname(__file__), "..", "..", "examples", "faults")
SMALL = ["--stiffness", "pem", "--points", "256", "--set", "stiffness.centre_distances=6",
         "--set", "stiffness.nodes_per_segment=8"]


def _run(tmp_path, *args):
    env = {**os.environ, "GEARDYN_CACHE_DIR": str(tmp_path / "cache")}
    return run_geardyn([*map(str, args)], capture_output=True, text=True, env=env, timeout=300)


@pytest.mark.slow
def test_static_te_rerun_other_inputs_force_and_foreign_files(tmp_path):
    out = tmp_path / "te.nc"
    r = _run(tmp_path, "static-te", *SMALL, "--out", out)
    assert r.returncode == 0, r.stderr
    before = out.read_bytes()
    r = _run(tmp_path, "static-te", *SMALL, "--out", out)
    assert r.returncode == 0, r.stderr
    assert "up to date (same inputs)" in r.stderr and out.read_bytes() == before
    assert "T = 100 N m: mean" in r.stdout  # the result is still reported
    r = _run(tmp_path, "static-te", *SMALL, "--torque", "50", "--out", out)
    assert r.returncode == 2 and "holds results of different inputs (torque_N_m 100.0 -> 50.0)" \
        in r.stderr, r.stderr
    r = _run(tmp_path, "static-te", *SMALL, "--torque", "50", "--force", "--out", out)
    assert r.returncode == 0, r.stderr
    with xr.open_dataset(out) as ds:
        assert list(ds["torque"].values) == [0.0, 50.0]
    foreign = tmp_path / "mine.nc"
    xr.Dataset({"x": ("t", [1.0, 2.0])}).to_netcdf(foreign)
    r = _run(tmp_path, "static-te", *SMALL, "--out", foreign)
    assert r.returncode == 2 and "not a geardyn result" in r.stderr, r.stderr


@pytest.mark.slow
def test_static_te_of_a_spall(tmp_path):
    spall = os.path.join(EXAMPLES, "spall.toml")
    r = _run(tmp_path, "static-te", "-c", spall, *SMALL, "--no-errors", "--out",
             tmp_path / "h.nc")
    assert r.returncode == 0, r.stderr
    assert "healthy (the case's spall left out; --crack includes it)" in r.stdout, r.stdout
    r = _run(tmp_path, "static-te", "-c", spall, *SMALL, "--no-errors", "--crack", "--out",
             tmp_path / "f.nc")
    assert r.returncode == 0, r.stderr
    assert "faulty: spall" in r.stdout
    with xr.open_dataset(tmp_path / "h.nc") as h, xr.open_dataset(tmp_path / "f.nc") as f:
        ph = float(h["transmission_error"][1].max() - h["transmission_error"][1].min())
        pf = float(f["transmission_error"][1].max() - f["transmission_error"][1].min())
    assert pf > 1.2 * ph  # the spall's lost contact and its gap raise the loaded TE's swing


@pytest.mark.slow
def test_measure_rerun_is_up_to_date(tmp_path):
    out = tmp_path / "m.nc"
    args = ["measure", "--stiffness", "pem", "--csv", "--set", "simulation.record_time=0.3 s",
            "--set", "stiffness.centre_distances=6", "--set", "stiffness.nodes_per_segment=8",
            "--out", out]
    r = _run(tmp_path, *args)
    assert r.returncode == 0, r.stderr
    before = out.read_bytes(), out.with_suffix(".csv").read_bytes()
    r = _run(tmp_path, *args)
    assert r.returncode == 0 and "up to date (same inputs)" in r.stderr, r.stderr
    assert (out.read_bytes(), out.with_suffix(".csv").read_bytes()) == before
    out.with_suffix(".csv").unlink()  # a companion gone: computed again
    r = _run(tmp_path, *args)
    assert r.returncode == 0 and out.with_suffix(".csv").exists(), r.stderr
    r = _run(tmp_path, *args[:-2], "--no-crack", "--out", out)
    assert r.returncode == 2 and "crack True -> False" in r.stderr, r.stderr
