"""The record: variable names and units, attributes, decimation, progress, NetCDF and .mat."""

from __future__ import annotations

import math
import warnings

import numpy as np
import pytest
import xarray as xr

from geardyn.dynamics import save_mat, save_netcdf, simulate, static_equilibrium
from geardyn.dynamics.model import DynamicModel
from geardyn.stiffness import StiffnessMap

from ._support import geometric_map, short_case

STATE = ["theta_m", "y_p", "theta_p", "y_g", "theta_g", "theta_out",
         "omega_m", "v_yp", "omega_p", "v_yg", "omega_g", "omega_out"]
OTHER = ["transmission_error", "mesh_force", "mesh_deflection", "centre_distance_change",
         "pressure_angle", "contact_ratio", "contact_ratio_eq8", "mesh_stiffness", "contact",
         "iterations", "residual_before", "residual_after"]


@pytest.fixture(scope="module")
def case():
    return short_case(**{"simulation.record_time": 0.01})


@pytest.fixture(scope="module")
def smap(case):
    return geometric_map(case.gear_pair())


@pytest.fixture(scope="module")
def ds(case, smap):
    return simulate(case, smap, model="II")


def test_variables_units_and_attributes(ds, case):
    assert set(STATE + OTHER) <= set(ds.data_vars)
    for name in STATE + OTHER + ["time"]:
        var = ds[name]
        assert var.attrs["units"] and var.attrs["long_name"], name
        if name in STATE:
            assert var.dtype == np.float64
    units = {"theta_p": "rad", "y_p": "m", "omega_p": "rad/s", "v_yg": "m/s", "time": "s",
             "mesh_force": "N", "centre_distance_change": "m", "pressure_angle": "rad",
             "mesh_stiffness": "N/m", "transmission_error": "rad", "residual_before": "m"}
    for name, u in units.items():
        assert ds[name].attrs["units"] == u
    a = ds.attrs
    assert a["pinion_teeth"] == 23 and a["gear_teeth"] == 23 and a["model"] == "II"
    assert a["dt"] == 1e-5 and a["complete"] == 1
    assert "Xue & Howard" in a["citations"] and a["geardyn_version"]
    assert "[simulation]" in a["case_toml"] and "xue_howard" in a["case_toml"]
    assert a["output_law_calibrated"] == 1 and a["target_speed"] == 114.14


def test_starts_at_static_equilibrium_and_time_axis(ds, case, smap):
    """settle_time = 0: the first sample is the static state (theta_p = 0 at t = 0)."""
    st = static_equilibrium(DynamicModel.from_case(case, smap), smap, which="II")
    assert ds.sizes["time"] == 1000
    np.testing.assert_allclose(np.diff(ds.time.values), 1e-5, rtol=1e-9)
    assert float(ds.time[0]) == 0.0 and float(ds.theta_p[0]) == 0.0
    assert float(ds.y_p[0]) == pytest.approx(st.y_p, rel=1e-14)
    assert float(ds.mesh_force[0]) == pytest.approx(st.mesh_force, rel=1e-12)
    assert float(ds.omega_g[0]) == pytest.approx(114.14, rel=1e-14)
    assert float(ds.transmission_error[0]) == pytest.approx(st.transmission_error, rel=1e-12)
    # the recorded angles are the total ones: theta_p grows with the speed
    assert float(ds.theta_p[-1]) == pytest.approx(114.14 * float(ds.time[-1]), rel=1e-3)
    te = ds.theta_p.values - ds.theta_g.values
    np.testing.assert_allclose(te, ds.transmission_error.values, atol=1e-12)


