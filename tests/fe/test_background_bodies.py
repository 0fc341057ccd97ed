"""A second process builds the faulty map's FE bodies while the first builds the healthy map
(issue 16.3): the maps are the same bytes as a one-process build, the bodies come from the
cache the second process filled, it stops at once on an error, and it starts only when it
helps and is allowed."""

from __future__ import annotations

import os
import time

import numpy as np
import pytest

import geardyn
from geardyn import processes
from geardyn.cache import Cache, record_lookups
from geardyn.stiffness import build_map
from geardyn.stiffness.fe import background as bg
from geardyn.stiffness.fe.background import (
    FE_PROCESSES_ENV,
    faulty_bodies_in_background,
    fe_processes,
)

from .._cli_fork import run_geardyn

#: a small FE case: coarse mesh, few grid lines (the bodies take about a second each)
SMALL = {"stiffness.method": "fe", "stiffness.fe.refinement": 0.3,
         "stiffness.centre_distances": 3, "stiffness.nodes_per_segment": 6}


@pytest.fixture(scope="module")
def case():
    return geardyn.paper_case().with_overrides(SMALL)


def _maps(case):
    return build_map(case, cracked=False), build_map(case, cracked=True)


@pytest.mark.slow
def test_the_second_process_fills_the_cache_and_the_maps_are_the_same_bytes(case, tmp_path,
                                                                          monkeypatch):
    monkeypatch.setenv("GEARDYN_CACHE_DIR", str(tmp_path / "one"))
    monkeypatch.setenv(FE_PROCESSES_ENV, "0")
    with faulty_bodies_in_background(case) as started:
        assert not started                                      # not allowed: one process
        one = _maps(case)

    monkeypatch.setenv("GEARDYN_CACHE_DIR", str(tmp_path / "two"))
    monkeypatch.setenv(FE_PROCESSES_ENV, "1")
    with faulty_bodies_in_background(case) as back:
        assert back.started and back.process.pid != os.getpid()
        back.process.join(timeout=300)     # let it finish first, so the test does not race it
        assert back.process.exitcode == 0
        with record_lookups() as rec:
            two = _maps(case)
    fe = [r for r in rec if r["kind"] == "fe"]
    # every body (healthy and cracked, each map asks for its own) comes from the other process
    assert len({r["key"] for r in fe}) >= 2 and all(r["hit"] for r in fe), fe
    for a, b in zip(one, two, strict=True):
        assert np.array_equal(a.k_mb, b.k_mb) and np.array_equal(a.dd, b.dd)
        assert a.attrs["inputs_hash"] == b.attrs["inputs_hash"]
    assert np.min(two[1].k_mb) < 0.97 * np.min(two[0].k_mb)        # the crack is in the second map


@pytest.mark.slow
def test_one_process_builds_the_faulty_bodies_first(case, tmp_path, monkeypatch):
    """Without a second process the context builds the faulty map's bodies before the block
    (faulty body first, reported through ``progress`` to its full count); the block finds every
    body in the cache and its maps are the bytes of a plain build; a cached faulty map or a
    disabled cache builds nothing first."""
    monkeypatch.setenv("GEARDYN_CACHE_DIR", str(tmp_path / "first"))
    monkeypatch.setenv(FE_PROCESSES_ENV, "0")
    calls = []
    with record_lookups() as before:
        with faulty_bodies_in_background(case, progress=lambda d, t: calls.append((d, t))) as b:
            assert not b.started
            built = [r for r in before if r["kind"] == "fe"]
            with record_lookups() as inside:
                first = _maps(case)
    assert built and not built[0]["hit"]                     # built here, before the block
    assert calls and calls[-1][0] == calls[-1][1] == len(built)
    fe = [r for r in inside if r["kind"] == "fe"]
    assert fe and all(r["hit"] for r in fe), fe              # the block only loads bodies
    monkeypatch.setenv("GEARDYN_CACHE_DIR", str(tmp_path / "plain"))
    plain = _maps(case)
    for a, b in zip(plain, first, strict=True):
        assert np.array_equal(a.k_mb, b.k_mb) and a.attrs["inputs_hash"] == b.attrs["inputs_hash"]
    with record_lookups() as again:  # the faulty map is cached now: nothing is built first
        with faulty_bodies_in_background(case):
            pass
    assert not [r for r in again if r["kind"] == "fe"]
    monkeypatch.setenv("GEARDYN_NO_CACHE", "1")  # nothing to keep the bodies in: nothing first
    monkeypatch.setenv("GEARDYN_CACHE_DIR", str(tmp_path / "off"))
    with record_lookups() as off:
        with faulty_bodies_in_background(case):
            pass
    assert not off and not (tmp_path / "off" / "fe").exists()


