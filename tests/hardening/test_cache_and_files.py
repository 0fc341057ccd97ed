"""Cache integrity, concurrent builders, overwrite protection and corrupted inputs."""

from __future__ import annotations

import json
import subprocess
import sys
import textwrap

import numpy as np
import pytest

from geardyn.cache import Cache, cache_key

from .._cli_fork import run_geardyn

BUILDER = textwrap.dedent("""
    import sys, time, pathlib
    from geardyn.cache import Cache
    root, counter = sys.argv[1], pathlib.Path(sys.argv[2])
    def build():
        with open(counter, "a") as fh:
            fh.write("built\\n")
        time.sleep(1.0)
        return b"x" * 100000
    def save(obj, path):
        pathlib.Path(path).write_bytes(obj)
    obj, hit = Cache(root, enabled=True).get_or_build("t", "samekey", ".bin", build, save,
                                                      lambda p: pathlib.Path(p).read_bytes())
    assert obj == b"x" * 100000
    print("hit" if hit else "built")
""")


def test_two_processes_building_one_entry_build_it_once(tmp_path):
    counter = tmp_path / "count.txt"
    procs = [subprocess.Popen([sys.executable, "-c", BUILDER, str(tmp_path / "c"), str(counter)],
                              stdout=subprocess.PIPE, text=True) for _ in range(2)]
    outs = sorted(p.communicate(timeout=60)[0].strip() for p in procs)
    assert all(p.returncode == 0 for p in procs)
    assert outs == ["built", "hit"]
    assert counter.read_text().count("built") == 1
    entry = tmp_path / "c" / "t" / "samekey.bin"
    assert Cache(tmp_path / "c").valid(entry, "samekey")
    assert not [p for p in (tmp_path / "c" / "t").iterdir() if ".tmp" in p.name]


@pytest.mark.parametrize("damage", ["truncate", "flip", "delete_sidecar", "wrong_key"])
def test_damaged_entries_are_detected_and_rebuilt(tmp_path, damage):
    c = Cache(tmp_path, enabled=True)
    builds = []

    def build():
        builds.append(1)
        return np.arange(1000.0)

    def save(obj, path):
        np.save(path, obj, allow_pickle=False)

    def load(path):
        return np.load(path, allow_pickle=False)

    key = cache_key({"a": 1})
    c.get_or_build("k", key, ".npy", build, save, load)
    path = c.path("k", key, ".npy")
    side = path.with_name(path.name + ".sha256")
    if damage == "truncate":
        path.write_bytes(path.read_bytes()[:100])
    elif damage == "flip":
        b = bytearray(path.read_bytes())
        b[-1] ^= 0xFF
        path.write_bytes(bytes(b))
    elif damage == "delete_sidecar":
        side.unlink()
    else:
        side.write_text(json.dumps({"key": "other", "sha256": "0"}))
    obj, hit = c.get_or_build("k", key, ".npy", build, save, load)
    assert not hit and len(builds) == 2
    np.testing.assert_array_equal(obj, np.arange(1000.0))
    assert c.valid(path, key)


def _cli(*args, cwd=None):
    return run_geardyn([*args], capture_output=True,
                       text=True, timeout=300, cwd=cwd)


#: short records on a coarse PEM map: the files are tested here, not the stiffness method
SHORT = ["--set", "simulation.record_time=0.005 s", "--set", "simulation.settle_time=0.001 s",
         "--set", "stiffness.method=pem", "--set", "stiffness.centre_distances=6",
         "--set", "stiffness.nodes_per_segment=8"]


@pytest.mark.slow
def test_outputs_are_not_overwritten_without_force(tmp_path):
    out = tmp_path / "sim.nc"
    assert _cli("simulate", "--out", str(out), *SHORT).returncode == 0
    before = out.read_bytes()
    r = _cli("simulate", "--out", str(out), *SHORT, "--set", "simulation.dt=5e-6 s")
    assert r.returncode == 2 and "--force" in r.stderr and "Traceback" not in r.stderr
    assert out.read_bytes() == before
    assert _cli("simulate", "--out", str(out), *SHORT, "--force").returncode == 0


