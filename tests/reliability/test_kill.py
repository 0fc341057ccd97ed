"""SIGKILL at random points of ``geardyn stiffness --method pem`` and ``geardyn sweep``, then the
same command again: the result equals an uninterrupted run bit for bit, nothing half-written is
ever served, and the temporary files of the killed process are gone.

"Random points" are stages of the command, observed on disk (a readiness marker: the cache
entry's lock, its checksum sidecar, a number of finished runs in the store...) and drawn from a
seeded generator (``GEARDYN_KILL_SEED``); the process group is killed as soon as the drawn
stage is reached. The marker predicates are monotone (a later stage satisfies an earlier
marker), so a stage passed between two polls still triggers the kill, just later. No sleeps
decide when to kill.
"""

from __future__ import annotations

import os
import signal
import subprocess
import textwrap
import time
from pathlib import Path

import numpy as np
import pytest

from geardyn.stiffness.map import StiffnessMap
from geardyn.studies.sweep import STATUS_OK, open_sweep, verify_store
from tests._cli_fork import run_geardyn
from tests.sweep._procs import GEARDYN, env

SMALL = ["--set", "stiffness.centre_distances=3", "--set", "stiffness.nodes_per_segment=5"]
#: Seed of the drawn kill points (GEARDYN_KILL_SEED=N explores others).
RNG_SEED = int(os.environ.get("GEARDYN_KILL_SEED", "20261123"))


def _env(cache: Path) -> dict[str, str]:
    e = env()
    e["GEARDYN_CACHE_DIR"] = str(cache)
    return e


def _kill_at(cmd: list[str], cwd: Path, cache: Path, marker, log: Path,
             timeout: float = 300.0) -> bool:
    """Run ``cmd`` and SIGKILL its process group when ``marker()`` becomes true.

    Returns True if killed, False if the command finished first (the marker's stage came after
    its last file, which a test treats as "killed after the end").
    """
    fh = open(log, "wb")  # noqa: SIM115 - closed below
    p = subprocess.Popen(cmd, cwd=cwd, env=_env(cache), stdout=fh, stderr=subprocess.STDOUT,
                         start_new_session=True)
    try:
        t0 = time.monotonic()
        while not marker():
            if p.poll() is not None:
                return False
            assert time.monotonic() - t0 < timeout, log.read_text()
            time.sleep(0.002)  # a poll interval, not a kill time
        os.killpg(p.pid, signal.SIGKILL)
        p.wait(timeout=60)
        return True
    finally:
        if p.poll() is None:
            os.killpg(p.pid, signal.SIGKILL)
            p.wait(timeout=60)
        fh.close()


def _same_map(a: StiffnessMap, b: StiffnessMap) -> None:
    for name in ("dd", "phase_a", "length_a", "k_mb", "slot_tooth"):
        np.testing.assert_array_equal(getattr(a, name), getattr(b, name), err_msg=name)
    for name in b.extra:
        np.testing.assert_array_equal(a.extra[name], b.extra[name], err_msg=name)
    assert dict(a.attrs) == dict(b.attrs)


# --------------------------------------------------------------------------------------------
# geardyn stiffness --method pem
# --------------------------------------------------------------------------------------------
def _stiffness_markers(cache: Path, out: Path) -> dict:
    entries = cache / "stiffness"
    return {
        "first map started": lambda: any(entries.glob("*.lock")),
        "first map in the cache": lambda: len(list(entries.glob("*.nc.sha256"))) >= 1,
        "second map in the cache": lambda: len(list(entries.glob("*.nc.sha256"))) >= 2,
        "outputs started": lambda: out.is_dir() and any(out.iterdir()),
        "cracked map written": lambda: (out / "stiffness_cracked.nc").is_file(),
    }


@pytest.fixture(scope="module")
def stiffness_reference(tmp_path_factory):
    tmp = tmp_path_factory.mktemp("stiffness-ref")
    cmd = [*GEARDYN, "stiffness", "--method", "pem", "--out", str(tmp / "out"), *SMALL]
    r = run_geardyn(cmd[len(GEARDYN):], env=_env(tmp / "cache"), timeout=600, cwd=tmp)
    assert r.returncode == 0, r.stdout + r.stderr
    return {k: StiffnessMap.from_netcdf(tmp / "out" / f"stiffness_{k}.nc")
            for k in ("healthy", "cracked")}


