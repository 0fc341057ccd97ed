"""The model II study (issue 18, item 4): structure, an exact zero, and the bearing resonance.

Oracles:

* **identical inputs**: with a stiffness map that does not depend on the centre distance, model
  II and model I-static integrate the same equations, so RMS(II - I-static) is zero (to
  rounding), however far the centre distance moves;
* **closed-form mode**: the centre distance moves with ``y_g - y_p``; with a mesh and couplings
  much stiffer than the bearings, the mode in which the gear centres move against each other
  has ``omega^2 = 2 k / (2 m + 4 / S)``, ``S = r_b1^2 / J_1 + r_b2^2 / J_2`` with
  ``J_1 = I_p + I_m``, ``J_2 = I_g + I_out`` (the rotations the rigid mesh forces, their kinetic
  energy minimised over the free rigid rotation). Written here from the masses and stiffnesses,
  not taken from geardyn: the eigen-analysis must find it, and the ratio (and the
  centre-distance swing that causes it) must peak where the mesh frequency meets it;
* **the page follows the numbers**: the summary's sentence is recomputed after the values are
  rewritten (below and above the threshold).
"""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest
import xarray as xr

import geardyn
from geardyn.errors import InputError
from geardyn.studies.model_regimes import (
    AXES,
    MAIN_SIGNALS,
    NOT_RUN,
    SIGNALS,
    THRESHOLD,
    centre_distance_modes,
    compare_point,
    load_study_sweep,
    model_regimes,
    point_case,
    run_times,
    study_case,
)
from geardyn.studies.model_regimes_report import regime_summary, write_report

#: A coarse map and short records: the plumbing tests need no accuracy.
COARSE = {"stiffness.method": "pem", "stiffness.centre_distances": 6,
          "stiffness.nodes_per_segment": 8, "simulation.settle_time": 0.02,
          "simulation.record_time": 0.02}


def _coarse_base():
    return study_case(geardyn.paper_case().with_overrides(COARSE, source="test"))


def _closed_form_mode(case) -> float:
    """[Hz] of the centre-distance mode with a rigid mesh and rigid couplings (module doc)."""
    pair = case.gear_pair()
    rb1, rb2 = pair.pinion.base_radius, pair.gear.base_radius
    j1 = case.pinion.inertia + case.motor.inertia
    j2 = case.gear.inertia + case.load.inertia
    s = rb1 ** 2 / j1 + rb2 ** 2 / j2
    k, m = case.pinion.bearing_stiffness, case.pinion.mass
    assert k == case.gear.bearing_stiffness and m == case.gear.mass
    return math.sqrt(2 * k / (2 * m + 4 / s)) / (2 * math.pi)


# ------------------------------------------------------------------------------ the sweep
def test_shipped_sweeps_cover_the_issue_ranges():
    sw = load_study_sweep()
    axes = {a.key: a.values for a in sw.axes}
    assert list(axes) == list(AXES)
    assert min(axes["pinion.bearing_stiffness"]) == pytest.approx(1e5)
    assert max(axes["pinion.bearing_stiffness"]) == pytest.approx(1e8)
    assert min(axes["pinion.bearing_damping_ratio"]) == 0.005
    assert max(axes["pinion.bearing_damping_ratio"]) == 0.10
    assert axes["crack.depth"][0] == 0.0 and len(axes["crack.depth"]) >= 3
    assert sw.links == {"gear.bearing_stiffness": "pinion.bearing_stiffness",
                        "gear.bearing_damping_ratio": "pinion.bearing_damping_ratio"}
    # the mesh frequency crosses the closed-form centre-distance mode at every stiffness
    w = np.asarray(axes["load.speed"])
    f_mesh = 23 * w / (2 * np.pi)
    for k in axes["pinion.bearing_stiffness"]:
        f0 = _closed_form_mode(point_case(sw.base_case, k, 0.02, 100.0, 0.0))
        if k <= 1e7:  # the closed form holds while the bearings are much softer than the mesh
            assert f_mesh.min() < f0 < f_mesh.max(), k
    quick = load_study_sweep(quick=True)
    assert quick.n_runs < sw.n_runs
    assert sw.base_case.stiffness.method == "pem"


