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

#: A text-valued axis (simulation.model) beside a numeric one, as examples/transverse's sweep
FRICTION = textwrap.dedent("""
    name = "friction-small"
    [set]
    simulation.dynamics = "transverse"
    simulation.record_time = "0.1 s"
    simulation.settle_time = "0.02 s"
    stiffness.centre_distances = 6
    stiffness.nodes_per_segment = 6
    stiffness.method = "pem"
    [axes]
    mesh.friction_coefficient = [0.0, 0.1]
    simulation.model = ["II", "I-static"]
    [store]
    signals = ["v_yg"]
    tsa = false
    raw = false
    [execution]
    batch_size = 4
""")


@pytest.fixture(autouse=True)
def _close_the_scripts_figures():
    """The example script's ``main`` draws with pyplot and returns its figure (the tests look at
    it): closed after each test, so that no figure outlives it in the worker
    (tests/diagnostics/test_plots.py::test_no_pyplot_state checks that geardyn's own plots leave
    none, whichever file the worker ran before)."""
    yield
    if "matplotlib.pyplot" in sys.modules:
        sys.modules["matplotlib.pyplot"].close("all")


@pytest.mark.slow
def test_plot_sweep_example(tmp_path, client):
    store = tmp_path / "small.zarr"
    res = run_sweep(parse_sweep(SWEEP), store, client=client)
    assert (res.ok, res.failed) == (6, 6)  # the 70 mm bores fail in the geometry
    png = tmp_path / "fm4.png"
    r = subprocess.run([sys.executable, str(SCRIPT), str(store), "--metric", "v_yg__FM4",
                        "--x", "crack.depth", "--out", str(png)], capture_output=True, text=True,
                       env=env(),
                       timeout=120)
    assert r.returncode == 0, r.stderr
    assert png.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n" and png.stat().st_size > 10_000

    main = runpy.run_path(str(SCRIPT))["main"]
    # three swept values: the script asks which one goes on the x axis
    with pytest.raises(SystemExit, match="the store sweeps 3 values: choose the x axis with --x, "
                                         "one of crack.depth, motor.torque, pinion.bore_radius"):
        main([str(store), "--out", str(tmp_path / "a.png")])
    with pytest.raises(SystemExit, match="'nope' is not a swept coordinate"):
        main([str(store), "--x", "nope", "--out", str(tmp_path / "a.png")])
    fig, lines = main([str(store), "--x", "crack.depth", "--out", str(tmp_path / "b.png")])
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
    # a metric in the wrong case: the name the store has is suggested, and all are listed
    with pytest.raises(SystemExit, match=r"'v_yg__fm4' is not in the store; did you mean "
                                         r"'v_yg__FM4'\?.* metric one of .*FM4.*rms"):
        main([str(store), "--metric", "v_yg__fm4"])


@pytest.mark.slow
def test_plot_sweep_single_axis_default_and_text_axis(tmp_path, client):
    """The one swept value is the default x; a text-valued axis (simulation.model) labels lines
    and, as --x, gives categories in the sweep's order (it used to die on a format code)."""
    main = runpy.run_path(str(SCRIPT))["main"]
    single = tmp_path / "single.zarr"
    res = run_sweep(parse_sweep(SWEEP.replace('motor.torque = ["80 N m", "120 N m"]\n', "")
                                .replace('pinion.bore_radius = ["20 mm", "70 mm"]\n', "")
                                .replace('["1 mm", "3 mm", "5 mm"]', '["1 mm", "5 mm"]')),
                    single, client=client)
    assert (res.ok, res.failed) == (2, 0)
    fig, lines = main([str(single), "--metric", "v_yg__rms", "--out", str(tmp_path / "s.png")])
    ds = open_sweep(single).load()
    assert list(lines) == ["v_yg__rms"]  # one line, against crack.depth
    x, y = lines["v_yg__rms"]
    np.testing.assert_array_equal(x, [0.001, 0.005])
    np.testing.assert_array_equal(y, ds["v_yg__rms"].values)
    assert fig.axes[0].get_xlabel() == "crack.depth [m]"

    store = tmp_path / "friction.zarr"
    res = run_sweep(parse_sweep(FRICTION), store, client=client)
    assert (res.ok, res.failed) == (4, 0)
    ds = open_sweep(store).load()
    with pytest.raises(SystemExit, match="choose the x axis with --x, one of "
                                         "mesh.friction_coefficient, simulation.model"):
        main([str(store), "--metric", "v_yg__rms"])
    png = tmp_path / "mu.png"
    r = subprocess.run([sys.executable, str(SCRIPT), str(store), "--metric", "v_yg__rms",
                        "--x", "mesh.friction_coefficient", "--out", str(png)],
                       capture_output=True, text=True, env=env(), timeout=120)
    assert r.returncode == 0, r.stderr
    assert "Traceback" not in r.stderr and png.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    fig, lines = main([str(store), "--metric", "v_yg__rms", "--x", "mesh.friction_coefficient",
                       "--out", str(png)])
    assert set(lines) == {"simulation.model = II", "simulation.model = I-static"}
    model = ds["simulation.model"].values
    for name, (x, y) in lines.items():
        sel = model == name.split(" = ")[1]
        np.testing.assert_array_equal(x, [0.0, 0.1])
        np.testing.assert_array_equal(y, ds["v_yg__rms"].values[sel])
    fig, lines = main([str(store), "--metric", "v_yg__rms", "--x", "simulation.model",
                       "--out", str(tmp_path / "model.png")])
    assert set(lines) == {"mesh.friction_coefficient = 0", "mesh.friction_coefficient = 0.1"}
    for name, (x, y) in lines.items():
        assert list(x) == ["II", "I-static"]  # the sweep's order, not alphabetical
        mu = float(name.split(" = ")[1])
        for m, v in zip(x, y, strict=True):
            sel = (model == m) & (ds["mesh.friction_coefficient"].values == mu)
            assert v == ds["v_yg__rms"].values[sel].item()
    ax = fig.axes[0]
    assert [t.get_text() for t in ax.get_xticklabels()] == ["II", "I-static"]
    assert ax.get_xlabel() == "simulation.model"


def test_plot_sweep_of_a_missing_store_is_a_message(tmp_path):
    """Not zarr's FileNotFoundError traceback (a user audit of 2026-11-27)."""
    main = runpy.run_path(str(SCRIPT))["main"]
    with pytest.raises(SystemExit) as info:
        main([str(tmp_path / "nowhere.zarr")])
    assert str(info.value).endswith("nowhere.zarr: is not a Zarr store"), info.value
