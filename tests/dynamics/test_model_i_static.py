"""Model I-static: model I with ``K(theta)`` at the static operating centre distance of eq. 4.

Oracles
-------
* exact: with a map that does not depend on the centre distance, model I-static *is* model I
  (every recorded variable bit for bit); with a map linear in the centre distance and constant in
  the angle, its mesh stiffness is the map at the static change ``dd_s`` computed here by hand
  from eq. 4 (bearing deflections ``N/k_y`` from the mesh force ``N = T/r_b1``), to rounding;
* tooth errors: at ``t = 0`` the contact geometry of model I-static is model II's (both at the
  static centre distance), not model I's;
* a second model: on the paper case with the PEM map, model I-static reproduces model II (whose
  centre distance moves only a few um about ``dd_s``) to a few percent of each signal's standard
  deviation, while model I is off by about one standard deviation (issue 18 of the project);
* the CLI and the sweep accept the new name (case-insensitive on the command line).
"""

from __future__ import annotations

import math
import os
import sys
import textwrap
import warnings

import numpy as np
import pytest
import xarray as xr

import geardyn
from geardyn.config import SimulationConfig
from geardyn.dynamics import simulate
from geardyn.dynamics.model import MODELS
from geardyn.errors import InputError
from geardyn.stiffness import StiffnessMap, centre_distance_grid
from geardyn.studies.model_compare import compare_models

from .._cli_fork import run_geardyn
from ._support import geometric_map, short_case


def test_the_three_models_are_the_config_choices():
    from typing import get_args

    assert get_args(SimulationConfig.model_fields["model"].annotation) == MODELS
    assert MODELS == ("I", "I-static", "II")


def test_a_map_constant_in_the_centre_distance_makes_i_static_model_i_bit_for_bit():
    """One grid line (the square-wave map of the geometric contact count at the design centre
    distance): nothing depends on ``dd``, so the shifted map and centre distance change nothing.
    Even ``centre_distance_change`` (the geometric ``d(t) - d``) rounds the same."""
    case = short_case(**{"simulation.record_time": 0.01})
    flat = geometric_map(case.gear_pair(), dd=(0.0, 0.0), n_d=1)
    a = simulate(case, flat, model="I")
    b = simulate(case, flat, model="I-static")
    assert set(a.data_vars) == set(b.data_vars)
    for v in a.data_vars:
        assert np.array_equal(a[v].values, b[v].values, equal_nan=True), v
        assert a[v].attrs == b[v].attrs, v
    assert np.array_equal(a.time.values, b.time.values)
    assert a.attrs["model"] == "I" and b.attrs["model"] == "I-static"
    assert np.ptp(a.mesh_stiffness.values) > 0.5 * a.mesh_stiffness.values.min()  # not trivial


def _hand_static_dd(case) -> float:
    """Eq. 4 by hand from the case's numbers: ``N = T_in / r_b1`` (no torsional damping),
    ``y_p = -N/k_yp``, ``y_g = N/k_yg``, ``d' = sqrt((r_b1 + r_b2)^2 + (d sin a + y_g - y_p)^2)``
    for a standard pair (no profile shift: ``d = m (z1 + z2)/2``, ``r_b = m z cos(a)/2``)."""
    m, a = case.pair.module, case.pair.pressure_angle
    z1, z2 = case.pinion.teeth, case.gear.teeth
    assert case.pinion.profile_shift == 0 and case.gear.profile_shift == 0
    assert case.pinion.torsional_damping == 0 and case.motor.law == "constant"
    rb1, rb2 = m * z1 * math.cos(a) / 2, m * z2 * math.cos(a) / 2
    d = m * (z1 + z2) / 2
    n = case.motor.torque / rb1
    yp, yg = -n / case.pinion.bearing_stiffness, n / case.gear.bearing_stiffness
    return math.sqrt((rb1 + rb2) ** 2 + (d * math.sin(a) + yg - yp) ** 2) - d


