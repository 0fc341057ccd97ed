"""``geardyn crack-growth`` on examples/faults/crack_growth.toml, and its refusals.

Oracles (none echoes the code under test): the equivalent straight crack of a straight crack's
own tip is that crack (round trip through :func:`geardyn.stiffness.fe.mesh.crack_segment`); the
gear's highest point of single tooth contact equals the pinion's of the pair with the two gears
swapped; Paris ``C`` conversions by hand; and, on the grown example, physical monotonicity (cycles
and ``K_I`` grow with the crack, the FE compliance too) rather than stored numbers.
"""

from __future__ import annotations

import json
import math
import os
from pathlib import Path

import numpy as np
import pytest

from geardyn.errors import InputError

from .._cli_fork import run_geardyn

ROOT = Path(__file__).resolve().parents[2]
EXAMPLE = ROOT / "examples" / "faults" / "crack_growth.toml"
#: Easigrow's AA7050-T7451 Paris fit (src/material.rs, "paris:newman-aa7050t7451"): an example
#: material, not a geardyn default.
PARIS = ["--paris-c", "1.593e-11 m/cycle/(MPa m^0.5)^m", "--paris-m", "3.668"]


def _run(args, tmp_path, timeout=600):
    env = {**os.environ, "GEARDYN_CACHE_DIR": str(tmp_path / "cache")}
    env.pop("GEARDYN_DEBUG", None)
    return run_geardyn(["crack-growth", *args],
                       capture_output=True, text=True, env=env, timeout=timeout, cwd=tmp_path)


# ------------------------------------------------------------------------------ fast tier
def test_equivalent_crack_of_a_straight_crack_is_itself():
    from geardyn.config import paper_case
    from geardyn.faults.tooth_growth import equivalent_crack
    from geardyn.stiffness.fe.mesh import CrackGeometry, crack_segment

    g = paper_case().gear_pair().pinion
    for depth, deg in ((0.5e-3, 30.0), (3e-3, 45.0), (6e-3, 70.0)):
        mouth, tip = crack_segment(g, CrackGeometry(depth, math.radians(deg)))
        q, v = equivalent_crack(mouth, tip)
        assert q == pytest.approx(depth, rel=1e-12)
        assert math.degrees(v) == pytest.approx(deg, rel=1e-12)


def test_gear_hpstc_is_the_swapped_pairs_pinion_hpstc():
    from geardyn.config import paper_case
    from geardyn.faults.tooth_growth import hpstc_roll

    a = paper_case(["pinion.teeth=19", "gear.teeth=31"]).gear_pair()
    b = paper_case(["pinion.teeth=31", "gear.teeth=19"]).gear_pair()
    assert hpstc_roll(a, gear="gear") == pytest.approx(hpstc_roll(b, gear="pinion"), rel=1e-12)
    assert hpstc_roll(b, gear="gear") == pytest.approx(hpstc_roll(a, gear="pinion"), rel=1e-12)
    # the HPSTC lies on the active involute, below the tip
    g = a.gear
    assert 0 < hpstc_roll(a, gear="gear") < math.sqrt(g.tip_radius ** 2 - g.base_radius ** 2)
    with pytest.raises(InputError, match="gear"):
        hpstc_roll(a, gear="wheel")


def test_paris_c_units():
    from geardyn.cli.crack_growth import parse_paris_c, parse_stress_intensity

    # per MPa m^0.5: (1 MPa)^-m = 1e-6^m Pa^-m; mm/cycle: 1e-3 m
    assert parse_paris_c("1.593e-11 m/cycle/(MPa m^0.5)^m", 3.668) == pytest.approx(
        1.593e-11 * 10.0 ** (-6 * 3.668), rel=1e-12)
    assert parse_paris_c("2e-8 mm/cycle/(MPa sqrt(m))^3", 3.0) == pytest.approx(2e-29, rel=1e-12)
    assert parse_paris_c("1e-30 m/cycle/(Pa*m^0.5)^m", 3.0) == 1e-30
    for bad in ("1e-11", "1e-11 m/cycle", "-1e-11 m/cycle/(MPa m^0.5)^m",
                "1e-11 m/cycle/(MPa m^0.5)^2", "1e-11 m/s/(MPa m^0.5)^m", None):
        with pytest.raises(InputError, match="--paris-c"):
            parse_paris_c(bad, 3.0)
    assert parse_stress_intensity("2 MPa m^0.5", "t") == 2e6
    assert parse_stress_intensity("0", "t") == 0.0
    with pytest.raises(InputError, match="t"):
        parse_stress_intensity("-1 MPa m^0.5", "t")


def test_case_crack_refusals():
    from geardyn.config import load_case
    from geardyn.faults.tooth_growth import case_crack

    c = case_crack(load_case(EXAMPLE))
    assert (c.gear, c.tooth, c.depth, c.field, c.key) == ("pinion", 11, 1e-3, "faults[0]",
                                                          "faults.0")
    with pytest.raises(InputError, match=r"faults\[0\]\.width"):
        case_crack(load_case(EXAMPLE, ["faults.0.width=10mm"]))
    with pytest.raises(InputError, match=r"faults\[0\]"):  # the [crack] and a root_crack entry
        case_crack(load_case(EXAMPLE, ["crack.enabled=true"]))
    with pytest.raises(InputError, match="crack"):
        case_crack(load_case(None, ["crack.enabled=false"]))


