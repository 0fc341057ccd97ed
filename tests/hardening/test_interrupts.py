"""Ctrl-C during long commands leaves no half-written file, and re-running the same command (no
--force) continues: the CLI's "re-run the same command to continue" is true.

No luck involved: SIGINT is sent when the command reports (through ``$GEARDYN_TEST_READY_FILE``)
that the stage to interrupt has started, and a command that finishes before the signal arrives
fails the test instead of skipping it (the workloads are sized to run for minutes).
"""

from __future__ import annotations

import json
import os
import signal
import subprocess
import sys
import time

import pytest

from .._cli_fork import run_geardyn

pytestmark = [pytest.mark.slow, pytest.mark.timeout(3600)]

#: An interrupted command ends with status 130, or by SIGINT when the Ctrl-C landed inside a
#: Python ``exec`` (see ``geardyn.cli._common._say_interrupted``); a shell shows both as 130.
INTERRUPTED = (130, -signal.SIGINT)


def _tmp_files(*folders):
    out = []
    for folder in folders:
        for _dirpath, _, files in os.walk(folder):
            out += [f for f in files if ".tmp" in f or (f.startswith(".") and f != ".lock")]
    return [f for f in out if not f.endswith(".lock")]


def _start(args, env):
    return subprocess.Popen([sys.executable, "-m", "geardyn", *args], env=env,
                            stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)


def _interrupt_when_ready(proc, ready_file, stage, timeout=300.0):
    """Send SIGINT as soon as ``stage`` has started (per the ready file); fail if the command
    ends first or the stage never starts."""
    t0 = time.time()
    while True:
        started = ready_file.read_text().splitlines() if ready_file.exists() else []
        if any(line.startswith(stage) for line in started):
            break
        if proc.poll() is not None:
            out, err = proc.communicate()
            pytest.fail(f"the command ended (exit {proc.returncode}) before stage {stage!r} "
                        f"started; stages seen: {started}; stderr: {err[-500:]}")
        if time.time() - t0 > timeout:
            proc.kill()
            pytest.fail(f"stage {stage!r} did not start within {timeout} s")
        time.sleep(0.02)
    proc.send_signal(signal.SIGINT)
    stdout, stderr = proc.communicate(timeout=300)
    assert proc.returncode in INTERRUPTED, \
        f"the command finished before the interrupt: {stderr[-500:]}"
    return stdout, stderr


RUN = ["--stiffness", "pem", "--set", "simulation.record_time=0.5 s",
       "--set", "simulation.settle_time=0.05 s", "--set", "stiffness.centre_distances=11",
       "--set", "diagnostics.samples_per_rev=1024"]


def test_ctrl_c_during_run_then_the_same_command_continues(tmp_path):
    env = dict(os.environ, GEARDYN_CACHE_DIR=str(tmp_path / "cache"),
               GEARDYN_TEST_READY_FILE=str(tmp_path / "ready"))
    out = tmp_path / "out"
    p = _start(["run", "--out", str(out), *RUN], env)
    # the simulation stage integrates model I and II records five times: tens of seconds at least
    _, stderr = _interrupt_when_ready(p, tmp_path / "ready", "simulation")
    assert "interrupted" in stderr and "re-run the same command" in stderr
    assert "Traceback" not in stderr
    assert not _tmp_files(out, tmp_path / "cache")
    record = json.loads((out / "inputs.json").read_text())
    assert record["complete"] is False  # recognisably interrupted
    if (out / "summary.json").exists():
        assert json.loads((out / "summary.json").read_text())["complete"] is False
    # the same command, no --force: it continues into the folder, reusing the cached maps
    env.pop("GEARDYN_TEST_READY_FILE")
    r = run_geardyn(["run", "--out", str(out), *RUN],
                    env=env, capture_output=True, text=True, timeout=1800)
    assert r.returncode == 0, r.stderr
    assert "continuing the interrupted run" in r.stderr
    assert json.loads((out / "summary.json").read_text())["complete"] is True
    record = json.loads((out / "inputs.json").read_text())
    assert record["complete"] is True
    assert record["cache"]["stiffness"] == {"hits": 2, "built": 0}
    assert not _tmp_files(out, tmp_path / "cache")