def test_a_map_linear_in_the_centre_distance_is_read_at_the_static_distance():
    """``k(theta, dd) = k0 (1 + s dd)`` (linear interpolation in ``dd`` is exact for it), unequal
    bearings and 120 N m: model I-static's mesh stiffness is ``k0 (1 + s dd_s)`` at every step,
    with ``dd_s`` from eq. 4 by hand; model I's is ``k0``."""
    case = short_case(**{"simulation.record_time": 0.005, "motor.torque": 120.0,
                         "pinion.bearing_stiffness": 2.0e6, "gear.bearing_stiffness": 5.0e5})
    k0, slope = 1.0e8, 200.0  # 1/m: +20 % per mm
    lin = StiffnessMap.from_function(case.gear_pair(), np.linspace(-1e-3, 4e-3, 6),
                                     lambda th, d: {"k_mb": np.full(th.size, k0 * (1 + slope * d))},
                                     n_seg=2)
    dd_s = _hand_static_dd(case)
    assert 1.3e-3 < dd_s < 3e-3  # not the default case's 1.0852 mm, far from dd = 0
    ds = simulate(case, lin, model="I-static")
    k_expected = k0 * (1 + slope * dd_s)
    assert ds.attrs["stiffness_centre_distance_change"] == pytest.approx(dd_s, rel=1e-12)
    assert ds.attrs["static_centre_distance_change"] == pytest.approx(dd_s, rel=1e-12)
    np.testing.assert_allclose(ds.mesh_stiffness.values, k_expected, rtol=1e-12)
    ds1 = simulate(case, lin, model="I")
    np.testing.assert_allclose(ds1.mesh_stiffness.values, k0, rtol=1e-12)
    # the fixed operating point's geometry (eq. 6) and the units
    pair = case.gear_pair()
    assert ds.attrs["stiffness_pressure_angle"] == pytest.approx(
        math.acos(pair.base_radius_sum / (pair.design_centre_distance + dd_s)), rel=1e-12)
    assert ds.attrs["stiffness_centre_distance_change_units"] == "m"
    assert ds.attrs["stiffness_pressure_angle_units"] == "rad"
    op = pair.operating(dd_s)
    assert ds.attrs["stiffness_contact_ratio"] == pytest.approx(op.contact_ratio, rel=1e-10)
    # the recorded centre distance stays the geometric one of the bearing motion (as model I)
    assert float(ds.centre_distance_change[0]) == pytest.approx(dd_s, rel=1e-9)
    assert ds.centre_distance_change.attrs["units"] == "m"


def test_tooth_errors_use_the_static_centre_distance_geometry():
    """Gear tip relief starting at roll angle 0.2 rad, below the pitch point: at ``t = 0`` the
    single loaded pair meets at the pitch point of the pinion, i.e. at the gear's roll
    ``(T1T2 - s_pitch)/r_b2``, which grows with the centre distance (``T1T2`` by 3.2 mm at the
    static ``dd_s``), so its relief does too. Model I-static's error equals model II's (both at
    ``d + dd_s``), model I's is smaller (design ``T1T2``) by ``slope 3.2 mm / r_b2`` (about 2.6 um
    of a 20 um relief over 0.38 rad of roll)."""
    case = short_case(**{"simulation.record_time": 0.001, "modifications.gear.tip_relief": 2e-5,
                         "modifications.gear.relief_start": 0.2})
    smap = geometric_map(case.gear_pair())
    e = {w: simulate(case, smap, model=w).mesh_error.values[0] for w in MODELS}
    assert e["II"] > 1e-6
    assert e["I-static"] == pytest.approx(e["II"], rel=1e-9)
    assert e["II"] - e["I"] > 0.05 * e["II"]