@pytest.mark.slow
def test_racing_the_second_process_gives_the_same_maps(case, tmp_path, monkeypatch):
    """No waiting: whichever process comes to a body first builds it (the entry's lock)."""
    monkeypatch.setenv("GEARDYN_CACHE_DIR", str(tmp_path / "race"))
    monkeypatch.setenv(FE_PROCESSES_ENV, "1")
    with faulty_bodies_in_background(case) as back:
        assert back.started
        raced = _maps(case)
    assert back.process.exitcode == 0
    monkeypatch.setenv("GEARDYN_CACHE_DIR", str(tmp_path / "alone"))
    monkeypatch.setenv(FE_PROCESSES_ENV, "0")
    alone = _maps(case)
    for a, b in zip(alone, raced, strict=True):
        assert np.array_equal(a.k_mb, b.k_mb)


@pytest.mark.slow
def test_an_error_in_the_block_stops_the_second_process_at_once(case, tmp_path, monkeypatch):
    monkeypatch.setenv("GEARDYN_CACHE_DIR", str(tmp_path / "c"))
    monkeypatch.setenv(FE_PROCESSES_ENV, "1")
    t0 = time.perf_counter()
    with pytest.raises(KeyboardInterrupt):
        with faulty_bodies_in_background(case) as back:
            assert back.process.is_alive()
            raise KeyboardInterrupt
    assert not back.process.is_alive() and back.process.exitcode != 0
    assert time.perf_counter() - t0 < 15


def test_it_starts_only_when_it_helps(case, tmp_path, monkeypatch):
    monkeypatch.setenv("GEARDYN_CACHE_DIR", str(tmp_path / "c"))
    monkeypatch.setenv(FE_PROCESSES_ENV, "1")
    cache = Cache()
    assert bg._wanted(case, cache, "fe")
    assert not bg._wanted(case, cache, "pem")                       # no FE bodies
    healthy = case.with_overrides({"crack.enabled": False})
    assert not bg._wanted(healthy, cache, "fe")                     # no faulty body
    monkeypatch.setenv("GEARDYN_NO_CACHE", "1")
    assert not bg._wanted(case, Cache(), "fe")                      # nowhere to share them
    monkeypatch.delenv("GEARDYN_NO_CACHE")
    monkeypatch.setenv(FE_PROCESSES_ENV, "0")
    assert not bg._wanted(case, cache, "fe")                        # not allowed


@pytest.mark.slow
def test_not_started_when_the_faulty_map_is_cached(case, tmp_path, monkeypatch):
    monkeypatch.setenv("GEARDYN_CACHE_DIR", str(tmp_path / "c"))
    monkeypatch.setenv(FE_PROCESSES_ENV, "0")
    build_map(case, cracked=True)
    monkeypatch.setenv(FE_PROCESSES_ENV, "1")
    with faulty_bodies_in_background(case) as back:
        assert not back.started


@pytest.mark.parametrize("value, expected", [("0", 0), ("1", 1), (" 1 ", 1)])
def test_the_setting(monkeypatch, value, expected):
    monkeypatch.setenv(FE_PROCESSES_ENV, value)
    assert fe_processes() == expected


@pytest.mark.parametrize("value", ["2", "-1", "yes", "0.5"])
def test_a_bad_setting_names_the_variable_its_value_and_what_is_allowed(monkeypatch, value):
    monkeypatch.setenv(FE_PROCESSES_ENV, value)
    with pytest.raises(ValueError) as info:
        fe_processes()
    assert FE_PROCESSES_ENV in str(info.value) and repr(value) in str(info.value)
    # what is allowed, in words (mutation testing, 2026-11-26: the text was not checked)
    assert "0 (everything in one process) or 1 (a second process builds the faulty FE map's " \
        "bodies, and one draws the report's figures)" in str(info.value)