@pytest.mark.parametrize("command", ["simulate", "stiffness"])
def test_ctrl_c_during_a_command_leaves_no_partial_output(tmp_path, command):
    env = dict(os.environ, GEARDYN_CACHE_DIR=str(tmp_path / "cache"),
               GEARDYN_TEST_READY_FILE=str(tmp_path / "ready"))
    target = tmp_path / ("sim.nc" if command == "simulate" else "stf")
    args = [command, "--out", str(target)]
    if command == "simulate":  # 2e7 model II steps: many minutes
        args += ["--stiffness", "pem", "--set", "stiffness.centre_distances=6",
                 "--set", "simulation.record_time=200 s", "--set", "simulation.decimation=10000"]
        stage = "model II"
    else:  # 1001 x 2 PEM map columns at 256 nodes a segment: minutes
        args += ["--method", "pem", "--set", "stiffness.centre_distances=1001", "--set",
                 "stiffness.nodes_per_segment=256"]
        stage = "pem map, healthy"
    p = _start(args, env)
    _, stderr = _interrupt_when_ready(p, tmp_path / "ready", stage)
    assert "Traceback" not in stderr and "re-run the same command" in stderr
    if command == "simulate":
        assert not target.exists()
    else:
        assert not list(target.glob("*.nc")) if target.exists() else True
    assert not _tmp_files(tmp_path)


def _children(pid: int) -> list[int]:
    """Process ids whose parent is ``pid`` (Linux ``/proc``)."""
    kids = []
    for entry in os.listdir("/proc"):
        if entry.isdigit():
            try:
                with open(f"/proc/{entry}/stat") as fh:
                    fields = fh.read().rsplit(")", 1)[1].split()
            except OSError:
                continue
            if int(fields[1]) == pid:
                kids.append(int(entry))
    return kids


def _cmdline(pid: int) -> str:
    try:
        with open(f"/proc/{pid}/cmdline", "rb") as fh:
            return fh.read().replace(b"\0", b" ").decode(errors="replace")
    except OSError:
        return ""


def _running(pid: int) -> bool:
    """``pid`` exists and is not a zombie."""
    try:
        with open(f"/proc/{pid}/stat") as fh:
            return fh.read().rsplit(")", 1)[1].split()[0] != "Z"
    except OSError:
        return False


@pytest.mark.skipif(not os.path.isdir("/proc"), reason="reads the process table from /proc")
def test_ctrl_c_to_the_group_while_a_second_process_builds_fe_bodies(tmp_path):
    """A terminal's Ctrl-C reaches every process of the group: the second FE process (which
    ignores it from its first instruction) prints nothing and is stopped by the first, which
    reports the interruption as usual."""
    env = dict(os.environ, GEARDYN_CACHE_DIR=str(tmp_path / "cache"), GEARDYN_FE_PROCESSES="1",
               GEARDYN_TEST_READY_FILE=str(tmp_path / "ready"))
    target = tmp_path / "stf"
    p = subprocess.Popen([sys.executable, "-m", "geardyn", "stiffness", "--method", "fe",
                          "--out", str(target)], env=env, stdout=subprocess.PIPE,
                         stderr=subprocess.PIPE, text=True, start_new_session=True)
    ready, t0, kids = tmp_path / "ready", time.time(), []
    while True:
        started = ready.read_text().splitlines() if ready.exists() else []
        kids = _children(p.pid)
        workers = [k for k in kids if "spawn_main" in _cmdline(k)]
        if any(s.startswith("fe map, healthy") for s in started) and workers:
            break
        if p.poll() is not None or time.time() - t0 > 300:
            p.kill()
            pytest.fail(f"no second FE process seen before the end: {p.communicate()[1][-500:]}")
        time.sleep(0.02)
    time.sleep(0.3)  # inside the second process's imports or its body, not at its first line
    os.killpg(p.pid, signal.SIGINT)
    _, stderr = p.communicate(timeout=120)
    assert p.returncode in INTERRUPTED, stderr[-500:]
    assert "Traceback" not in stderr and "KeyboardInterrupt" not in stderr, stderr[-1500:]
    assert "re-run the same command" in stderr
    # the worker is stopped by the first process before it exits; multiprocessing's resource
    # tracker (also a child) ends by itself once both are gone
    assert not [k for k in workers if _running(k)], "second process still running"
    deadline = time.time() + 60
    while [k for k in kids if _running(k)] and time.time() < deadline:
        time.sleep(0.1)
    assert not [k for k in kids if _running(k)], [_cmdline(k) for k in kids if _running(k)]
    assert not list(target.glob("*.nc")) if target.exists() else True