def test_bad_model_names_are_refused():
    case = short_case(**{"simulation.record_time": 0.001})
    with pytest.raises(InputError, match="I-static"):
        simulate(case, geometric_map(case.gear_pair()), model="III")
    # the model's name in any case, as the CLI's --model takes it
    ds = simulate(case, geometric_map(case.gear_pair()), model="i-static")
    assert ds.attrs["model"] == "I-static"
    with pytest.raises(InputError, match="simulation.model"):
        geardyn.paper_case({"simulation.model": "III"})
    assert geardyn.paper_case({"simulation.model": "I-static"}).simulation.model == "I-static"


# ------------------------------------------------------------------- the paper case, PEM map
def _pem_runs(window):
    """The paper case (0.5 s settled, 1 s recorded, dt = 10 us) on its cracked PEM map, with the
    stiffness sampled per ``simulation.stiffness_window``."""
    from geardyn.stiffness.pem import pem_map

    case = geardyn.paper_case({"stiffness.method": "pem", "simulation.stiffness_window": window})
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        smap = pem_map(case, centre_distance_grid(case), cracked=True)
    return case, {w: simulate(case, smap, model=w) for w in MODELS}


@pytest.fixture(scope="module")
def pem_runs():
    """Stiffness sampled at a point (the handover 'flips' below exist only there)."""
    return _pem_runs("point")


@pytest.fixture(scope="module")
def pem_runs_step():
    """Stiffness averaged over each step's rotation (the default)."""
    return _pem_runs("step")


def test_i_static_reproduces_model_ii_better_without_the_handover_flips(pem_runs, pem_runs_step):
    """With the stiffness averaged over each step (``stiffness_window = "step"``, the default)
    a handover that moves inside a step moves the stiffness by the moved fraction of the step
    instead of flipping a whole step: the flips that carry most of the PEM's II - I-static
    difference in :func:`test_i_static_reproduces_model_ii_on_the_paper_case_with_pem` go, and
    every signal's RMS(II - I-static)/STD(II) falls (measured: 0.3-1.7 % against 1.5-7.8 %),
    while model I stays as far off as with point sampling (82-140 %, issue 18's FE figure for
    the same comparison is 0.10-0.52 %).

    Tolerances: every signal below its point-sampled value and below issue 18's "about 5 %" for
    the PEM; model I at least 50 % off."""
    _, rp = pem_runs
    _, rs = pem_runs_step
    cp = compare_models(rp["I"], rp["I-static"], rp["II"])
    cs = compare_models(rs["I"], rs["I-static"], rs["II"])
    for s in cs.signal.values:
        step, point = cs.sel(signal=s), cp.sel(signal=s)
        assert float(step.rms_ii_minus_i_static) < float(point.rms_ii_minus_i_static), s
        assert float(step.rms_ii_minus_i_static) < 0.05, s
        assert float(step.rms_ii_minus_i) > 0.5, s
    assert np.abs(rs["II"].mesh_stiffness.values - rs["I-static"].mesh_stiffness.values).max() \
        < np.abs(rp["II"].mesh_stiffness.values - rp["I-static"].mesh_stiffness.values).max()