@pytest.mark.parametrize("value", ["", "  "])
def test_an_empty_setting_is_the_default(monkeypatch, value):
    """``GEARDYN_FE_PROCESSES=`` (set, but to nothing) is the default, not a bad value."""
    monkeypatch.setenv(FE_PROCESSES_ENV, value)
    monkeypatch.setattr(processes, "_available_memory", lambda: 8 * 1024 ** 3)
    for cores, expected in [(2, 1), (1, 0)]:
        monkeypatch.setattr(os, "cpu_count", lambda c=cores: c)
        assert fe_processes() == expected


def test_the_default_needs_two_cores_and_the_memory(monkeypatch):
    monkeypatch.delenv(FE_PROCESSES_ENV, raising=False)
    big, small = 8 * 1024 ** 3, 1024 ** 3
    for cores, avail, expected in [(2, big, 1), (1, big, 0), (None, big, 0), (2, small, 0),
                                   (16, bg.MIN_AVAILABLE_BYTES, 1), (2, None, 1)]:
        monkeypatch.setattr(os, "cpu_count", lambda c=cores: c)
        monkeypatch.setattr(processes, "_available_memory", lambda a=avail: a)
        assert fe_processes() == expected, (cores, avail)


def test_available_memory_is_read_from_meminfo():
    avail = bg._available_memory()
    if not os.path.exists("/proc/meminfo"):
        assert avail is None
    else:
        assert avail is not None and 0 < avail < 1 << 50


def test_available_memory_is_meminfos_kib_in_bytes(monkeypatch):
    """``MemAvailable`` is in KiB (proc(5)): the function answers bytes; a file without the
    line, or an unreadable one, answers None (the default then does not depend on memory)."""
    import builtins
    import io

    real_open = builtins.open
    text = {"now": "MemTotal:       24000000 kB\nMemAvailable:    3145728 kB\nCached: 1 kB\n"}

    def fake_open(path, *args, **kwargs):
        if path == "/proc/meminfo":
            if text["now"] is None:
                raise PermissionError(path)
            return io.StringIO(text["now"])
        return real_open(path, *args, **kwargs)

    monkeypatch.setattr(builtins, "open", fake_open)
    assert processes._available_memory() == 3145728 * 1024 == processes.MIN_AVAILABLE_BYTES
    text["now"] = "MemTotal:       24000000 kB\n"
    assert processes._available_memory() is None
    text["now"] = None
    assert processes._available_memory() is None


@pytest.mark.slow
def test_geardyn_stiffness_with_the_second_process(tmp_path):
    """Through the CLI, as a user runs it: the same maps as in one process, no process left."""

    import xarray as xr

    sets = [a for k, v in SMALL.items() for a in ("--set", f"{k}={v}")]
    outs = {}
    for n in ("1", "0"):
        env = dict(os.environ, GEARDYN_FE_PROCESSES=n,
                   GEARDYN_CACHE_DIR=str(tmp_path / f"cache{n}"))
        out = tmp_path / f"out{n}"
        r = run_geardyn(["stiffness", "--method", "fe",
                         *sets, "--out", str(out)], capture_output=True, text=True, env=env,
                        timeout=300)
        assert r.returncode == 0, r.stdout + r.stderr
        with xr.open_dataset(out / "stiffness_cracked.nc", engine="h5netcdf") as ds:
            outs[n] = ds["k_mb"].values.copy()
    np.testing.assert_array_equal(outs["1"], outs["0"])


def _mark(path) -> None:
    """A follow-up task for the second process: write ``path``."""
    from pathlib import Path

    Path(path).write_text(str(os.getpid()))