def test_a_half_built_llvm_object_after_ctrl_c_prints_nothing():
    """CI, 2026-11-26: a Ctrl-C while numba compiled the kernel (a fresh numba cache) cut an
    llvmlite object's construction short; its ``__del__`` then raised ``AttributeError:
    'PassBuilder' object has no attribute '_as_parameter_'``, which Python printed with a
    traceback after geardyn's "interrupted" line. The CLI's unraisable hook drops exactly that;
    anything else still reaches the default hook."""
    from types import SimpleNamespace

    from geardyn.cli._common import _unraisable

    seen = []
    hook = _unraisable(seen.append)

    def llvm_del():  # stands for llvmlite.binding.ffi._ObjectRef.__del__
        pass

    llvm_del.__module__ = "llvmlite.binding.ffi"
    half_built = SimpleNamespace(
        exc_value=AttributeError("'PassBuilder' object has no attribute '_as_parameter_'"),
        object=llvm_del)
    hook(half_built)
    assert seen == []
    other = SimpleNamespace(exc_value=AttributeError("'X' object has no attribute 'y'"),
                            object=llvm_del)
    ours = SimpleNamespace(exc_value=AttributeError("no attribute '_as_parameter_'"),
                           object=test_a_half_built_llvm_object_after_ctrl_c_prints_nothing)
    hook(other)
    hook(ours)
    assert seen == [other, ours]


def test_a_ctrl_c_swallowed_by_a_gc_callback_reaches_the_main_thread():
    """2026-11-27: a Ctrl-C that landed in a garbage-collector callback (distributed's
    ``GCDiagnosis`` in a sweep's first process) was swallowed as unraisable and kept only as a
    pending flag, which the sweep never looked at: the sweep ran to its end (3 of 24 Ctrl-Cs
    2.2-2.3 s into a one-worker sweep). The CLI's unraisable hook delivers it to the main
    thread again, where it is raised outside the callback."""
    import gc

    from geardyn.cli import _common

    def callback(phase, info):  # stands for GCDiagnosis._gc_callback, hit by the Ctrl-C
        if phase == "start":
            _common._on_sigint(signal.SIGINT, None)

    old = signal.signal(signal.SIGINT, _common._on_sigint)
    old_hook = sys.unraisablehook
    sys.unraisablehook = _common._unraisable(old_hook)
    gc.callbacks.append(callback)
    try:
        with pytest.raises(KeyboardInterrupt) as raised:
            try:
                gc.collect()  # the callback's KeyboardInterrupt is unraisable here
            finally:
                gc.callbacks.remove(callback)
            deadline = time.monotonic() + 10.0
            while time.monotonic() < deadline:  # the main thread's next instructions
                time.sleep(0.001)
        # raised again by the handler in this function's frame, not in the callback's
        frames = [entry.name for entry in raised.traceback]
        assert frames[0] == "test_a_ctrl_c_swallowed_by_a_gc_callback_reaches_the_main_thread"
        assert "callback" not in frames and _common._INTERRUPT["pending"], frames
    finally:
        if callback in gc.callbacks:
            gc.callbacks.remove(callback)
        sys.unraisablehook = old_hook
        signal.signal(signal.SIGINT, old)
        _common._INTERRUPT["pending"] = False


def test_dasks_gc_timer_cut_short_by_a_ctrl_c_prints_nothing():
    """After a Ctrl-C inside distributed's garbage-collection timer callback, its next call
    asserts that the previous collection ended (``AssertionError`` from
    ``distributed.gc.GCDiagnosis._gc_callback``, printed with a traceback at every later
    collection); the CLI's hook drops that, and only that."""
    from types import SimpleNamespace

    from geardyn.cli._common import _unraisable

    seen = []
    hook = _unraisable(seen.append)

    def gc_callback(phase, info):  # stands for distributed.gc.GCDiagnosis._gc_callback
        pass

    gc_callback.__module__ = "distributed.gc"
    cut_short = SimpleNamespace(exc_value=AssertionError(), object=gc_callback)
    hook(cut_short)
    assert seen == []
    other_error = SimpleNamespace(exc_value=ValueError("x"), object=gc_callback)
    ours = SimpleNamespace(exc_value=AssertionError(),
                           object=test_a_ctrl_c_swallowed_by_a_gc_callback_reaches_the_main_thread)
    hook(other_error)
    hook(ours)
    assert seen == [other_error, ours]
