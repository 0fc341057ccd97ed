"""Tampered cache entries and temporary files left by killed processes.

Oracle for "rebuilt": a clean build of the same map into an empty cache; the rebuilt map must
equal it bit for bit (every array and every attribute).
"""

from __future__ import annotations

import hashlib
import json
import os
import shutil
import subprocess
import sys
import time
import warnings

import numpy as np
import pytest

from geardyn import paper_case
from geardyn.cache import Cache, cache_key
from geardyn.errors import DataFileError
from geardyn.io import temp_prefix, write_bytes_atomic
from geardyn.stiffness import build_map, map_inputs
from geardyn.stiffness import map as map_module

SMALL = {"stiffness.centre_distances": 3, "stiffness.nodes_per_segment": 5}


@pytest.fixture(scope="module")
def case():
    return paper_case(SMALL)


def _build(case, cache, cracked):
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")  # the PEM's documented range warnings
        return build_map(case, method="pem", cracked=cracked, cache=cache)


def _assert_identical(a, b):
    for name in ("dd", "phase_a", "length_a", "k_mb", "slot_tooth"):
        np.testing.assert_array_equal(getattr(a, name), getattr(b, name), err_msg=name)
    assert (a.mesh_angle, a.n_cycles, a.n_seg, a.base_radius) == (
        b.mesh_angle, b.n_cycles, b.n_seg, b.base_radius)
    assert sorted(a.extra) == sorted(b.extra)
    for name in a.extra:
        np.testing.assert_array_equal(a.extra[name], b.extra[name], err_msg=name)
    assert dict(a.attrs) == dict(b.attrs)


@pytest.fixture(scope="module")
def clean(case, tmp_path_factory):
    """Healthy and cracked maps built once into an empty cache (the oracle)."""
    cache = Cache(tmp_path_factory.mktemp("clean"), enabled=True)
    return {"healthy": _build(case, cache, False), "cracked": _build(case, cache, True)}


def _sidecar(path, key):
    """A sidecar that matches the (substituted) content: only the inputs hash can tell."""
    digest = hashlib.sha256(path.read_bytes()).hexdigest()
    path.with_name(path.name + ".sha256").write_text(json.dumps({"key": key, "sha256": digest}))


def test_a_cracked_map_copied_over_the_healthy_key_is_rebuilt(case, clean, tmp_path):
    cache = Cache(tmp_path, enabled=True)
    healthy, cracked = _build(case, cache, False), _build(case, cache, True)
    hkey, ckey = healthy.attrs["inputs_hash"], cracked.attrs["inputs_hash"]
    # one hashing convention: the map records the cache key of its inputs
    assert hkey == cache_key(map_inputs(case, "pem", False)) != ckey
    assert not hasattr(map_module, "_hash_inputs") and not hasattr(map_module, "inputs_hash")
    entry = cache.path("stiffness", hkey, ".nc")
    shutil.copyfile(cache.path("stiffness", ckey, ".nc"), entry)
    _sidecar(entry, hkey)
    assert cache.valid(entry, hkey)  # the checksum alone cannot see it
    again = _build(case, cache, False)
    assert again.attrs["inputs_hash"] == hkey
    assert not np.array_equal(again.k_mb, clean["cracked"].k_mb)
    _assert_identical(again, clean["healthy"])
    # the entry was replaced by the rebuilt map, which now loads as a hit
    _assert_identical(_build(case, cache, False), clean["healthy"])


def test_a_folder_in_place_of_an_entry_is_refused_clearly(case, tmp_path):
    cache = Cache(tmp_path, enabled=True)
    key = _build(case, cache, False).attrs["inputs_hash"]
    entry = cache.path("stiffness", key, ".nc")
    entry.unlink()
    entry.mkdir()
    (entry / "keep.txt").write_text("not the cache's")
    with pytest.raises(DataFileError, match="is a folder where a cache entry belongs"):
        _build(case, cache, False)
    assert (entry / "keep.txt").read_text() == "not the cache's"


@pytest.mark.parametrize("kind", ["dangling_symlink", "fifo", "garbage_sidecar"])
def test_an_unreadable_entry_is_rebuilt(case, clean, tmp_path, kind):
    cache = Cache(tmp_path, enabled=True)
    key = _build(case, cache, False).attrs["inputs_hash"]
    entry = cache.path("stiffness", key, ".nc")
    if kind == "garbage_sidecar":
        entry.with_name(entry.name + ".sha256").write_bytes(b"\xff\xfe[")
    else:
        entry.unlink()
        if kind == "fifo":
            os.mkfifo(entry)  # opening it for reading would block for ever
        else:
            entry.symlink_to(tmp_path / "nowhere.nc")
    _assert_identical(_build(case, cache, False), clean["healthy"])
    assert entry.is_file() and not entry.is_symlink()


