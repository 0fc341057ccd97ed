"""An FE stiffness map (the coarse test mesh of tests/fe/conftest.py) with tooth errors: the
static transmission error and a short model II simulation, against closed forms.

Oracles: with runout only, every pair in contact has the same error ``e_run(theta)``, so the
loaded static TE is ``e_run + N / k_mb(theta - e_run / r_b1)`` exactly (the mesh approach of all
pairs shifted by the common error, the pattern moved along the line of action); unloaded, the
TE of any error set is the smallest error of the pairs in contact (pure geometry, no stiffness).
"""

from __future__ import annotations

import warnings

import numpy as np
import pytest

from geardyn.modifications import ToothModifications
from geardyn.static_te import static_transmission_error
from geardyn.stiffness import StiffnessMap
from tests.fe.conftest import coarse_settings

pytestmark = pytest.mark.slow  # meshes and factorises two FE bodies (about 10 s)


@pytest.fixture(scope="module")
def fe_healthy(_private_cache):
    """Healthy FE map of the paper pair on the coarse test mesh, dd in {0, 1.5 mm} (the static
    operating point, +1.07 mm, lies inside)."""
    import geardyn
    from geardyn.stiffness.fe import FEStiffness

    case = geardyn.paper_case({"stiffness.method": "fe", "stiffness.nodes_per_segment": 6,
                               "simulation.settle_time": 0.0, "simulation.record_time": 0.01})
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        model = FEStiffness(case, cracked=False, settings=coarse_settings(case))
        smap = StiffnessMap.from_function(model.pair, np.array([0.0, 1.5e-3]), model.evaluate,
                                          n_seg=case.stiffness.nodes_per_segment,
                                          attrs=model.attrs())
    assert "load_share" in smap.extra and smap.attrs["method"] == "fe"
    return case, smap


def test_runout_on_the_fe_map_shifts_the_loaded_te_exactly(fe_healthy):
    case, smap = fe_healthy
    err = case.with_overrides({"modifications.pinion.runout": 8e-6,
                               "modifications.gear.runout": 5e-6,
                               "modifications.gear.runout_phase": 0.7})
    mods = ToothModifications.from_case(err)
    pair = mods.pair
    rb1 = pair.pinion.base_radius
    th = np.linspace(0.0, 2 * np.pi, 1201, endpoint=False)
    ds = static_transmission_error(smap, 100.0, modifications=mods, theta=th)
    run = mods.runout_error(th)
    want = run + (100.0 / rb1) / smap(th - run / rb1, 0.0)
    np.testing.assert_allclose(ds.transmission_error.values * 1e-6, want, rtol=1e-10)
    assert np.ptp(run) > 20e-6  # the runout is really there (+/- 13 um)


def test_class_6_errors_on_the_fe_map_static_te_and_simulation(fe_healthy):
    from geardyn.dynamics import simulate

    case, smap = fe_healthy
    err = case.with_overrides({"modifications.pinion.grade": 6, "modifications.gear.grade": 6,
                               "modifications.gear.seed": 2})
    mods = ToothModifications.from_case(err)
    th = np.linspace(0.0, 2 * np.pi, 2001, endpoint=False)
    # unloaded: the smallest error of the pairs in contact, whatever the map
    ds0 = static_transmission_error(smap, 0.0, modifications=mods, theta=th)
    pe = mods.pair_errors(th)
    want0 = np.where(pe["in_contact"], pe["e"], np.inf).min(axis=1)
    np.testing.assert_allclose(ds0.transmission_error.values * 1e-6, want0, rtol=0, atol=1e-15)
    # loaded: the approach solves the force balance over the FE pair stiffnesses
    ds = static_transmission_error(smap, 100.0, modifications=mods, theta=th)
    delta = ds.transmission_error.values * 1e-6
    sh = np.where(pe["in_contact"], mods.shares(smap, pe["theta_eff"], 0.0, pe["in_contact"]),
                  0.0)
    k = sh / sh.sum(axis=1, keepdims=True) * smap(th, 0.0)[:, None]
    force = np.sum(np.where(pe["in_contact"], k * np.maximum(delta[:, None] - pe["e"], 0), 0),
                   axis=1)
    np.testing.assert_allclose(force, 100.0 / mods.pair.pinion.base_radius, rtol=1e-9)
    assert np.ptp(delta) > np.ptp(ds0.transmission_error.values * 1e-6) / 2
    # dynamics with the errors on the FE map: the excitation acts, contact is kept, and the
    # mean mesh force is the static one (torque balance)
    sim = simulate(err, smap, model="II")
    assert "mesh_error" in sim and np.ptp(sim.mesh_error.values) > 1e-6
    assert np.all(np.isfinite(sim.mesh_force.values)) and sim.contact.values.min() == 1
    assert abs(float(sim.mesh_force.mean()) / sim.attrs["static_mesh_force"] - 1) < 0.05
