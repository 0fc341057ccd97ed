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


def test_a_record_named_as_its_copy_is_refused(tmp_path):
    """``measure --out y.mat --mat`` wrote a NetCDF file named y.mat, which MATLAB could not
    read, and simulate's .mat copy overwrote its own record (a user audit, 2026-11-27)."""
    for cmd, name, flag in (("measure", "y.mat", "--mat"), ("measure", "y.csv", "--csv"),
                            ("simulate", "s.mat", "--mat")):
        r = _run(tmp_path, cmd, "--stiffness", "pem", flag, "--out", tmp_path / name)
        assert r.returncode == 2, r.stderr
        assert f"--out: got '{tmp_path / name}'" in r.stderr, r.stderr
        assert f"e.g. {name[:-4]}.nc ({flag} writes {name} beside it)" in r.stderr, r.stderr
        assert "Traceback" not in r.stderr and not (tmp_path / name).exists()


@pytest.mark.slow
def test_copies_of_a_replaced_record_are_not_left_behind(tmp_path):
    """A forced re-measure without --csv/--mat left the old record's copies beside the new
    record, and a later run with --csv --mat found them there and kept them (they held the old
    SNR). Now each copy carries the SHA-256 of its record's inputs: a copy of another record is
    removed when not asked for, rewritten when asked for."""
    import numpy as np
    from scipy.io import loadmat

    from geardyn.io import copy_inputs_sha256, inputs_sha256

    out = tmp_path / "r.nc"
    base = ["measure", "--stiffness", "pem", "--set", "simulation.record_time=0.2 s",
            "--set", "stiffness.centre_distances=6", "--set", "stiffness.nodes_per_segment=8",
            "--out", out]
    r = _run(tmp_path, *base, "--csv", "--mat")
    assert r.returncode == 0, r.stderr
    old = copy_inputs_sha256(out.with_suffix(".csv"))
    assert old == copy_inputs_sha256(out.with_suffix(".mat")) == inputs_sha256(
        xr.open_dataset(out).attrs["geardyn_inputs"])
    r = _run(tmp_path, *base, "--set", "measurement.snr=10", "--force")
    assert r.returncode == 0, r.stderr
    assert f"removed {out.with_suffix('.csv')}, {out.with_suffix('.mat')}" in r.stderr, r.stderr
    assert not out.with_suffix(".csv").exists() and not out.with_suffix(".mat").exists()
    # a stale copy put back (as a user restoring a backup would): rewritten when asked for
    r = _run(tmp_path, *base, "--set", "measurement.snr=10", "--csv")
    assert r.returncode == 0, r.stderr
    fresh = out.with_suffix(".csv").read_text()
    stale = fresh.replace(copy_inputs_sha256(out.with_suffix(".csv")), old)
    out.with_suffix(".csv").write_text(stale)
    r = _run(tmp_path, *base, "--set", "measurement.snr=10", "--csv", "--mat")
    assert r.returncode == 0 and "up to date" in r.stderr, r.stderr
    assert f"wrote {out.with_suffix('.csv')}, {out.with_suffix('.mat')} from it" in r.stderr
    assert out.with_suffix(".csv").read_text() == fresh
    with xr.open_dataset(out) as ds:
        acc = ds["acc"].values
    m = loadmat(out.with_suffix(".mat"))
    np.testing.assert_array_equal(m["acc"][:, 0], acc)
    assert float(np.squeeze(m["attrs"]["snr_requested"][0, 0])) == 10.0
    # a file of the same name that geardyn did not write (no stamp) is not removed
    own = out.with_suffix(".csv")
    own.write_text("time,acc\n0,1\n")
    r = _run(tmp_path, *base, "--set", "measurement.snr=10", "--force")
    assert r.returncode == 0 and own.read_text() == "time,acc\n0,1\n", r.stderr
