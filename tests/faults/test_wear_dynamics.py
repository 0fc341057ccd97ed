"""Wear in the dynamics and the static TE (issue 15: "wear ... as a profile deviation").

A uniform wear of depth ``delta`` over a tooth's flank is a gap ``delta`` along the line of action
(:mod:`geardyn.faults.wear`), which :class:`geardyn.modifications.ToothModifications` adds to that
tooth's deviation table. Oracles, with the same stiffness map (``stiffness = false``):

* loaded static TE in single contact of the worn pair: ``p = F/k + delta``, so the TE rises by
  exactly ``delta``; in double contact by ``delta k_w/(k_w + k_o)``, strictly between 0 and
  ``delta``; with the worn tooth out of mesh, not at all;
* the worn tooth is in mesh for one contact interval per revolution: ``eps Theta_m`` of pinion
  angle (``eps`` the contact ratio at the operating point);
* zero depth is no wear (bit for bit).
"""

from __future__ import annotations

import math
import warnings
from pathlib import Path

import numpy as np
import pytest

from geardyn.config import load_case
from geardyn.dynamics import simulate
from geardyn.modifications import ToothModifications
from geardyn.static_te import static_transmission_error
from geardyn.stiffness import build_map

from .._cli_fork import run_geardyn

WEAR = Path(__file__).resolve().parents[2] / "examples" / "faults" / "wear.toml"
DELTA = 5e-6


def _case(depth=DELTA, **over):
    return load_case(WEAR, {"faults.0.stiffness": False, "faults.0.depth": depth,
                            "stiffness.centre_distances": 3, **over})


@pytest.fixture(scope="module")
def healthy_map():
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        return build_map(_case(), cracked=False)


def test_static_te_rises_by_the_wear_depth_in_single_contact(healthy_map):
    case = _case()
    pair = case.gear_pair()
    mods = ToothModifications.from_case(case)
    assert mods.active and "wear of tooth 11" in mods.describe()
    th = np.linspace(0.0, 2 * math.pi, 23 * 400, endpoint=False)
    worn = static_transmission_error(healthy_map, 100.0, modifications=mods, theta=th)
    perfect = static_transmission_error(healthy_map, 100.0,
                                        modifications=ToothModifications.none(pair), theta=th)
    d = (worn.transmission_error.values - perfect.transmission_error.values) * 1e-6  # [m]
    n = worn.loaded_pairs.values
    on = d > 1e-12
    single, double = on & (n == 1), on & (n == 2)
    assert single.sum() > 100 and double.sum() > 100
    np.testing.assert_allclose(d[single], DELTA, rtol=1e-9)
    assert np.all((d[double] > 0) & (d[double] < DELTA))
    assert np.all(d >= -1e-15)
    # in mesh for one contact interval of the worn tooth per revolution
    eps = pair.operating(0.0).contact_ratio
    span = on.mean() * 2 * math.pi
    assert span == pytest.approx(eps * pair.mesh_angle, rel=0.01)


def test_zero_depth_is_no_wear_and_the_dynamics_see_the_gap(healthy_map):
    quick = {"simulation.settle_time": 0.02, "simulation.record_time": 0.06}
    zero = _case(0.0, **quick)
    assert not ToothModifications.from_case(zero).active
    worn = _case(**quick)
    a = simulate(zero, healthy_map, model="II")
    b = simulate(zero.with_overrides({"faults": []}), healthy_map, model="II")
    for v in a.data_vars:
        assert np.array_equal(a[v].values, b[v].values, equal_nan=True), v
    w = simulate(worn, healthy_map, model="II")
    e = w["mesh_error"].values  # the load-share-weighted gap of the loaded pairs [m]
    assert np.nanmax(e) == pytest.approx(DELTA, rel=1e-9)   # the worn pair alone in contact
    assert np.nanmin(e) >= 0.0 and np.mean(e == 0.0) > 0.5   # out of mesh most of the time
    assert np.std(w.transmission_error.values) != np.std(a.transmission_error.values)


def test_the_healthy_runs_of_a_study_carry_no_wear(healthy_map, tmp_path):
    """A study's healthy pair has no faults: ``without_faults`` removes the wear gap from the
    tooth deviations (the maps leave faults out with ``cracked=False``); the faulty runs keep
    it. Checked on ``geardyn simulate --no-crack`` and the ``geardyn run`` pipeline's cases."""
    import xarray as xr

    from geardyn.faults import without_faults

    worn = _case()
    assert ToothModifications.from_case(worn).active
    healthy = without_faults(worn)
    assert not ToothModifications.from_case(healthy).active and healthy.faults == []
    plain = load_case(WEAR.parent.parent.parent / "src" / "geardyn" / "cases" / "xue_howard.toml")
    assert without_faults(plain) is plain  # no faults: the same case, the same cache keys
    args = ["simulate", "--config", str(WEAR), "--set",
            "faults.0.stiffness=false", "--set", f"faults.0.depth={DELTA}", "--set",
            "stiffness.centre_distances=3", "--set", "simulation.settle_time=0.02", "--set",
            "simulation.record_time=0.06"]
    for flag in ("--no-crack", "--crack"):
        out = tmp_path / f"{flag}.nc"
        r = run_geardyn([*args, flag, "--out", str(out)], timeout=600)
        assert r.returncode == 0, r.stderr
        with xr.open_dataset(out) as ds:
            if flag == "--no-crack":  # perfect teeth: no deviation recorded at all
                assert "mesh_error" not in ds
            else:
                assert float(np.nanmax(ds["mesh_error"].values)) == pytest.approx(DELTA,
                                                                                   rel=1e-9)