def _dead_pid() -> int:
    p = subprocess.Popen([sys.executable, "-c", "pass"])
    p.wait()
    return p.pid


def test_stale_temporary_files_are_removed_and_live_ones_kept(case, tmp_path):
    """Temp files of a killed builder (its pid is gone) or of another host older than a day are
    removed on the next run, in the cache and in an output folder; those of live processes stay."""
    cache = Cache(tmp_path / "cache", enabled=True)
    key = _build(case, cache, False).attrs["inputs_hash"]
    entry = cache.path("stiffness", key, ".nc")
    dead, live = _dead_pid(), os.getppid()
    host = temp_prefix(entry).split(".")[-3]
    folder = entry.parent
    stale = [folder / f".{entry.name}.{host}.{dead}.abc123xy.nc",
             folder / f".{entry.name}.otherhost.{live}.abc123xy.nc"]
    keep = [folder / f".{entry.name}.{host}.{live}.abc123xy.nc",
            folder / f".{entry.name}.otherhost.{dead}.zz9911aa.nc",
            folder / "notes.nc"]
    for p in stale + keep:
        p.write_bytes(b"half")
    old = time.time() - 2 * 86400
    os.utime(stale[1], (old, old))
    _build(case, cache, False)  # a hit: the stale ones go all the same
    assert [p.exists() for p in stale] == [False, False]
    assert all(p.exists() for p in keep)
    # an output folder: the next atomic write of the same destination cleans up
    out = tmp_path / "out"
    out.mkdir()
    left = out / f".result.nc.{host}.{dead}.q1w2e3r4.nc"
    left.write_bytes(b"half")
    other = out / f".other.nc.{host}.{dead}.q1w2e3r4.nc"
    other.write_bytes(b"half")
    write_bytes_atomic(out / "result.nc", b"whole")
    assert not left.exists() and other.exists() and (out / "result.nc").read_bytes() == b"whole"


@pytest.mark.slow
def test_a_cracked_fe_body_copied_over_the_healthy_key_is_rebuilt(tmp_path):
    """The FE body cache (influence coefficients) compares its stored inputs hash with the key.

    Oracle: the healthy body built into an empty cache; the rebuilt entry equals it bit for bit.
    """
    import dataclasses

    from geardyn.stiffness.fe import FESettings
    from geardyn.stiffness.fe.mesh import CrackGeometry
    from geardyn.stiffness.fe.model import body_influence, body_inputs

    case = paper_case()
    settings = dataclasses.replace(FESettings.from_case(case), flank_size=0.15e-3,
                                   tooth_size=1.5e-3, body_size=6e-3, refined_teeth=3, n_points=8)
    from geardyn.stiffness.fe.solve import ElasticMaterial

    gear = case.gear_pair().pinion
    mat = ElasticMaterial(float(case.material.youngs_modulus), float(case.material.poisson_ratio),
                          settings.plane)
    crack = CrackGeometry(depth=2e-3, angle=float(case.crack.angle))
    clean, hit = body_influence(gear, mat, settings, None, cache=Cache(tmp_path / "clean", True))
    assert not hit
    cache = Cache(tmp_path / "tampered", enabled=True)
    body_influence(gear, mat, settings, None, cache=cache)
    cracked, _ = body_influence(gear, mat, settings, crack, cache=cache)
    hkey = cache_key(body_inputs(gear, mat, settings, None))
    ckey = cache_key(body_inputs(gear, mat, settings, crack))
    assert (clean.inputs_hash, cracked.inputs_hash) == (hkey, ckey) and hkey != ckey
    entry = cache.path("fe", hkey, ".npz")
    shutil.copyfile(cache.path("fe", ckey, ".npz"), entry)
    _sidecar(entry, hkey)
    assert cache.valid(entry, hkey)  # the checksum alone cannot see it
    again, hit = body_influence(gear, mat, settings, None, cache=cache)
    assert not hit  # rebuilt, not served
    assert again.inputs_hash == hkey
    np.testing.assert_array_equal(again.H, clean.H)
    np.testing.assert_array_equal(again.u, clean.u)
    assert (again.load_offsets, again.read_offsets) == (clean.load_offsets, clean.read_offsets)
    again2, hit2 = body_influence(gear, mat, settings, None, cache=cache)
    assert hit2 and np.array_equal(again2.H, clean.H)