@pytest.mark.parametrize("args, field", [
    (["--paris-c", "1e-11 m/cycle/(MPa m^0.5)^m", "--paris-m=-3"], "--paris-m"),
    (["--paris-m", "3"], "--paris-c"),
    (["--paris-c", "1e-11 m/cycle/(MPa m^0.5)^m"], "--paris-m"),
    (["--paris-c", "1e-11", "--paris-m", "3"], "--paris-c"),
    ([*PARIS, "--set", "faults.0.depth=20mm"], "faults[0].depth"),
    ([*PARIS, "--step-size", "5 mm"], "--step-size: got '5 mm'; allowed: a crack extension in "
                                      "(0, "),
    ([*PARIS, "--stiffness", "iso"], "--stiffness"),
])
def test_bad_input_is_one_line_exit_2(tmp_path, args, field):
    """In-process (typer's CliRunner): exit 2, one line naming the field, nothing written."""
    from tests.config._cli import assert_clean_error, cli

    r = cli("crack-growth", "--config", str(EXAMPLE), "--out", str(tmp_path / "o"), *args)
    assert_clean_error(r, field)
    assert not (tmp_path / "o").exists()


def test_crack_deeper_than_the_tooth_in_the_crack_section(tmp_path):
    """The paper's own [crack] (no --config), 20 mm deep: refused naming crack.depth."""
    from tests.config._cli import assert_clean_error, cli

    r = cli("crack-growth", "--out", str(tmp_path / "o"), *PARIS, "--set", "crack.depth=20mm")
    assert_clean_error(r, "crack.depth")


def test_negative_exponent_in_a_real_process(tmp_path):
    """The console path end to end: a subprocess, exit 2, one line, no traceback."""
    r = _run(["--config", str(EXAMPLE), "--out", str(tmp_path / "o"), "--paris-c",
              "1e-11 m/cycle/(MPa m^0.5)^m", "--paris-m", "-3"], tmp_path)
    assert r.returncode == 2, r.stderr
    lines = r.stderr.strip().splitlines()
    assert len(lines) == 1 and "--paris-m" in lines[0], r.stderr
    assert "Traceback" not in r.stderr + r.stdout


# ------------------------------------------------------------------------------ slow tier
@pytest.mark.slow
def test_example_quick_through_the_cli(tmp_path):
    import xarray as xr

    out = tmp_path / "out"
    r = _run(["--config", str(EXAMPLE), "--out", str(out), *PARIS, "--quick"], tmp_path)
    assert r.returncode == 0, r.stderr
    assert len(r.stdout.strip().splitlines()) == 1  # the one-line summary
    for name in ("fig_crack_path.png", "fig_sif.png", "fig_cycles.png", "fig_indicators.png",
                 "fig_mesh_stiffness.png"):
        assert (out / name).read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    record = json.loads((out / "inputs.json").read_text())
    assert record["complete"] is True
    with xr.open_dataset(out / "crack_growth.nc", engine="h5netcdf") as ds:
        ds = ds.load()
    for name, var in {**ds.data_vars, **ds.coords}.items():
        assert var.attrs.get("long_name"), name
        if var.dtype.kind in "fiu":
            assert "units" in var.attrs, name
    assert ds["K_I"].attrs["units"] == "Pa m^0.5" and ds["cycles"].attrs["units"] == "1"
    assert ds["tip_x"].attrs["units"] == "m" and ds["kink_angle"].attrs["units"] == "rad"
    assert "chord" in ds.attrs["equivalent_crack"]
    a = ds["crack_length"].values
    assert a.size >= 4 and np.all(np.diff(a) > 0)
    n = ds["cycles"].values
    assert n[0] == 0 and np.all(np.diff(n) > 0)
    assert np.all(np.diff(ds["K_I"].values) > 0)
    assert np.all(np.diff(ds["compliance"].values) > 0)
    assert "outline" in ds.attrs["stop"]
    # the first analysed tip is the initial straight crack: its chord is the 1 mm, 45 deg crack
    assert ds["equivalent_depth"].values[0] == pytest.approx(1e-3, rel=1e-9)
    assert ds["equivalent_angle"].values[0] == pytest.approx(math.radians(45), rel=1e-9)
    # indicators vs cycles
    assert ds.sizes["sample_length"] == 3
    assert list(ds["simulation_status"].values) == ["ok"] * 3
    fm4 = ds["v_yg__FM4"].values
    assert np.all(np.isfinite(fm4)) and np.isfinite(float(ds["v_yg__FM4_healthy"]))
    # with the default 20 dB of noise the healthy difference signal is noise-like: FM4 of a
    # Gaussian signal is 3, within about 3 standard errors sqrt(24/2048) of a 2048-sample
    # estimate; the longest crack stands far above it
    assert "20 dB" in ds.attrs["indicator_noise"]
    assert abs(float(ds["v_yg__FM4_healthy"]) - 3.0) < 3 * math.sqrt(24 / 2048) + 0.1
    assert fm4[-1] > 10
    er = ds["transmission_error__EnergyRatio"].values
    assert np.all(np.isfinite(er)) and er[-1] > er[0]  # a longer crack, a larger energy ratio
    assert np.all(np.diff(ds["sample_cycles"].values) > 0)
    # NA4 over the run (healthy record first): its first record is the single record's NA4;
    # against the residual kurtosis, which diagnostic_features computes on its own, each
    # sample's NA4 over the run is kurtosis * (variance / mean variance so far)^2
    for s in ("v_yg", "omega_p", "transmission_error"):
        assert float(ds[f"{s}__NA4_run_healthy"]) == pytest.approx(
            float(ds[f"{s}__NA4_healthy"]), rel=1e-9)
        var = np.r_[float(ds[f"{s}__residual_variance_healthy"]),
                    ds[f"{s}__residual_variance"].values]
        mean_so_far = np.cumsum(var) / np.arange(1, var.size + 1)
        want = ds[f"{s}__residual_kurtosis"].values * (var[1:] / mean_so_far[1:]) ** 2
        np.testing.assert_allclose(ds[f"{s}__NA4_run"].values, want, rtol=1e-9)
        # the residual's variance grows with the crack (the 1 mm crack's is the noise's, as
        # the healthy record's), so the run's mean lags behind it and NA4 over the run stands
        # above the single record's (the residual kurtosis) once the crack has grown
        assert np.all(np.diff(var[1:]) > 0), (s, var)
        assert np.all(ds[f"{s}__NA4_run"].values[1:] > ds[f"{s}__NA4"].values[1:])
    assert ds["v_yg__residual_variance"].attrs["units"] == "(m/s)^2"
    k = ds["mesh_stiffness"].values
    assert np.all(np.isfinite(k)) and k[-1].min() < ds["healthy_mesh_stiffness"].values.min()
    # the CSV: one row per crack length, units in the header, indicators at the sampled rows
    lines = (out / "crack_growth.csv").read_text().strip().splitlines()
    assert lines[0].startswith("crack_length [m],") and "K_I [Pa m^0.5]" in lines[0]
    assert len(lines) == a.size + 1