@pytest.mark.slow
def test_follow_up_work_runs_after_the_bodies_and_outlives_the_block(case, tmp_path,
                                                                     monkeypatch):
    import functools

    monkeypatch.setenv("GEARDYN_CACHE_DIR", str(tmp_path / "c"))
    monkeypatch.setenv(FE_PROCESSES_ENV, "1")
    marker = tmp_path / "done"
    t0 = time.perf_counter()
    with faulty_bodies_in_background(case, then=(functools.partial(_mark, marker),)) as back:
        assert back.started
    assert back.process.is_alive() or marker.exists()   # the block did not wait for the task
    back.process.join(timeout=300)
    assert back.process.exitcode == 0
    assert int(marker.read_text()) == back.process.pid != os.getpid()
    with record_lookups() as rec:
        build_map(case, cracked=True)
    assert all(r["hit"] for r in rec if r["kind"] == "fe")  # the bodies came before the task
    assert time.perf_counter() - t0 < 300


@pytest.mark.slow
def test_compile_kernels_leaves_the_time_step_kernel_compiled():
    from geardyn.dynamics import _kernel
    from geardyn.dynamics.warm import compile_kernels

    seconds = compile_kernels()
    assert seconds > 0 and _kernel.advance.signatures


def _boom() -> None:
    raise RuntimeError("a follow-up task that fails")


@pytest.mark.slow
def test_an_error_in_the_second_process_ends_it_quietly(case, tmp_path, monkeypatch, capfd):
    monkeypatch.setenv("GEARDYN_CACHE_DIR", str(tmp_path / "c"))
    monkeypatch.setenv(FE_PROCESSES_ENV, "1")
    with faulty_bodies_in_background(case, then=(_boom,)) as back:
        pass
    back.process.join(timeout=300)
    assert back.process.exitcode == 1
    err = capfd.readouterr().err
    assert "Traceback" not in err and "a follow-up task that fails" not in err


@pytest.mark.slow
def test_the_second_process_fills_the_callers_cache(case, tmp_path, monkeypatch):
    """A cache given by the caller, not the default one, receives the bodies."""
    monkeypatch.setenv("GEARDYN_CACHE_DIR", str(tmp_path / "default"))
    monkeypatch.setenv(FE_PROCESSES_ENV, "1")
    mine = Cache(tmp_path / "mine", enabled=True)
    with faulty_bodies_in_background(case, cache=mine) as back:
        back.process.join(timeout=300)
    assert back.process.exitcode == 0
    assert len(list((tmp_path / "mine" / "fe").glob("*.npz"))) >= 2
    assert not (tmp_path / "default" / "fe").exists()


UNGUARDED = """
import geardyn
from geardyn.stiffness import build_map
from geardyn.stiffness.fe.background import faulty_bodies_in_background
print("top level ran", flush=True)
case = geardyn.paper_case().with_overrides({overrides!r})
with faulty_bodies_in_background(case) as bg:
    build_map(case, cracked=False)
    build_map(case, cracked=True)
bg.process.join()
print("second process exit", bg.process.exitcode, flush=True)
"""


@pytest.mark.slow
def test_a_users_script_without_a_main_guard_runs_once(tmp_path):
    """The second process does not import the user's script (which would run its top level
    again, and fail with multiprocessing's bootstrapping error without a main guard)."""
    import subprocess
    import sys

    script = tmp_path / "script.py"
    script.write_text(UNGUARDED.format(overrides=SMALL))
    env = dict(os.environ, GEARDYN_FE_PROCESSES="1", GEARDYN_CACHE_DIR=str(tmp_path / "c"))
    r = subprocess.run([sys.executable, str(script)], capture_output=True, text=True, env=env,
                       timeout=300, cwd=tmp_path)
    assert r.returncode == 0, r.stderr
    assert r.stdout.count("top level ran") == 1, r.stdout
    assert "second process exit 0" in r.stdout, r.stdout + r.stderr
    assert "Traceback" not in r.stderr and "RuntimeError" not in r.stderr, r.stderr[-1500:]


def test_the_main_module_is_put_back():
    import __main__

    def state():
        return ("__spec__" in vars(__main__), vars(__main__).get("__spec__"),
                "__file__" in vars(__main__), vars(__main__).get("__file__"))

    before = state()
    with bg._without_main_module():
        assert getattr(__main__, "__spec__", None) is None and "__file__" not in vars(__main__)
    assert state() == before
    with pytest.raises(KeyError):
        with bg._without_main_module():
            raise KeyError("an error while starting")
    assert state() == before