def test_i_static_reproduces_model_ii_on_the_paper_case_with_pem(pem_runs):
    """With the stiffness sampled at a point (``stiffness_window = "point"``, geardyn before
    2026-11-25). Measured (paper case, PEM, dt = 10 us, 1 s recorded): RMS(II - I-static)/STD(II) =
    1.5-7.8 % over the ten default signals of :func:`compare_models` (transmission error 2.9 %,
    mesh force 7.8 %, v_yg 4.6 %, omega_p 4.6 %), against RMS(II - I)/STD(II) = 82-140 %
    (issue 18 quotes 2.9-4.7 % and 91-140 % for its run frozen at model II's mean centre
    distance). With the FE map the same run gives 0.10-0.52 % against 79-130 %.

    Where the PEM figure comes from: the entry handover sits at pinion angle
    ``(T1T2(d) - u_2 - s_pitch)/r_b1``, which moves by ``(d / T1T2) / r_b1`` = 42.7 rad/m with the
    centre distance; model II's ``d(t)`` wanders ``|d - d_s|`` = 1.2 um on average from the static
    value, so a fraction ``42.7 |d - d_s| / (w dt)`` = 4.3 % of the entry handovers fall in a
    different time step for the two models ("flips": one step with the pair count, a 44-49 %
    stiffness jump, different; every other step differs by at most 0.02 %). Outside about 3 ms
    after a flip the records differ by 0.03-0.55 % of STD; the flips carry the rest. The
    response to a flip scales with dt (measured with dt = 10, 5, 2.5 us: transmission error 2.9,
    2.0, 1.4 %, as sqrt(dt)), the mesh force's one-step spike does not (7.8, 7.0, 6.6 %): with
    the sharp PEM handovers the few-percent figure is partly an artefact of the time step.

    Tolerances: the flip count within 3 sqrt(expected) (a binomial count); 1 % of STD outside
    the flips (the map's mean stiffness changes by 0.08 % per 5 um at ``d_s``); overall 10 %,
    issue 18's threshold for "the two models differ"; model I at least 50 % off. None is fitted
    to the measured values.
    """
    case, r = pem_runs
    ii, i_s = r["II"], r["I-static"]
    dd_s = i_s.attrs["stiffness_centre_distance_change"]
    cmp = compare_models(r["I"], i_s, ii)
    for s in cmp.signal.values:
        row = cmp.sel(signal=s)
        assert float(row.rms_ii_minus_i_static) < 0.10, s
        assert float(row.rms_ii_minus_i) > 0.5, s
        assert float(row.explained_fraction) > 0.9, s
    # the flips: how many, against the handover kinematics
    pair = case.gear_pair()
    d_op = pair.design_centre_distance + dd_s
    dtheta_dd = d_op / math.sqrt(d_op ** 2 - pair.base_radius_sum ** 2) / pair.pinion.base_radius
    dd = ii.centre_distance_change.values - dd_s
    turns = float(ii.theta_p[-1] - ii.theta_p[0]) / (2 * math.pi)
    p_flip = dtheta_dd * np.mean(np.abs(dd)) / (ii.attrs["target_speed"] * ii.attrs["dt"])
    expected = p_flip * case.pinion.teeth * turns
    k2, ks = ii.mesh_stiffness.values, i_s.mesh_stiffness.values
    flips = np.nonzero(np.abs(k2 - ks) > 0.05 * k2)[0]
    assert expected > 5  # enough handovers for the count to mean something
    assert abs(flips.size - expected) < 3 * math.sqrt(expected), (flips.size, expected)
    quiet = np.ones(k2.size, bool)
    after = int(round(3e-3 / (ii.attrs["dt"] * ii.attrs["decimation"])))
    for i in flips:
        quiet[i:i + after] = False
    assert quiet.mean() > 0.8
    for s in cmp.signal.values:
        a, b = ii[s].values[quiet], i_s[s].values[quiet]
        assert np.sqrt(np.mean((a - b) ** 2)) < 0.01 * np.std(ii[s].values), s


def test_compare_models_checks_its_inputs_and_computes_the_ratios():
    """On synthetic records: the three ratios from their definitions."""
    t = np.arange(1000) * 1e-4
    base = np.sin(2 * np.pi * 50 * t)

    def rec(model, x):
        return xr.Dataset({"x": ("time", x, {"units": "m"})}, coords={"time": t},
                          attrs={"model": model})

    ii = rec("II", base)
    i_s = rec("I-static", base + 0.01)          # RMS(II - Is) = 0.01
    i_1 = rec("I", 0.5 * base)                  # RMS(II - I) = 0.5 RMS(base)
    out = compare_models(i_1, i_s, ii, signals=["x"])
    std = np.std(base)
    assert float(out.rms_ii_minus_i_static.sel(signal="x")) == pytest.approx(0.01 / std,
                                                                             rel=1e-12)
    rms1 = math.sqrt(np.mean((0.5 * base) ** 2))
    assert float(out.rms_ii_minus_i.sel(signal="x")) == pytest.approx(rms1 / std, rel=1e-12)
    assert float(out.explained_fraction.sel(signal="x")) == pytest.approx(1 - 0.01 / rms1,
                                                                          rel=1e-12)
    for v in out.data_vars:
        assert out[v].attrs["units"] == "1" and out[v].attrs["long_name"]
    assert str(out.signal_units.sel(signal="x").values) == "m"
    with pytest.raises(InputError, match="model I-static"):
        compare_models(i_1, ii, ii, signals=["x"])
    with pytest.raises(InputError, match="time samples"):
        compare_models(i_1, rec("I-static", base).isel(time=slice(0, 10)), ii, signals=["x"])
    with pytest.raises(InputError, match="signals"):
        compare_models(i_1, i_s, ii, signals=["y"])