def test_study_sweep_refuses_what_it_cannot_map(tmp_path):
    text = Path(str(load_study_sweep(quick=True).origin)).read_text()
    bad = tmp_path / "torque.toml"
    bad.write_text(text.replace("[axes]\n", '[axes]\nmotor.torque = ["50 N m", "100 N m"]\n'))
    with pytest.raises(InputError, match="axes.motor.torque"):
        load_study_sweep(bad)
    unlinked = tmp_path / "unlinked.toml"
    unlinked.write_text(text.replace('gear.bearing_stiffness = "pinion.bearing_stiffness"\n',
                                     ""))
    with pytest.raises(InputError, match="link.gear.bearing_stiffness"):
        load_study_sweep(unlinked)


def test_study_case_refuses_what_it_cannot_sweep():
    case = geardyn.paper_case()
    with pytest.raises(InputError, match="pinion.bearing_damping"):
        study_case(case.with_overrides({"pinion.bearing_damping": 50.0}, source="t"))
    with pytest.raises(InputError, match="load.coefficient"):
        study_case(case.with_overrides({"load.coefficient": 0.8}, source="t"))
    base = study_case(case)
    # the map reaches the contact-ratio-1 limit of the pair, and not beyond it
    limit = case.gear_pair().max_centre_distance_change()
    assert limit - 1e-5 < base.stiffness.centre_distance_max <= limit


def test_run_times_follow_the_rules():
    from geardyn.dynamics import DynamicModel
    from geardyn.stiffness import build_map

    base = _coarse_base()
    for k, zeta, w in ((1e6, 0.005, 25.0), (1e8, 0.1, 360.0)):
        case = point_case(base, k, zeta, w, 0.0)
        dyn = DynamicModel.from_case(case, build_map(case, cracked=False))
        settle, record = run_times(case, dyn)
        modes = centre_distance_modes(dyn)
        sigma = modes["decay_rate"][modes["index"]]
        dt = case.simulation.dt
        assert settle >= max(3 / sigma, case.simulation.settle_time) - 1e-12
        assert settle < max(3 / sigma, case.simulation.settle_time) + dt + 1e-12
        assert abs(settle / dt - round(settle / dt)) < 1e-6
        revs = record * w / (2 * np.pi)
        assert revs == pytest.approx(round(revs), abs=1e-9) and round(revs) >= 2
        assert record >= case.simulation.record_time


# ------------------------------------------------------------------------- exact zero
def test_centre_distance_independent_map_gives_zero_difference():
    """Identical inputs: a one-line map, K(theta) the same at every centre distance."""
    from geardyn.stiffness import build_map
    from geardyn.stiffness.map import StiffnessMap

    case = point_case(_coarse_base(), 1e6, 0.02, 120.0, 0.0, settle_time=0.05,
                      record_time=0.2)
    real = build_map(case, cracked=False)
    n = 2048
    theta = (np.arange(n) + 0.5) * real.period / n
    flat = StiffnessMap.from_table(case.gear_pair(), theta, real(theta, np.full(n, 1.07e-3)))
    res = compare_point(case, flat, start_evaluation=False)
    assert res["status_ii"] == 0 and res["status_i_static"] == 0
    assert res["centre_distance_std"] > 1e-7  # the centre distance does move ...
    for s in SIGNALS:  # ... and changes nothing
        assert res[f"ratio__{s}"] == pytest.approx(0.0, abs=1e-9), s
    # with the real map the same point differs (the zero is not a plumbing artefact)
    res = compare_point(case, real, start_evaluation=False)
    assert res["ratio__mesh_stiffness"] > 1e-4


def test_static_point_beyond_the_map_is_not_run():
    """k = 1e5 N/m at 100 N m: eq. 4 opens the centre distance past the contact-ratio-1 end."""
    from geardyn.stiffness import build_map

    case = point_case(_coarse_base(), 1e5, 0.02, 100.0, 0.0)
    smap = build_map(case, cracked=False)
    res = compare_point(case, smap)
    assert res["static_centre_distance_change"] > smap.dd[-1]
    assert all(res[f"status_{r}"] == NOT_RUN for r in ("ii", "i_static", "ii_start"))
    assert math.isnan(res["ratio__mesh_force"])


