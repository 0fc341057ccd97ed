"""Subprocess helpers for the sweep tests: a real Dask scheduler and workers, the CLI."""

from __future__ import annotations

import contextlib
import json
import os
import signal
import subprocess
import sys
import time
from collections.abc import Iterator
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]
GEARDYN = [sys.executable, "-m", "geardyn"]
# the ``dask`` console script of this interpreter's environment (found even when the venv is
# not activated, i.e. its bin folder not on PATH)
_here = Path(sys.executable).with_name("dask")
DASK = str(_here) if _here.exists() else "dask"


def env() -> dict[str, str]:
    """The test environment, with the repository on the path (for tests.sweep._evaluators)."""
    e = dict(os.environ)
    e["PYTHONPATH"] = os.pathsep.join([str(ROOT), *filter(None, [e.get("PYTHONPATH")])])
    e.pop("GEARDYN_PROGRESS", None)
    return e


def start(args: list[str], cwd: Path, log: Path,
          extra_env: dict[str, str] | None = None) -> subprocess.Popen:
    """Start a process in its own session (its group can be killed as a whole), with
    :func:`env` and ``extra_env``."""
    fh = open(log, "wb")  # noqa: SIM115 - closed when the process is stopped
    p = subprocess.Popen(args, cwd=cwd, env={**env(), **(extra_env or {})}, stdout=fh,
                         stderr=subprocess.STDOUT, start_new_session=True)
    p._log = fh  # type: ignore[attr-defined]
    return p


def stop(p: subprocess.Popen, sig: int = signal.SIGTERM, timeout: float = 15.0) -> None:
    """Stop a process started by :func:`start` and everything in its process group."""
    with contextlib.suppress(ProcessLookupError):
        os.killpg(p.pid, sig)
    try:
        p.wait(timeout=timeout)
    except subprocess.TimeoutExpired:
        with contextlib.suppress(ProcessLookupError):
            os.killpg(p.pid, signal.SIGKILL)
        p.wait(timeout=timeout)
    with contextlib.suppress(ProcessLookupError):  # children left in the group
        os.killpg(p.pid, signal.SIGKILL)
    p._log.close()  # type: ignore[attr-defined]


@contextlib.contextmanager
def dask_cluster(tmp: Path, n_workers: int = 2, timeout: float = 60.0) -> Iterator[str]:
    """A ``dask scheduler`` and ``n_workers`` ``dask worker`` processes on 127.0.0.1.

    Yields the scheduler address; everything is torn down on exit.
    """
    from distributed import Client

    sched_file = tmp / "scheduler.json"
    procs = [start([DASK, "scheduler", "--host", "127.0.0.1", "--port", "0",
                    "--no-dashboard", "--scheduler-file", str(sched_file)], tmp,
                   tmp / "scheduler.log")]
    try:
        t0 = time.monotonic()
        while not sched_file.exists() or not sched_file.read_text().strip():
            if time.monotonic() - t0 > timeout or procs[0].poll() is not None:
                raise RuntimeError("dask scheduler did not start:\n"
                                   + (tmp / "scheduler.log").read_text())
            time.sleep(0.1)
        address = json.loads(sched_file.read_text())["address"]
        assert address.startswith("tcp://127.0.0.1:")
        for i in range(n_workers):
            procs.append(start([DASK, "worker", address, "--nworkers", "1", "--nthreads", "1",
                                "--host", "127.0.0.1", "--no-dashboard", "--name", f"w{i}",
                                "--local-directory", str(tmp / f"w{i}")], tmp,
                               tmp / f"worker{i}.log"))
        with Client(address, timeout=timeout) as cl:
            cl.wait_for_workers(n_workers, timeout=timeout)
        yield address
    finally:
        for p in reversed(procs):
            stop(p)
