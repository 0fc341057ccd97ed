"""A simulated record holds its own arrays, not views of the kernel's record buffer (a view of
one column keeps every recorded quantity of the buffer alive as long as the record: 92 MB in
the paper's run, issue 16)."""

from __future__ import annotations

import numpy as np
import pytest

from geardyn.dynamics import simulate

from ._support import geometric_map, short_case


@pytest.mark.parametrize("model", ["I", "I-static", "II"])
def test_no_variable_is_a_view_of_a_larger_buffer(model):
    case = short_case(**{"simulation.record_time": 0.01})
    ds = simulate(case, geometric_map(case.gear_pair(), dd=(0.0, 2e-3), n_d=5), model=model)
    checked = 0
    for name, var in ds.variables.items():
        arr = var.values
        assert isinstance(arr, np.ndarray), name
        base = arr
        while base.base is not None and isinstance(base.base, np.ndarray):
            base = base.base
        assert base.nbytes <= arr.nbytes, (name, base.shape, arr.shape)
        checked += 1
    assert checked > 20 and ds.sizes["time"] > 10
    for name in ("mesh_force", "mesh_stiffness", "centre_distance_change", "residual_after"):
        assert name in ds.variables



def test_the_transverse_record_too():
    case = short_case(**{"simulation.record_time": 0.01, "simulation.dynamics": "transverse"})
    ds = simulate(case, geometric_map(case.gear_pair(), dd=(0.0, 2e-3), n_d=5), model="II")
    assert "v_xp" in ds.variables and ds.sizes["time"] > 10
    for name, var in ds.variables.items():
        arr = var.values
        assert arr.base is None or arr.base.nbytes <= arr.nbytes, name