# --------------------------------------------------------- the resonance, in closed form
def test_closed_form_mode_matches_the_eigen_analysis():
    from geardyn.dynamics import DynamicModel
    from geardyn.stiffness import build_map

    base = _coarse_base()
    for k in (3e5, 1e6, 3e6):
        case = point_case(base, k, 0.02, 100.0, 0.0)
        dyn = DynamicModel.from_case(case, build_map(case, cracked=False))
        modes = centre_distance_modes(dyn)
        f = modes["frequency"][modes["index"]]
        # the closed form neglects the mesh compliance (k / k_mb <= 3e-2) and the couplings'
        # (their modes lie above 1 kHz): a few per cent at most
        assert f == pytest.approx(_closed_form_mode(case), rel=0.03), k
        assert modes["share"][modes["index"]] > 0.3


@pytest.mark.slow
def test_ratio_peaks_where_the_mesh_frequency_meets_the_closed_form_mode():
    """k = 1e6 N/m, zeta = 2 %: speeds with mesh frequency / closed-form mode from 0.6 to 1.5
    (above the 1/2 and 1/3 sub-harmonics, where the mesh's 2nd and 3rd harmonics excite the
    mode). The ratio and the centre-distance swing must both be largest at one of the grid
    points bracketing 1 (0.9, 1.0, 1.1), and smaller at both ends."""
    from geardyn.stiffness import build_map

    base = study_case(geardyn.paper_case().with_overrides(
        {"stiffness.method": "pem", "simulation.settle_time": 0.05,
         "simulation.record_time": 0.2}, source="test"))
    f0 = _closed_form_mode(point_case(base, 1e6, 0.02, 100.0, 0.0))
    rs = np.array([0.6, 0.7, 0.8, 0.9, 1.0, 1.1, 1.25, 1.5])
    ratio, swing = [], []
    smap = None
    from geardyn.studies.model_regimes import timed_case

    for r in rs:
        case = point_case(base, 1e6, 0.02, float(r * f0 * 2 * np.pi / 23), 0.0)
        smap = smap or build_map(case, cracked=False)
        case, _, _ = timed_case(case, smap)
        res = compare_point(case, smap, start_evaluation=False)
        ratio.append(max(res[f"ratio__{s}"] for s in MAIN_SIGNALS))
        swing.append(res["centre_distance_std"])
    ratio, swing = np.array(ratio), np.array(swing)
    assert np.all(np.isfinite(ratio))
    assert 0.9 <= rs[np.argmax(ratio)] <= 1.1, ratio
    assert 0.9 <= rs[np.argmax(swing)] <= 1.1, swing
    assert max(ratio[0], ratio[-1]) < ratio.max()


# ------------------------------------------------------------ the study end to end (Dask)
TINY = """
name = "tiny_model_regimes"
base = "xue_howard"
[set]
stiffness.method = "pem"
stiffness.centre_distances = 6
stiffness.nodes_per_segment = 8
simulation.settle_time = "0.02 s"
simulation.record_time = "0.02 s"
[axes]
pinion.bearing_stiffness = ["1e5 N/m", "1e8 N/m"]
load.speed = ["300 rad/s", "360 rad/s"]
[link]
gear.bearing_stiffness = "pinion.bearing_stiffness"
[execution]
batch_size = 2
"""


@pytest.fixture(scope="module")
def tiny(tmp_path_factory):
    """k = 1e5 N/m (statically beyond contact ratio 1 at 100 N m: not run) and 1e8 N/m, two
    high speeds; crack depth and damping not swept (the base case's 5 mm and 5 %)."""
    pytest.importorskip("distributed")
    from distributed import Client

    tmp = tmp_path_factory.mktemp("tiny")
    (tmp / "tiny.toml").write_text(TINY)
    stages = []
    with Client(processes=False, n_workers=1, threads_per_worker=1,
                dashboard_address=":0") as client:
        ds = model_regimes(tmp / "store.zarr", sweep=tmp / "tiny.toml", client=client,
                           progress=lambda s, d, n: stages.append((s, d, n)))
    return ds, stages, tmp


