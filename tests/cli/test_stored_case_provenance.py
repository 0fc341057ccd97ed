"""The case a command stores in its record (``case_toml``) is the case it ran: options that
override case values (``--stiffness``, ``--model``) are in it, with the option as the value's
source, so loading the stored case and running it again gives the same record."""

from __future__ import annotations

import numpy as np
import xarray as xr
from typer.testing import CliRunner

from geardyn.cli import app
from geardyn.config import load_case

#: The paper's case (stiffness.method = "fe", simulation.model = "II") cut short, coarse maps;
#: the method and model come from the options under test.
SHORT = ["--set", "simulation.settle_time=0.002", "--set", "simulation.record_time=0.004",
         "--set", "stiffness.centre_distances=6", "--set", "stiffness.nodes_per_segment=8"]


def _invoke(*args):
    r = CliRunner().invoke(app, list(args))
    assert r.exit_code == 0, r.output
    return r


def _stored_case(path, tmp_path, name="stored.toml"):
    with xr.open_dataset(path, engine="h5netcdf") as ds:
        attrs = dict(ds.attrs)
    toml = tmp_path / name
    toml.write_text(attrs["case_toml"])
    return load_case(toml), toml, attrs


def test_simulate_stores_the_options_and_the_stored_case_runs_the_same(tmp_path):
    paper = load_case(None)  # the options below change its values
    assert paper.stiffness.method == "fe" and paper.simulation.model == "II"
    out = tmp_path / "sim.nc"
    _invoke("simulate", "--stiffness", "PEM", "--model", "i-static", "--no-crack",
            "-o", str(out), *SHORT)
    case, toml, attrs = _stored_case(out, tmp_path)
    assert attrs["stiffness_method"] == "pem" and attrs["model"] == "I-static"
    assert case.stiffness.method == "pem" and case.simulation.model == "I-static"
    assert case.provenance["stiffness.method"] == "--stiffness option"
    assert case.provenance["simulation.model"] == "--model option"
    assert case.provenance["simulation.record_time"] == "--set"  # the others keep theirs
    # the stored case, run again without the options, is the same run
    again = tmp_path / "again.nc"
    _invoke("simulate", "-c", str(toml), "--no-crack", "-o", str(again))
    with xr.open_dataset(out, engine="h5netcdf") as a, \
            xr.open_dataset(again, engine="h5netcdf") as b:
        assert b.attrs["stiffness_method"] == "pem" and b.attrs["model"] == "I-static"
        np.testing.assert_array_equal(a["mesh_force"].values, b["mesh_force"].values)
    # and it stores the same case (the values' sources included: the options' stay)
    case2, _, _ = _stored_case(again, tmp_path, "stored2.toml")
    assert case2.model_dump() == case.model_dump()


def test_static_te_stores_the_stiffness_option(tmp_path):
    out = tmp_path / "te.nc"
    _invoke("static-te", "--stiffness", "pem", "--no-errors", "--points", "16", "-o", str(out),
            *SHORT)
    case, _, attrs = _stored_case(out, tmp_path)
    assert attrs["stiffness_method"] == "pem" and case.stiffness.method == "pem"
    assert case.provenance["stiffness.method"] == "--stiffness option"


def test_measure_stores_the_stiffness_and_model_options(tmp_path):
    out = tmp_path / "rec.nc"
    _invoke("measure", "--stiffness", "pem", "--model", "i", "--no-crack", "-o", str(out),
            *SHORT)
    case, _, attrs = _stored_case(out, tmp_path)
    assert attrs["stiffness_method"] == "pem" and attrs["simulation_model"] == "I"
    assert case.stiffness.method == "pem" and case.simulation.model == "I"
    assert case.provenance["stiffness.method"] == "--stiffness option"
    assert case.provenance["simulation.model"] == "--model option"
