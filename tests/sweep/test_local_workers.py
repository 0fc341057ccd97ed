"""The local cluster's worker processes (``geardyn.studies.sweep.local_workers``): forked from a
server that imported the run code (Linux), or spawned; the same stored bits either way."""

from __future__ import annotations

import os
import signal
import subprocess
import sys
import textwrap
import time

import numpy as np
import pytest

from geardyn.errors import InputError
from geardyn.studies.sweep import open_sweep, run_sweep
from geardyn.studies.sweep.local_workers import (
    WORKER_MALLOC,
    WORKER_PRELOAD,
    worker_start_method,
)

from .._cli_fork import run_geardyn
from ._procs import GEARDYN, env, start, stop

LINUX = sys.platform.startswith("linux")

SWEEP = textwrap.dedent("""
    name = "workers"
    seed = 4
    [set]
    stiffness.method = "pem"
    stiffness.centre_distances = 6
    stiffness.nodes_per_segment = 6
    simulation.record_time = "0.12 s"
    simulation.settle_time = "0.01 s"
    [axes]
    crack.depth = ["1 mm", "3 mm"]
    motor.torque = ["60 N m", "120 N m"]
    [execution]
    batch_size = 1
""")


def _worker_state(cl) -> list[tuple[bool, str]]:
    """Per worker: was the forkserver's preload imported, and the worker's OMP_NUM_THREADS."""
    def state():
        return ("geardyn.studies.sweep._worker_preload" in sys.modules,
                os.environ.get("OMP_NUM_THREADS", ""))
    return list(cl.run(state).values())


def _malloc_settings(cl) -> set:
    return set(cl.run(lambda: tuple(os.environ.get(k) for k in WORKER_MALLOC)).values())


@pytest.mark.skipif(not LINUX, reason="the forkserver start is Linux's")
def test_two_workers_fork_from_the_preloaded_server_one_or_as_asked_spawns(monkeypatch):
    from geardyn.studies.sweep.execute import _dask_client

    monkeypatch.delenv("GEARDYN_WORKER_START", raising=False)
    assert worker_start_method(2) == "forkserver" and worker_start_method(8) == "forkserver"
    assert worker_start_method(1) == "spawn"  # one worker: nothing to share
    for k in WORKER_MALLOC:
        monkeypatch.delenv(k, raising=False)
    environ = dict(os.environ)
    with _dask_client(None, 2, None) as cl:
        forked = _worker_state(cl)
        malloc = _malloc_settings(cl)
        profiling = cl.run(lambda: __import__("dask").config.get(
            "distributed.worker.profile.enabled"))
    assert forked == [(True, "1"), (True, "1")], forked  # the nanny's variables arrived too
    assert set(profiling.values()) == {False}  # no dashboard: no stack sampling every 10 ms
    # glibc keeps a run's freed arrays (up to 32 MB each) for the next run, not Dask's 64 kB
    assert malloc == {(str(32 * 2 ** 20), str(64 * 2 ** 20))}, malloc
    assert dict(os.environ) == environ
    monkeypatch.setenv("GEARDYN_WORKER_START", "spawn")  # (the slow test spawns two workers)
    assert worker_start_method(2) == "spawn"
    assert WORKER_PRELOAD[-1] == "geardyn.studies.sweep._worker_preload"


@pytest.mark.slow
@pytest.mark.skipif(not LINUX, reason="the forkserver start is Linux's")
def test_forked_and_spawned_workers_store_the_same_bits(tmp_path, monkeypatch):
    f = tmp_path / "s.toml"
    f.write_text(SWEEP)
    stores = {}
    for method in ("forkserver", "spawn"):
        monkeypatch.setenv("GEARDYN_WORKER_START", method)
        stores[method] = tmp_path / f"{method}.zarr"
        result = run_sweep(f, stores[method], workers=2)
        assert result.workers == 2
        assert result.ok == 4 and result.failed == 0, result
    a, b = (open_sweep(stores[m]).load() for m in ("forkserver", "spawn"))
    compared = 0
    for name in a.data_vars:
        if name in ("run_seconds", "worker", "batch_checksum"):  # how it ran
            continue
        np.testing.assert_array_equal(a[name].values, b[name].values, err_msg=name)
        compared += 1
    assert compared > 20 and np.isfinite(a["v_yg__FM4"].values).all()