@pytest.mark.slow
def test_tiny_study_structure(tiny):
    ds, stages, _ = tiny
    assert dict(ds.sizes) == {"crack_depth": 1, "damping_ratio": 1, "bearing_stiffness": 2,
                              "pinion_speed": 2, "signal": len(SIGNALS), "convergence_dt": 4,
                              "convergence_signal": len(MAIN_SIGNALS), "runup_window": 60,
                              "runup_signal": len(MAIN_SIGNALS)}
    assert ds.crack_depth.values.tolist() == [5e-3] and ds.damping_ratio.values.tolist() == [0.05]
    # k = 1e5 N/m: not run, NaN
    assert np.all(ds.status_ii.values[..., 0, :] == NOT_RUN)
    assert np.all(np.isnan(ds.ratio_max.values[..., 0, :]))
    # k = 1e8 N/m runs; the headline is the largest main-signal ratio
    for v in ("status_ii", "status_i_static", "status_ii_start"):
        assert np.all(ds[v].values[..., 1, :] == 0)
    r = ds.rms_ii_minus_i_static.sel(signal=list(MAIN_SIGNALS)).values[:, 0, 0, 1, :]
    assert np.array_equal(ds.ratio_max.values[0, 0, 1, :], r.max(axis=0))
    assert np.all(np.isfinite(ds.rms_ii_minus_ii_start.values[:, 0, 0, 1, :]))
    assert np.allclose(ds.mesh_frequency.values, 23 * ds.pinion_speed.values / (2 * np.pi))
    # the time-step check ran at the largest ratio; its reference has zero error
    assert ds.attrs["convergence_status"] == "ok"
    assert np.all(ds.convergence_error_predictor.values[-1] == 0)
    assert ("time-step check", 1, 1) in stages and ("simulations", 4, 4) in stages
    assert stages[-1] == ("run-up", 2, 2) and ds.attrs["runup_status"] == "ok"


@pytest.mark.slow
def test_tiny_study_netcdf_has_units_and_long_name_everywhere(tiny):
    """Every data variable and coordinate of model_regimes.nc (written as the CLI writes it)
    has a non-empty ``units`` ("1" for dimensionless numbers and labels) and ``long_name``."""
    from geardyn.io import write_netcdf_atomic

    ds, _, tmp = tiny
    path = tmp / "model_regimes.nc"
    write_netcdf_atomic(ds, path)
    with xr.open_dataset(path) as nc:
        names = list(nc.data_vars) + list(nc.coords)
        # the label and index coordinates and the error messages are in the file
        assert {"signal", "convergence_signal", "runup_signal", "runup_window",
                "error"} <= set(names)
        missing = [(n, a) for n in names for a in ("units", "long_name")
                   if not str(nc[n].attrs.get(a, "")).strip()]
        assert missing == []
        for n in ("signal", "convergence_signal", "runup_signal", "runup_window", "error",
                  "ratio_max", "status_ii"):
            assert nc[n].attrs["units"] == "1", n
        assert nc["pinion_speed"].attrs["units"] == "rad/s"
        assert nc["convergence_dt"].attrs["units"] == "s"


@pytest.mark.slow
def test_tiny_study_page_and_resume(tiny):
    ds, _, tmp = tiny
    page = write_report(ds, tmp / "page", command="test")
    text = page.read_text()
    assert "Range explored" in text and "data:image/png;base64," in text
    assert "A run-up through the centre-distance mode" in text
    assert (tmp / "page" / "figures" / "ratio_maps.png").stat().st_size > 10_000
    from distributed import Client

    with Client(processes=False, n_workers=1, threads_per_worker=1,
                dashboard_address=":0") as client:
        again = model_regimes(tmp / "store.zarr", sweep=tmp / "tiny.toml", client=client,
                              convergence=False)
    assert again.attrs["sweep_computed_now"] == 0 and again.attrs["sweep_resumed"] == 1
    assert np.array_equal(again.ratio_max.values, ds.ratio_max.values, equal_nan=True)


