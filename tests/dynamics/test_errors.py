"""Bad input and numerical failure: clear errors naming the field, the time and the state."""

from __future__ import annotations

import numpy as np
import pytest

from geardyn.dynamics import simulate
from geardyn.errors import InputError, NumericalError

from ._support import geometric_map, short_case, triangle_map


@pytest.fixture(scope="module")
def case():
    return short_case(**{"simulation.record_time": 0.005})


@pytest.fixture(scope="module")
def smap(case):
    return geometric_map(case.gear_pair())


def test_too_coarse_time_step_is_refused(case, smap):
    with pytest.raises(InputError) as ei:
        simulate(case.with_overrides({"simulation.dt": 5e-5}), smap)
    assert ei.value.field == "simulation.dt"
    from geardyn.dynamics import DynamicModel, max_time_step

    dt_max = max_time_step(DynamicModel.from_case(case, smap), smap)[0]
    msg = str(ei.value)
    assert "steps per period" in msg and "Hz" in msg and f"<= {dt_max:.4g} s" in msg


def test_bad_model_name(case, smap):
    with pytest.raises(InputError, match="model"):
        simulate(case, smap, model="III")


def test_map_without_the_operating_point(case):
    narrow = geometric_map(case.gear_pair(), dd=(-0.5e-3, 0.5e-3))
    with pytest.raises(InputError, match="centre_distance_max"):
        simulate(case, narrow, model="II")
    assert simulate(case, narrow, model="I").attrs["complete"] == 1


def test_centre_distance_leaving_the_map_stops_with_the_state_and_a_partial_record(case):
    """A map only +/- 0.3 um around the static point: the handover transients leave it."""
    tight = geometric_map(case.gear_pair(), dd=(1.0849e-3, 1.0855e-3), n_d=3)
    with pytest.raises(NumericalError) as ei:
        simulate(case, tight, model="II")
    exc = ei.value
    assert "left the stiffness map's range" in str(exc)
    assert "1.0849" in str(exc) and "1.0855" in str(exc)       # the map's range, in mm
    assert exc.time is not None and 0 < exc.time < 0.005
    assert "centre_distance_change" in exc.state and "theta_p" in exc.state
    dd = exc.state["centre_distance_change"]
    assert not 1.0849e-3 <= dd <= 1.0855e-3
    part = exc.partial
    assert part.attrs["complete"] == 0 and "left the stiffness map" in part.attrs["failure"]
    assert 0 < part.sizes["time"] and float(part.time[-1]) < exc.time
    assert np.isfinite(part.theta_p.values).all()


def test_iteration_limit(case):
    """A tolerance below rounding cannot be met: the step fails after max_iterations."""
    c = case.with_overrides({"simulation.tolerance": 1e-18, "simulation.max_iterations": 1})
    with pytest.raises(NumericalError, match="did not converge") as ei:
        simulate(c, triangle_map(case.gear_pair()), model="II")
    assert ei.value.state["iterations"] == 1
    assert ei.value.time == pytest.approx(1e-5)


def test_load_laws_without_a_steady_state(smap):
    c = short_case(**{"load.law": "constant", "load.coefficient": 50.0})
    with pytest.raises(InputError, match="load.coefficient"):
        simulate(c, smap)
    c = short_case(**{"load.law": "table", "load.table_speeds": [0.0, 100.0],
                      "load.table_torques": [0.0, 10.0]})
    with pytest.raises(InputError, match="balances the input torque"):
        simulate(c, smap)


def test_runaway_is_reported_with_time_state_and_partial_record(case, smap, monkeypatch):
    """The divergence guard (|p| beyond its sanity limit) stops the run with the time and the
    state; valid input cannot diverge, so the limit is lowered here to trigger it mid-run."""
    from geardyn.dynamics import _kernel as K
    from geardyn.dynamics import newmark

    original = newmark._setup_for_case

    def low_limit(*args, **kw):
        setup = original(*args, **kw)
        setup.fp[K.FP_PLIM] = 1.2e-5          # inside the mesh deflection's dynamic range
        return setup

    monkeypatch.setattr(newmark, "_setup_for_case", low_limit)
    with pytest.raises(NumericalError, match="runaway mesh deflection") as ei:
        simulate(case, smap, model="I")
    exc = ei.value
    assert exc.time > 0 and abs(exc.state["mesh_deflection"]) > 1.2e-5
    assert "t = " in str(exc) and "mesh_deflection" in str(exc)
    assert exc.partial.attrs["complete"] == 0
    assert exc.partial.sizes["time"] == round(exc.time / 1e-5)
