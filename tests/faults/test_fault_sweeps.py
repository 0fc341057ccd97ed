"""A sweep over fault size runs through ``geardyn sweep`` for every fault type (issue 15, must
show; the spall's is ``test_examples.py::test_sweep_over_spall_width``).

Each sweep is a partial case over the paper's (the example of the type) with three sizes from
zero, short model II records and coarse PEM maps. Oracle: a zero-size fault is the healthy gear
(its records equal those of the case without the faults list, so the TSA's residual carries only
the integration residue), and the fault's own signature grows with its size: the energy ratio
of the gear bearing's velocity (residual energy over regular-meshing energy) rises strictly.
"""

from __future__ import annotations

import os
from pathlib import Path

import numpy as np
import pytest

from .._cli_fork import run_geardyn

EXAMPLES = Path(__file__).resolve().parents[2] / "examples" / "faults"

SWEEP = """
name = "{name}"
base = "{base}"
seed = 3
[set]
simulation.record_time = "0.12 s"
simulation.settle_time = "0.02 s"
stiffness.centre_distances = 4
stiffness.nodes_per_segment = 12
[axes]
{axis} = {values}
[store]
signals = ["v_yg", "transmission_error"]
tsa = false
raw = false
[execution]
batch_size = 3
"""

CASES = [
    ("root_crack_gear.toml", "faults.0.depth", '["0 mm", "1.5 mm", "3 mm"]'),
    ("partial_crack.toml", "faults.0.width", '["0 mm", "10 mm", "20 mm"]'),
    ("breakage.toml", "faults.0.height", '["0 mm", "1 mm", "2 mm"]'),
    ("wear.toml", "faults.0.depth", '["0 um", "15 um", "30 um"]'),
]


@pytest.mark.slow
@pytest.mark.parametrize("base, axis, values", CASES, ids=[c[0].split(".")[0] for c in CASES])
def test_fault_size_sweep_through_the_cli(tmp_path, base, axis, values):
    from geardyn.studies.sweep import open_sweep

    spec = tmp_path / "sweep.toml"
    spec.write_text(SWEEP.format(name=base.split(".")[0], base=(EXAMPLES / base).as_posix(),
                                 axis=axis, values=values))
    store = tmp_path / "s.zarr"
    r = run_geardyn(["sweep", str(spec), "--out", str(store),
                     "--workers", "1"], capture_output=True, text=True, timeout=900,
                    cwd=tmp_path, env={**os.environ, "GEARDYN_PROGRESS": "0"})
    assert r.returncode == 0, r.stdout + r.stderr
    ds = open_sweep(store).load()
    assert np.all(ds.status.values == 1), ds.error.values
    er = ds["v_yg__EnergyRatio"].values
    assert np.all(np.diff(er) > 0), (axis, er)