def test_not_started_in_a_daemonic_process_or_when_starting_fails(case, tmp_path, monkeypatch):
    import multiprocessing

    monkeypatch.setenv("GEARDYN_CACHE_DIR", str(tmp_path / "c"))
    monkeypatch.setenv(FE_PROCESSES_ENV, "1")
    cache = Cache()
    assert bg._wanted(case, cache, "fe")

    class Daemon:
        daemon = True

    with monkeypatch.context() as m:
        m.setattr(multiprocessing, "current_process", lambda: Daemon())
        assert not bg._wanted(case, cache, "fe")   # a pool's worker may not have children

    def refuse(_proc):
        raise OSError("Resource temporarily unavailable")

    monkeypatch.setattr(bg, "_start_quietly", refuse)
    with faulty_bodies_in_background(case) as back:
        assert not back.started                    # one process builds everything


@pytest.mark.slow
def test_the_second_process_draws_the_mesh_figures_this_one_then_copies(case, tmp_path,
                                                                        monkeypatch):
    """The ``then`` tasks of ``geardyn stiffness`` and ``geardyn run``: the second process,
    holding the cracked body's mesh, draws the FE mesh figures into the cache; this process
    then takes them from there without drawing (or meshing), and they are the bytes this
    process draws itself."""
    from functools import partial

    import geardyn.stiffness.fe as fe
    from geardyn.studies.paper_result import PLOT_MESH, FigureStore, fe_mesh_figure_task
    from geardyn.studies.stiffness_outputs import _fe_mesh_png, fe_mesh_png_task

    monkeypatch.setenv("GEARDYN_CACHE_DIR", str(tmp_path / "ahead"))
    monkeypatch.setenv(FE_PROCESSES_ENV, "1")
    tasks = (partial(fe_mesh_png_task, case, True), partial(fe_mesh_figure_task, case, True))
    with faulty_bodies_in_background(case, then=tasks) as back:
        assert back.started
    back.process.join(timeout=300)  # (with then work the block does not wait for it)
    assert back.process.exitcode == 0
    real = fe.plot_mesh

    def never(*_a, **_k):
        raise AssertionError("drawn here")

    monkeypatch.setattr(fe, "plot_mesh", never)
    with record_lookups() as rec:
        _fe_mesh_png(tmp_path / "a" / "fe_mesh.png", case, True)
        store = FigureStore()
        store.cached_here("fig_fe_mesh", PLOT_MESH, case, cracked=True)
    assert [(r["kind"], r["hit"]) for r in rec] == [("output", True), ("figure", True)]
    # the oracle: both drawn here, into another cache
    monkeypatch.setattr(fe, "plot_mesh", real)
    monkeypatch.setenv("GEARDYN_CACHE_DIR", str(tmp_path / "here"))
    _fe_mesh_png(tmp_path / "b" / "fe_mesh.png", case, True)
    here = FigureStore()
    here.cached_here("fig_fe_mesh", PLOT_MESH, case, cracked=True)
    assert (tmp_path / "a" / "fe_mesh.png").read_bytes() == \
        (tmp_path / "b" / "fe_mesh.png").read_bytes()
    assert store["fig_fe_mesh"].png == here["fig_fe_mesh"].png


@pytest.mark.parametrize("compiled, order", [(True, ["figure", "kernel"]),
                                             (False, ["kernel", "figure"])])
def test_the_kernel_first_only_where_numba_must_compile_it(monkeypatch, compiled, order):
    """A full run's second process: the mesh figure first where the kernel only loads (the
    first process asks for the figure as its maps end), the kernel first where it compiles
    (the first process waits for it at its simulations)."""
    import geardyn.dynamics.warm as warm
    import geardyn.studies.paper_result as pr

    calls: list[str] = []
    monkeypatch.setattr(warm, "kernels_compiled", lambda: compiled)
    monkeypatch.setattr(warm, "compile_kernels", lambda: calls.append("kernel"))
    monkeypatch.setattr(pr, "fe_mesh_figure_task", lambda *_a: calls.append("figure"))
    pr.kernels_and_mesh_figure_task(None, True)
    assert calls == order
