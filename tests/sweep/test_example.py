"""The shipped example: the script plots what the store holds (examples are tests)."""

from __future__ import annotations

import runpy
import subprocess
import sys
import textwrap

import numpy as np
import pytest

from geardyn.studies.sweep import open_sweep, parse_sweep, run_sweep

from ._procs import ROOT, env

SCRIPT = ROOT / "examples" / "plot_sweep.py"

SWEEP = textwrap.dedent("""
    name = "example-small"
    [set]
    simulation.record_time = "0.15 s"
    simulation.settle_time = "0.02 s"
    stiffness.centre_distances = 6
    stiffness.nodes_per_segment = 6
    stiffness.method = "pem"
    [axes]
    crack.depth = ["1 mm", "3 mm", "5 mm"]
    motor.torque = ["80 N m", "120 N m"]
    pinion.bore_radius = ["20 mm", "70 mm"]
    [execution]
    batch_size = 4
""")


@pytest.mark.slow
def test_plot_sweep_example(tmp_path, client):
    store = tmp_path / "small.zarr"
    res = run_sweep(parse_sweep(SWEEP), store, client=client)
    assert (res.ok, res.failed) == (6, 6)  # the 70 mm bores fail in the geometry
    png = tmp_path / "fm4.png"
    r = subprocess.run([sys.executable, str(SCRIPT), str(store), "--metric", "v_yg__FM4",
                        "--out", str(png)], capture_output=True, text=True, env=env(),
                       timeout=120)
    assert r.returncode == 0, r.stderr
    assert png.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n" and png.stat().st_size > 10_000

    main = runpy.run_path(str(SCRIPT))["main"]
    fig, lines = main([str(store), "--out", str(tmp_path / "b.png")])
    ds = open_sweep(store).load()
    ok = ds.status.values == 1
    # one line per torque (the failed bore radius drops out), ordered by crack depth
    assert len(lines) == 2
    for label, (x, y) in lines.items():
        torque = float(label.split("motor.torque = ")[1].split(" ")[0])
        sel = ok & (ds["motor.torque"].values == torque)
        np.testing.assert_array_equal(x, [0.001, 0.003, 0.005])
        np.testing.assert_array_equal(y, ds["v_yg__FM4"].values[sel])
    with pytest.raises(SystemExit, match="signal one of omega_p, transmission_error, v_yg"):
        main([str(store), "--metric", "nope"])
