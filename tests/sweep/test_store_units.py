"""Units of the stored signal results: the simulation record's own ``units`` attributes.

Oracle: the records :func:`geardyn.dynamics.simulate` writes (6-DOF with tooth errors, so it
has ``mesh_error``; transverse with friction and free centres), whose variables carry their
unit. Every signal the store accepts must have that unit, non-empty, in every stored variable
of the signal's own unit.
"""

from __future__ import annotations

import textwrap

import numpy as np
import pytest

from geardyn import paper_case
from geardyn.studies.sweep import RECORD_SIGNALS, GeardynEvaluator, parse_sweep, run_sweep
from geardyn.studies.sweep.spec import StoreSpec

QUICK = {"simulation.record_time": 0.01, "simulation.settle_time": 0.0,
         "stiffness.centre_distances": 6, "stiffness.nodes_per_segment": 6,
         "stiffness.method": "pem"}
RECORDS = {"6-dof with tooth errors": {"modifications.pinion.runout": 1e-6},
           "transverse": {"simulation.dynamics": "transverse", "mesh.friction_coefficient": 0.05}}

#: Variables of the signal's own unit, per signal s (the rest are dimensionless, "1").
OWN_UNIT = ("mean", "std", "rms", "peak_to_peak", "mesh_harmonic_rms", "tsa", "series")


@pytest.fixture(scope="module")
def record_units() -> dict[str, str]:
    """Unit of every time series of the two records, from the records themselves."""
    from geardyn.dynamics import simulate
    from geardyn.stiffness import build_map

    units: dict[str, str] = {}
    for extra in RECORDS.values():
        case = paper_case({**QUICK, **extra})
        ds = simulate(case, build_map(case, cracked=True))
        for name, var in ds.data_vars.items():
            if var.dims == ("time",):
                u = var.attrs["units"]
                assert units.setdefault(name, u) == u, name  # one unit per name across models
    return units


def test_the_signal_table_is_the_records_units(record_units):
    # both ways: every record signal is storable, and every storable signal is in a record
    assert set(RECORD_SIGNALS) == set(record_units)
    for name, unit in RECORD_SIGNALS.items():
        assert unit, name
        assert unit == record_units[name], name


def test_every_storable_signal_gets_the_records_unit(record_units):
    signals = list(RECORD_SIGNALS)
    ev = GeardynEvaluator(StoreSpec(signals=signals, tsa=True, raw=True))
    case = paper_case(QUICK)
    outs = {o.name: o.units for o in ev.outputs(case, {"__time__": np.zeros(4)})}
    for s in signals:
        for f in OWN_UNIT:
            assert outs[f"{s}__{f}"] == record_units[s], (s, f)
        for f in ("kurtosis", "FM4", "NA4", "residual_kurtosis"):
            assert outs[f"{s}__{f}"] == "1", (s, f)
    # the QA case: centre_distance_change is in metres, not ''
    assert {outs[f"centre_distance_change__{f}"] for f in OWN_UNIT} == {"m"}
    assert outs["theta_p__series"] == "rad"


def test_the_friction_example_stores_metres(tmp_path, client):
    # the store of examples/transverse/sweep_friction.toml's [store], on 2 short runs
    sw = parse_sweep(textwrap.dedent("""
        name = "friction_units"
        [set]
        stiffness.method = "pem"
        stiffness.centre_distances = 6
        stiffness.nodes_per_segment = 6
        simulation.dynamics = "transverse"
        simulation.record_time = "0.2 s"
        simulation.settle_time = "0.02 s"
        [axes]
        mesh.friction_coefficient = [0.0, 0.05]
        [store]
        signals = ["v_yg", "x_p", "centre_distance_change"]
        [execution]
        batch_size = 2
    """))
    res = run_sweep(sw, tmp_path / "f.zarr", client=client)
    assert res.ok == 2, res
    import xarray as xr

    ds = xr.open_zarr(tmp_path / "f.zarr")
    for f in ("mean", "std", "rms", "peak_to_peak", "mesh_harmonic_rms"):
        assert ds[f"centre_distance_change__{f}"].attrs["units"] == "m", f
        assert ds[f"x_p__{f}"].attrs["units"] == "m", f
        assert ds[f"v_yg__{f}"].attrs["units"] == "m/s", f
    assert np.all(np.isfinite(ds["centre_distance_change__rms"].values))