def test_an_unknown_start_method_is_refused_by_name(tmp_path, monkeypatch):
    monkeypatch.setenv("GEARDYN_WORKER_START", "fork")
    with pytest.raises(InputError) as e:
        worker_start_method(2)
    assert e.value.field == "GEARDYN_WORKER_START" and "forkserver or spawn" in e.value.allowed
    f = tmp_path / "s.toml"
    f.write_text(SWEEP)
    r = run_geardyn(["sweep", str(f), "--out", str(tmp_path / "o.zarr"), "--workers", "2"],
                    capture_output=True, text=True, env={**env(), "GEARDYN_WORKER_START": "fork"},
                    timeout=120, cwd=tmp_path)
    assert r.returncode == 2, r.stdout + r.stderr
    assert "GEARDYN_WORKER_START" in r.stderr and "Traceback" not in r.stderr


def _session(pid: int) -> list[int]:
    out = subprocess.run(["pgrep", "-s", str(pid)], capture_output=True, text=True).stdout
    return [int(x) for x in out.split()]


@pytest.mark.slow
@pytest.mark.skipif(not LINUX, reason="the forkserver start is Linux's")
def test_ctrl_c_while_the_forked_workers_start_is_honoured_without_tracebacks(tmp_path):
    """A terminal's Ctrl-C (SIGINT to the whole group) while the cluster starts (the command's
    main thread holds SIGINT back, as ``/proc`` shows; the forkserver is still importing): the
    command stops with the usual line and exit status once the cluster is up (the Ctrl-C is
    held, not lost: SIGINT used to be ignored in that window, and the sweep then ran to its
    end), no process prints a traceback (the forkserver and its workers ignore SIGINT from
    their start), and nothing of the session is left running."""
    f = tmp_path / "s.toml"
    f.write_text(SWEEP)
    log, ready = tmp_path / "sweep.log", tmp_path / "ready"
    p = start([*GEARDYN, "sweep", str(f), "--out", str(tmp_path / "o.zarr"), "--workers", "2"],
              tmp_path, log, extra_env={"GEARDYN_TEST_READY_FILE": str(ready)})
    try:
        t0 = time.monotonic()
        while not (ready.exists() and "local cluster starting" in ready.read_text()):
            assert p.poll() is None, log.read_text()
            assert time.monotonic() - t0 < 120, "the cluster's start was not seen"
            time.sleep(0.005)
        # the forkserver imports for about 2 s before it forks the first worker
        assert any("multiprocessing.forkserver" in _cmdline(k) for k in _session(p.pid))
        assert _sigint_held_back(p.pid)  # held, not ignored
        os.killpg(p.pid, signal.SIGINT)
        assert p.wait(timeout=120) in (130, -signal.SIGINT), log.read_text()
        text = log.read_text()
        assert "re-run the same command" in text, text
        assert "Traceback" not in text and "Exception ignored" not in text, text
        deadline = time.monotonic() + 30  # the forkserver ends when it sees its parent gone
        while _session(p.pid) and time.monotonic() < deadline:
            time.sleep(0.1)
        assert not _session(p.pid), [_cmdline(k) for k in _session(p.pid)]
    finally:
        stop(p, signal.SIGKILL)


def _sigint_held_back(pid: int) -> bool:
    """SIGINT blocked in ``pid``'s main thread and not ignored by the process (``/proc``): a
    Ctrl-C now is delivered later, not lost."""
    try:
        with open(f"/proc/{pid}/task/{pid}/status") as fh:
            fields = dict(line.split(":", 1) for line in fh if ":" in line)
    except OSError:
        return False
    bit = 1 << (signal.SIGINT - 1)
    return bool(int(fields["SigBlk"], 16) & bit and not int(fields["SigIgn"], 16) & bit)


def _cmdline(pid: int) -> str:
    try:
        with open(f"/proc/{pid}/cmdline") as fh:
            return fh.read().replace("\0", " ")
    except OSError:
        return ""