@pytest.mark.slow
@pytest.mark.parametrize("draw", [0, 1])
def test_killed_stiffness_run_resumes_to_the_uninterrupted_result(tmp_path, stiffness_reference,
                                                                  draw):
    cache, out = tmp_path / "cache", tmp_path / "out"
    markers = _stiffness_markers(cache, out)
    name = list(markers)[np.random.default_rng([RNG_SEED, draw]).integers(len(markers))]
    cmd = [*GEARDYN, "stiffness", "--method", "pem", "--out", str(out), *SMALL]
    killed = _kill_at(cmd, tmp_path, cache, markers[name], tmp_path / "killed.log")
    # whatever is on disk after the kill is whole: every complete-looking file reads
    for f in out.glob("*.nc") if out.exists() else []:
        StiffnessMap.from_netcdf(f)
    r = run_geardyn(cmd[len(GEARDYN):], env=_env(cache), timeout=600, cwd=tmp_path)
    assert r.returncode == 0, f"killed at {name!r} ({killed}): {r.stdout}{r.stderr}"
    for k, ref in stiffness_reference.items():
        _same_map(StiffnessMap.from_netcdf(out / f"stiffness_{k}.nc"), ref)
    left = [p.name for p in list((cache / "stiffness").iterdir()) + list(out.iterdir())
            if p.name.startswith(".")]
    assert left == [], f"killed at {name!r}: temporary files left: {left}"


# --------------------------------------------------------------------------------------------
# geardyn sweep (PEM maps, short records)
# --------------------------------------------------------------------------------------------
SWEEP = textwrap.dedent("""
    name = "killed"
    seed = 5
    [set]
    stiffness.method = "pem"
    simulation.record_time = "0.1 s"
    simulation.settle_time = "0.02 s"
    stiffness.centre_distances = 3
    stiffness.nodes_per_segment = 5
    [axes]
    crack.depth = ["1 mm", "3 mm"]
    motor.torque = ["60 N m", "90 N m", "120 N m"]
    [execution]
    batch_size = 2
""")
N_RUNS = 6


def _statuses(out: Path) -> np.ndarray | None:
    import zarr

    try:
        return np.asarray(zarr.open_group(str(out), mode="r")["status"][:])
    except Exception:  # not created yet
        return None


def _sweep_markers(cache: Path, out: Path) -> dict:
    def ok_at_least(k):
        def marker():
            st = _statuses(out)
            return st is not None and int((st == STATUS_OK).sum()) >= k
        return marker

    return {
        "maps being prepared": lambda: any((cache / "stiffness").glob("*.lock")),
        "store created": lambda: (out / ".zmetadata").is_file(),
        "one batch done": ok_at_least(2),
        "two batches done": ok_at_least(4),
    }


@pytest.fixture(scope="module")
def sweep_reference(tmp_path_factory):
    """The uninterrupted run, through the same command (a process cluster: the warnings a run
    records are captured per process, which an in-process threaded cluster cannot promise)."""
    tmp = tmp_path_factory.mktemp("sweep-ref")
    f = tmp / "sweep.toml"
    f.write_text(SWEEP)
    out = tmp / "reference.zarr"
    r = run_geardyn(["sweep", str(f), "--out", str(out), "--workers", "1"],
                    env=_env(tmp / "cache"), timeout=900, cwd=tmp)
    assert r.returncode == 0, r.stdout + r.stderr
    return out


@pytest.mark.slow
@pytest.mark.parametrize("draw", [0, 1])
def test_killed_sweep_resumes_to_the_uninterrupted_result(tmp_path, sweep_reference, draw):
    f = tmp_path / "sweep.toml"
    f.write_text(SWEEP)
    cache, out = tmp_path / "cache", tmp_path / "killed.zarr"
    markers = _sweep_markers(cache, out)
    name = list(markers)[np.random.default_rng([RNG_SEED, 10 + draw]).integers(len(markers))]
    cmd = [*GEARDYN, "sweep", str(f), "--out", str(out), "--workers", "1"]
    killed = _kill_at(cmd, tmp_path, cache, markers[name], tmp_path / "killed.log")
    r = run_geardyn(cmd[len(GEARDYN):], env=_env(cache), timeout=600, cwd=tmp_path)
    assert r.returncode == 0, f"killed at {name!r} ({killed}): {r.stdout}{r.stderr}"
    assert f"ok {N_RUNS}, failed 0, pending 0" in r.stdout
    assert verify_store(out).ok
    a, b = open_sweep(out).load(), open_sweep(sweep_reference).load()
    assert a.attrs["sweep_hash"] == b.attrs["sweep_hash"]
    compared = 0
    for n in [*a.coords, *a.data_vars]:
        if n in ("run_seconds", "worker", "batch_checksum"):  # how it ran, not what it computed
            continue
        np.testing.assert_array_equal(a[n].values, b[n].values, err_msg=f"{n} (killed at {name})")
        compared += 1
    assert compared > 40 and (a.status.values == STATUS_OK).all()
    assert not list(out.rglob("*.partial")) and not list(tmp_path.glob(".killed.zarr.*"))