@pytest.mark.slow
def test_fe_map_of_the_grown_path_through_the_cli(tmp_path):
    """``--stiffness fe``: each simulated length uses the FE map of the grown path itself (the
    crack meshed along its polyline). The mesh stiffness falls with the crack length at the
    cracked tooth's worst position and the indicators are finite; the first sample (the
    initial straight crack) has the straight crack's FE stiffness (one-point path, checked to
    round-off in tests/fe/test_crack_path_map.py)."""
    import xarray as xr

    out = tmp_path / "out"
    r = _run(["--config", str(EXAMPLE), "--out", str(out), *PARIS, "--quick", "--points", "2",
              "--stiffness", "fe"], tmp_path)
    assert r.returncode == 0, r.stderr
    with xr.open_dataset(out / "crack_growth.nc", engine="h5netcdf") as ds:
        ds = ds.load()
    assert ds.attrs["indicator_stiffness"] == "fe"
    # --quick: the maps of geardyn run --quick (coarse FE mesh, at most 11 centre distances)
    from geardyn.studies.paper import QUICK_CENTRE_DISTANCES, QUICK_REFINEMENT

    assert ds.attrs["indicator_fe_mesh_refinement"] == QUICK_REFINEMENT
    assert ds.attrs["indicator_map_centre_distances"] <= QUICK_CENTRE_DISTANCES
    assert "grown crack path" in ds["mesh_stiffness"].attrs["long_name"]
    assert list(ds["simulation_status"].values) == ["ok"] * 2
    k, kh = ds["mesh_stiffness"].values, ds["healthy_mesh_stiffness"].values
    loss = ((kh[None, :] - k) / kh[None, :]).max(axis=1)
    assert 0 < loss[0] < loss[1], loss
    assert np.all(np.isfinite(ds["v_yg__FM4"].values))


@pytest.mark.slow
def test_a_growth_stopped_by_the_step_limit_says_it_is_not_a_life(tmp_path):
    """QA walkthrough: 20 quick steps ended at 7.9 mm with "1.268e+08 cycles" and exit 0, read as
    a life; --steps 0 wrote a result of zero cycles."""
    r = _run(["--config", str(EXAMPLE), "--out", str(tmp_path / "z"), *PARIS, "--quick",
              "--steps", "0"], tmp_path)
    assert r.returncode == 2 and "--steps: got 0" in r.stderr, r.stderr
    r = _run(["--config", str(EXAMPLE), "--out", str(tmp_path / "two"), *PARIS, "--quick",
              "--steps", "2", "--points", "2", "--no-noise"], tmp_path)
    assert r.returncode == 0, r.stderr
    assert "stopped at the step limit (2 steps" in r.stdout and "not a life" in r.stdout, r.stdout