def test_decimation_settling_and_progress(case, smap):
    calls = []
    c = case.with_overrides({"simulation.decimation": 7, "simulation.settle_time": 0.003})
    ds = simulate(c, smap, model="I", progress=lambda d, t: calls.append((d, t)))
    assert ds.sizes["time"] == math.ceil(1000 / 7)
    np.testing.assert_allclose(np.diff(ds.time.values), 7e-5, rtol=1e-9)
    assert float(ds.time[0]) == pytest.approx(0.003)
    done = [d for d, _ in calls]
    assert done == sorted(done) and calls[-1][0] == calls[-1][1] == 300 + 999 // 7 * 7
    assert np.isnan(ds.residual_before.values).all() and (ds.iterations.values == 0).all()


def test_decimated_record_equals_full_record(case, smap):
    full = simulate(case, smap, model="II")
    dec = simulate(case.with_overrides({"simulation.decimation": 10}), smap, model="II")
    for name in ("y_g", "theta_p", "mesh_force", "iterations"):
        np.testing.assert_array_equal(dec[name].values, full[name].values[::10])


def test_netcdf_and_mat_round_trip(ds, tmp_path):
    from scipy.io import loadmat

    save_netcdf(ds, tmp_path / "sim.nc")
    with xr.open_dataset(tmp_path / "sim.nc", engine="h5netcdf") as back:
        for name in STATE + OTHER:
            np.testing.assert_array_equal(back[name].values, ds[name].values)
            assert back[name].attrs["units"] == ds[name].attrs["units"]
        assert back.attrs["complete"] == 1 and back.attrs["model"] == "II"
    save_mat(ds, tmp_path / "sim.mat")
    m = loadmat(tmp_path / "sim.mat")
    np.testing.assert_array_equal(m["y_g"][:, 0], ds.y_g.values)
    assert m["time"].shape == (ds.sizes["time"], 1)
    assert str(m["units"]["mesh_force"][0, 0][0]) == "N"


def test_user_table_map_and_hht(case):
    """A user's table (one mesh cycle, one centre distance) drives both models; HHT-alpha runs."""
    pair = case.gear_pair()
    th = np.linspace(0, pair.mesh_angle, 120, endpoint=False)
    k = 1.1e8 + 2.5e7 * np.cos(23 * th)
    table = StiffnessMap.from_table(pair, th, k)
    a = simulate(case, table, model="I")
    b = simulate(case, table, model="II")          # constant in d: model II = model I
    np.testing.assert_allclose(a.y_g.values, b.y_g.values, rtol=1e-12)
    h = simulate(case.with_overrides({"simulation.integrator": "hht",
                                      "simulation.hht_alpha": -0.05}), table, model="I")
    assert h.attrs["hht_alpha"] == -0.05
    assert np.abs(h.y_g.values - a.y_g.values).max() < 0.02 * np.ptp(a.y_g.values) + 1e-9


def test_builds_the_case_map_when_none_is_given():
    c = short_case(**{"simulation.record_time": 0.002, "stiffness.centre_distances": 6,
                      "stiffness.nodes_per_segment": 8})
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")      # the Sainsot range note of the paper's teeth
        ds = simulate(c, model="II", cracked=False)
    assert ds.attrs["stiffness_method"] == "pem" and ds.attrs["stiffness_cracked"] == 0


def test_mesh_deflection_is_the_projection_of_the_recorded_coordinates(ds, case, smap):
    """``mesh_deflection`` (eq. 15, p = g . z) against the recorded coordinates: the record adds
    the reference rotation to the angles, which g cancels (g . e = 0), so the projection of the
    recorded values equals it to the rounding of the reference angles."""
    g = DynamicModel.from_case(case, smap).g
    coords = np.stack([ds[v].values for v in STATE[:6]], axis=1)  # [rad, m, rad, m, rad, rad]
    p = coords @ g
    scale = np.abs(coords) @ np.abs(g)  # [m]: the largest terms of the sum
    assert np.ptp(ds.mesh_deflection.values) > 1e-3 * np.max(np.abs(ds.mesh_deflection.values))
    np.testing.assert_allclose(ds.mesh_deflection.values, p, rtol=0,
                               atol=16 * np.finfo(float).eps * scale.max())