# ------------------------------------------------------------------- command line and sweeps
GEARDYN = [sys.executable, "-m", "geardyn"]
SHORT = ["--set", "simulation.settle_time=0.002", "--set", "simulation.record_time=0.004",
         "--set", "stiffness.centre_distances=6", "--set", "stiffness.nodes_per_segment=8",
         "--set", "stiffness.method=pem"]


def _run(*args, cache):
    env = {**os.environ, "GEARDYN_CACHE_DIR": str(cache)}
    return run_geardyn(list(args), capture_output=True, text=True, env=env,
                       timeout=300)


@pytest.mark.slow
def test_cli_simulate_model_i_static_any_case(tmp_path):
    out = tmp_path / "s.nc"
    r = _run("simulate", "--model", "i-STATIC", "-o", str(out), *SHORT, cache=tmp_path / "c")
    assert r.returncode == 0, r.stderr
    assert "model I-static" in r.stdout and "static centre distance change 1.0852 mm" in r.stdout
    with xr.open_dataset(out, engine="h5netcdf") as ds:
        assert ds.attrs["model"] == "I-static" and ds.attrs["complete"] == 1
        assert round(float(ds.attrs["stiffness_centre_distance_change"]) * 1e3, 4) == 1.0852
        assert ds.attrs["stiffness_centre_distance_change_units"] == "m"
        assert ds["mesh_stiffness"].attrs["units"] == "N/m"


def test_cli_refuses_an_unknown_model_naming_the_allowed_ones(tmp_path):
    for cmd in ("simulate", "measure"):
        r = _run(cmd, "--model", "I-dynamic", "-o", str(tmp_path / "x.nc"), cache=tmp_path / "c")
        assert r.returncode == 2, (cmd, r.stderr)
        assert "--model" in r.stderr and "'I-static'" in r.stderr and "'II'" in r.stderr, cmd
        assert "Traceback" not in r.stderr
        assert not (tmp_path / "x.nc").exists()


def test_a_sweep_over_the_model_runs_i_static():
    from geardyn.dynamics import summary
    from geardyn.stiffness import build_map
    from geardyn.studies.sweep import evaluate_run, parse_sweep

    sw = parse_sweep(textwrap.dedent("""
        name = "models"
        [axes]
        simulation.model = ["I", "I-static", "II"]
    """))
    plan = sw.plan()
    assert [plan.overrides(i)["simulation.model"] for i in range(plan.n_runs)] == list(MODELS)
    case = geardyn.paper_case({"stiffness.method": "pem", "simulation.settle_time": 0.02,
                               "simulation.record_time": 0.17, "stiffness.centre_distances": 6,
                               "stiffness.nodes_per_segment": 6}).with_overrides(plan.overrides(1))
    assert case.simulation.model == "I-static"
    feats = evaluate_run(case)
    s = summary(simulate(case, build_map(case, cracked=True)))
    assert feats["sim__mean_mesh_force"] == s["mean_mesh_force_N"]
    assert feats["sim__std_transmission_error"] == s["std_transmission_error_rad"]
    s2 = summary(simulate(case, build_map(case, cracked=True), model="II"))
    assert feats["sim__std_transmission_error"] != s2["std_transmission_error_rad"]
