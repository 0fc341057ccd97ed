"""A sweep through a real ``dask scheduler`` and two ``dask worker`` processes on loopback.

The runs are real geardyn runs (stiffness map, model II simulation, diagnostics), kept short;
the oracle is :func:`geardyn.studies.sweep.evaluate_run` called in this process.
"""

from __future__ import annotations

import os
import signal
import textwrap
import time

import numpy as np
import pytest

from geardyn.studies.sweep import STATUS_FAILED, STATUS_OK, evaluate_run, load_sweep, open_sweep

from .._cli_fork import run_geardyn
from ._procs import GEARDYN, dask_cluster, env

SWEEP = textwrap.dedent("""
    name = "loopback"
    seed = 5
    [set]
    # the paper's FE maps on a coarse mesh: the sweep machinery is tested, not the FE (the
    # default mesh took 11 s per cracked body, cold, in each run of this file)
    stiffness.fe.refinement = 0.25
    simulation.record_time = "0.15 s"
    simulation.settle_time = "0.02 s"
    stiffness.centre_distances = 6
    stiffness.nodes_per_segment = 6
    [axes]
    crack.depth = ["1 mm", "4 mm"]
    motor.torque = ["80 N m", "120 N m"]
    simulation.dt = ["1e-5 s", "1e-3 s"]
    [execution]
    batch_size = 1
""")


@pytest.mark.slow
def test_sweep_on_a_real_scheduler_and_two_workers(tmp_path):
    f = tmp_path / "sweep.toml"
    f.write_text(SWEEP)
    out = tmp_path / "loopback.zarr"
    with dask_cluster(tmp_path, n_workers=2) as address:
        r = run_geardyn(["sweep", str(f), "--out", str(out), "--scheduler",
                         address], capture_output=True, text=True, env=env(), timeout=240,
                        cwd=tmp_path)
    assert r.returncode == 1, r.stdout + r.stderr  # 4 runs failed (recorded): exit status 1
    assert "ok 4, failed 4, pending 0" in r.stdout
    assert "4 of 8 runs failed (their errors are in the store" in r.stderr
    ds = open_sweep(out).load()
    sw = load_sweep(f)
    plan = sw.plan()
    np.testing.assert_array_equal(ds.run.values, np.arange(8))
    assert len({w.split(":")[1] for w in ds.worker.values}) == 2  # both workers ran batches
    for r_ in range(8):
        ov = plan.overrides(r_)
        if ov["simulation.dt"] > 1e-4:  # coarser than the dt check allows: recorded, not fatal
            assert ds.status.values[r_] == STATUS_FAILED
            assert str(ds.error.values[r_]).startswith("simulation.dt: got 0.001")
            continue
        assert ds.status.values[r_] == STATUS_OK
        if r_ in (0, 6):  # two runs recomputed here as the oracle
            ref = evaluate_run(sw.base_case.with_overrides(ov), sw.spec.store,
                               int(plan.seeds[r_]))
            for name in ("v_yg__FM4", "omega_p__kurtosis", "transmission_error__NA4",
                         "sim__mean_centre_distance_change"):
                assert ds[name].values[r_] == ref[name], name


@pytest.mark.slow
def test_a_lost_worker_does_not_lose_runs(tmp_path):
    """SIGKILL a worker process while it runs a task: the scheduler reruns the task elsewhere
    (the nanny starts a fresh worker) and every run is stored once, none failed by the loss.
    The closed-form evaluator takes 0.15 s a run."""
    from ._procs import start, stop
    from .conftest import OSC_SWEEP

    f = tmp_path / "sweep.toml"
    f.write_text(OSC_SWEEP.replace("batch_size = 5", "batch_size = 1"))
    out = tmp_path / "lost.zarr"
    with dask_cluster(tmp_path, n_workers=2) as address:
        cli = start([*GEARDYN, "sweep", str(f), "--out", str(out), "--scheduler", address,
                     "--evaluator", "tests.sweep._evaluators:SLOW"], tmp_path,
                    tmp_path / "cli.log")
        try:
            from distributed import Client

            with Client(address, timeout=30) as cl:
                deadline = time.monotonic() + 120
                while not any(cl.processing().values()):  # a task is running
                    assert time.monotonic() < deadline and cli.poll() is None, \
                        (tmp_path / "cli.log").read_text()
                    time.sleep(0.02)
                victim = next(w for w, tasks in cl.processing().items() if tasks)
                pid = cl.run(os.getpid, workers=[victim])[victim]
            os.kill(pid, signal.SIGKILL)  # the worker process; its nanny restarts it
            # exit status 1: the six 70 mm bores fail by design (recorded); none was lost
            assert cli.wait(timeout=180) == 1, (tmp_path / "cli.log").read_text()
            log = (tmp_path / "cli.log").read_text()
            assert "ok 6, failed 6, pending 0" in log and "6 of 12 runs failed" in log, log
        finally:
            stop(cli)
    ds = open_sweep(out).load()
    np.testing.assert_array_equal(ds.run.values, np.arange(12))
    assert (ds.status.values != 0).all()  # nothing pending
    assert (ds.status.values == STATUS_OK).sum() == 6  # the 70 mm bores fail, as recorded