@pytest.mark.slow
@pytest.mark.parametrize("content", [b"", b"\x89HDF\r\n\x1a\nrubbish", b"not a netcdf file"])
def test_corrupted_netcdf_input_is_a_clean_error(tmp_path, content):
    bad = tmp_path / "bad.nc"
    bad.write_bytes(content)
    r = _cli("diagnose", str(bad), "--out", str(tmp_path / "o"))
    assert r.returncode == 2
    assert "bad.nc" in r.stderr and "Traceback" not in r.stderr


@pytest.mark.slow
def test_truncated_simulation_file_is_a_clean_error(tmp_path):
    out = tmp_path / "sim.nc"
    assert _cli("simulate", "--out", str(out), *SHORT).returncode == 0
    data = out.read_bytes()
    (tmp_path / "trunc.nc").write_bytes(data[: len(data) // 2])
    r = _cli("diagnose", str(tmp_path / "trunc.nc"), "--out", str(tmp_path / "o"))
    assert r.returncode == 2 and "Traceback" not in r.stderr


@pytest.mark.slow
def test_nothing_in_a_case_or_data_file_is_executed(tmp_path):
    """Python written into case values or pickled objects in data files never runs."""
    marker = tmp_path / "pwned"
    payload = f"__import__('os').system('touch {marker}')"
    case = tmp_path / "case.toml"
    case.write_text(f'name = "{payload}"\n[pair]\nmodule = "{payload}"\n')
    r = _cli("config", "validate", str(case))
    assert r.returncode == 2
    r = _cli("geometry", "--set", f"pinion.teeth={payload}")
    assert r.returncode == 2
    # an object array in .npy needs pickle: refused, never unpickled
    class Evil:
        def __reduce__(self):
            return (__import__("os").system, (f"touch {marker}",))

    npy = tmp_path / "evil.npy"
    np.save(npy, np.array([Evil()], dtype=object), allow_pickle=True)
    r = _cli("diagnose", str(npy), "--fs", "1000", "--angle", "0", "--signal", "0",
             "--teeth", "23", "--out", str(tmp_path / "o"))
    assert r.returncode == 2 and "Traceback" not in r.stderr
    assert not marker.exists()


def test_cache_folder_honours_geardyn_cache_dir_then_xdg(tmp_path, monkeypatch):
    """GEARDYN_CACHE_DIR first; else the platform's user cache folder (platformdirs), which on
    Linux is $XDG_CACHE_HOME/geardyn, by default ~/.cache/geardyn."""
    import platformdirs

    from geardyn.cache import cache_dir

    monkeypatch.setenv("GEARDYN_CACHE_DIR", str(tmp_path / "mine"))
    monkeypatch.setenv("XDG_CACHE_HOME", str(tmp_path / "xdg"))
    assert cache_dir() == tmp_path / "mine"
    monkeypatch.delenv("GEARDYN_CACHE_DIR")
    expected = platformdirs.user_cache_path("geardyn", appauthor=False)
    assert cache_dir() == expected
    if sys.platform.startswith("linux"):
        assert cache_dir() == tmp_path / "xdg" / "geardyn"
        monkeypatch.delenv("XDG_CACHE_HOME")
        monkeypatch.setenv("HOME", str(tmp_path / "home"))
        assert cache_dir() == tmp_path / "home" / ".cache" / "geardyn"


def test_entry_lock_excludes_a_second_holder_in_the_same_process(tmp_path):
    """The entry lock (filelock) is a real lock between threads too: the second holder gets it
    only after the first released it."""
    import threading

    from geardyn.cache import _entry_lock

    entry = tmp_path / "k" / "e.nc"
    events: list[str] = []
    held, trying = threading.Event(), threading.Event()

    def second():
        trying.set()
        with _entry_lock(entry):
            events.append("second acquired")

    with _entry_lock(entry):
        t = threading.Thread(target=second)
        t.start()
        trying.wait(10)
        t.join(0.3)  # the second thread is blocked on the lock meanwhile
        assert t.is_alive()
        events.append("first released")
        held.set()
    t.join(10)
    assert events == ["first released", "second acquired"]