# ------------------------------------------------------------- the page follows the numbers
def _synthetic(ratio: np.ndarray) -> xr.Dataset:
    """A study Dataset with given ratio_max (crack 2 x zeta 1 x k 2 x speed 3) and the rest
    filled plainly; the first stiffness is 'not run'."""
    shape = ratio.shape
    dims = tuple(AXES[k][0] for k in AXES)
    status = np.zeros(shape, np.int8)
    status[:, :, 0, :] = NOT_RUN
    ratio = np.where(status == NOT_RUN, np.nan, ratio)
    per = np.repeat(ratio[None], len(SIGNALS), axis=0)
    per[[SIGNALS.index(s) for s in MAIN_SIGNALS[1:]]] *= 0.5  # the first main signal leads
    data = {v: (dims, status) for v in ("status_ii", "status_i_static", "status_ii_start")}
    data |= {v: (dims, np.where(status == 0, 0.0, np.nan)) for v in (
        "iterating_fraction", "max_iterations", "steps_without_fixed_point",
        "start_steps_without_fixed_point")}
    data |= {"start_iterating_fraction": (dims, np.where(status == 0, 0.2, np.nan)),
             "start_max_iterations": (dims, np.where(status == 0, 3.0, np.nan)),
             "ratio_max": (dims, ratio),
             "rms_ii_minus_i_static": (("signal", *dims), per),
             "rms_ii_minus_ii_start": (("signal", *dims), np.full(per.shape, 0.3)),
             "mode_frequency": (dims, np.broadcast_to(np.array([50.0, 500.0])[None, None, :,
                                                                              None], shape)),
             "static_centre_distance_change": (dims, np.full(shape, 1e-3))}
    w = np.array([10.0, 30.0, 100.0])
    return xr.Dataset(data, coords={"crack_depth": [0.0, 5e-3], "damping_ratio": [0.02],
                                    "bearing_stiffness": [1e5, 1e7], "pinion_speed": w,
                                    "signal": list(SIGNALS),
                                    "mesh_frequency": ("pinion_speed", 23 * w / (2 * np.pi))},
                      attrs={"threshold": THRESHOLD, "input_torque": 100.0,
                             "stiffness_method": "pem"})


def test_summary_says_nowhere_with_the_range_when_nothing_exceeds():
    s = regime_summary(_synthetic(np.full((2, 1, 2, 3), 0.05)))
    assert s["above"] == 0 and s["compared"] == 6 and s["not_run"] == 6
    assert s["sentence"].startswith("Nowhere in the range explored")
    assert "1e+05..1e+07 N/m" in s["sentence"] and "10..100 rad/s" in s["sentence"]
    assert "5 %" in s["sentence"]  # the largest ratio found, in per cent
    # one damping ratio is said as one value, not as the range "2..2 % (1 values)"
    assert "damping ratio 2 % (1 value)" in s["ranges"] and "2..2" not in s["ranges"]
    assert "(2 values, both bearings)" in s["ranges"]


def test_summary_says_where_it_exceeds():
    r = np.full((2, 1, 2, 3), 0.05)
    r[1, 0, 1, 2] = 0.25
    s = regime_summary(_synthetic(r))
    assert s["above"] == 1 and "at 1 of the 6 points" in s["sentence"]
    assert s["max_ratio"] == 0.25 and s["max_signal"] == MAIN_SIGNALS[0]
    assert "100 rad/s" in s["max_point"] and "crack 5 mm" in s["max_point"]
    assert s["crack_effect"] == pytest.approx(0.20)
    row = s["by_stiffness"][1]
    assert row[4] == 1 and row[6] == "100"


def test_page_says_one_stiffness_above_as_one_value(tmp_path):
    """The points above the threshold at one bearing stiffness: '1e+07 N/m', not the range
    '1e+07..1e+07 N/m'; at two stiffnesses the range stays."""
    import re

    r = np.full((2, 1, 2, 3), 0.05)
    r[1, 0, 1, 2] = 0.25
    one = write_report(_synthetic(r), tmp_path / "one", command="test").read_text()
    said = re.findall(r"have bearing stiffness ([^ ]+) N/m", one)
    assert said == ["1e+07"]
    # the first stiffness run as well, and above the threshold at one point
    ds = _synthetic(r)
    for v in ("status_ii", "status_i_static", "status_ii_start"):
        ds[v][:, :, 0, :] = 0
    for v in ("iterating_fraction", "max_iterations", "steps_without_fixed_point",
              "start_steps_without_fixed_point"):
        ds[v][:] = 0.0
    ds["ratio_max"][1, 0, 0, 2] = 0.3
    ds["rms_ii_minus_i_static"][:, 1, 0, 0, 2] = 0.3
    two = write_report(ds, tmp_path / "two", command="test").read_text()
    assert re.findall(r"have bearing stiffness ([^ ]+) N/m", two) == ["1e+05..1e+07"]
