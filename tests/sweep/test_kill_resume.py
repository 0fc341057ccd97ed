"""Interrupt a sweep (Ctrl-C, then SIGKILL) and resume it with the same command.

Every run must be present exactly once, and every stored value must equal (bit for bit) the
value of an uninterrupted sweep of the same file. The runs are real geardyn runs (short).
"""

from __future__ import annotations

import os
import signal
import textwrap
import time

import numpy as np
import pytest
import zarr

from geardyn.studies.sweep import STATUS_OK, STATUS_PENDING, load_sweep, open_sweep, run_sweep

from .._cli_fork import run_geardyn
from ._procs import GEARDYN, env, start, stop

SWEEP = textwrap.dedent("""
    name = "interrupted"
    seed = 9
    [set]
    # the paper's FE maps on a coarse mesh: the sweep machinery is tested, not the FE (the
    # default mesh took 11 s per cracked body, cold, in each run of this file)
    stiffness.fe.refinement = 0.25
    simulation.record_time = "0.15 s"
    simulation.settle_time = "0.02 s"
    stiffness.centre_distances = 6
    stiffness.nodes_per_segment = 6
    [axes]
    crack.depth = ["1 mm", "3 mm"]
    motor.torque = { start = "60 N m", stop = "130 N m", num = 3 }
    [sample]
    method = "lhs"
    n = 2
    [sample.dimensions]
    mesh.damping_ratio = { low = 0.04, high = 0.1 }
    [execution]
    batch_size = 2
""")


def statuses(out) -> np.ndarray | None:
    try:
        return np.asarray(zarr.open_group(str(out), mode="r")["status"][:])
    except Exception:  # not created yet
        return None


@pytest.mark.slow
def test_kill_and_resume_gives_the_uninterrupted_result(tmp_path, client):
    f = tmp_path / "sweep.toml"
    f.write_text(SWEEP)
    out = tmp_path / "interrupted.zarr"
    n = 12  # 2 depths x 3 torques x 2 samples
    cmd = [*GEARDYN, "sweep", str(f), "--out", str(out), "--workers", "1"]

    def interrupt(sig: int, at_least: int, log: str) -> np.ndarray:
        """Start the command and send ``sig`` to its process group once enough runs are ok."""
        p = start(cmd, tmp_path, tmp_path / log)
        try:
            t0 = time.monotonic()
            while True:
                st = statuses(out)
                if st is not None and (st == STATUS_OK).sum() >= at_least:
                    break
                assert p.poll() is None, (tmp_path / log).read_text()
                assert time.monotonic() - t0 < 180, "no run finished in time"
                time.sleep(0.01)
            if sig == signal.SIGINT:  # Ctrl-C in a terminal reaches the whole group
                os.killpg(p.pid, signal.SIGINT)
                # 130, or death by SIGINT if the Ctrl-C landed in an ``exec`` (a shell shows 130)
                assert p.wait(timeout=60) in (130, -signal.SIGINT), (tmp_path / log).read_text()
                assert "re-run the same command" in (tmp_path / log).read_text()
                assert "Traceback" not in (tmp_path / log).read_text()
        finally:
            stop(p, signal.SIGKILL)  # the CLI, its scheduler and its worker processes
        st = statuses(out)
        assert at_least <= (st == STATUS_OK).sum() < n and (st == STATUS_PENDING).any(), st
        return st

    st = interrupt(signal.SIGINT, 2, "ctrl-c.log")
    st = interrupt(signal.SIGKILL, int((st == STATUS_OK).sum()) + 2, "killed.log")

    r = run_geardyn(cmd[len(GEARDYN):], env=env(), timeout=240, cwd=tmp_path)
    assert r.returncode == 0, r.stdout + r.stderr
    assert "resumed" in r.stdout and f"ok {n}, failed 0, pending 0" in r.stdout
    done_before = int((st == STATUS_OK).sum())
    assert f"{n - done_before} computed now" in r.stdout.replace("\n", " ")

    reference = tmp_path / "reference.zarr"
    run_sweep(load_sweep(f), reference, client=client)
    a, b = open_sweep(out).load(), open_sweep(reference).load()
    np.testing.assert_array_equal(a.run.values, np.arange(n))
    assert a.attrs["sweep_hash"] == b.attrs["sweep_hash"]
    for name in a.coords:
        np.testing.assert_array_equal(a[name].values, b[name].values, err_msg=name)
    compared = 0
    for name in a.data_vars:
        # how it ran, not what it computed (the batch checksums cover the run times too)
        if name in ("run_seconds", "worker", "batch_checksum"):
            continue
        np.testing.assert_array_equal(a[name].values, b[name].values, err_msg=name)
        compared += 1
    assert compared > 60 and (a.status.values == STATUS_OK).all()
    assert np.isfinite(a["v_yg__FM4"].values).all()
