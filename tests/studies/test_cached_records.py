"""The simulation records of a run are read from the simulation cache at each access
(``studies.paper.CachedRecords``): the same data as computed, a pruned or tampered entry
simulated again, and held in memory when there is no disk cache."""

from __future__ import annotations

import numpy as np
import pytest

import geardyn
from geardyn.cache import Cache
from geardyn.stiffness import build_map
from geardyn.studies.paper import CachedRecords, _simulation_key, cached_simulation

SMALL = {"stiffness.method": "pem", "stiffness.centre_distances": 6,
         "stiffness.nodes_per_segment": 8, "simulation.settle_time": 0.002,
         "simulation.record_time": 0.004}


@pytest.fixture(scope="module")
def job():
    case = geardyn.paper_case().with_overrides(SMALL)
    return case, build_map(case, cracked=True), "II"


def _same(a, b) -> None:
    assert list(a.variables) == list(b.variables) and a.attrs == b.attrs
    for name in a.variables:
        assert np.array_equal(a[name].values, b[name].values), name


def test_records_come_back_as_computed_even_after_a_prune_or_tampering(job, tmp_path):
    cache = Cache(tmp_path / "c", enabled=True)
    ds = cached_simulation(*job, cache=cache)
    records = CachedRecords(cache)
    records.add(("II", "cracked"), ds, *job)
    assert list(records) == [("II", "cracked")] and len(records) == 1
    first = records[("II", "cracked")]
    assert first is not ds  # read back, not held
    _same(ds, first)
    path = cache.path("simulation", _simulation_key(*job), ".npz")
    path.unlink()  # pruned meanwhile: simulated again through the cache
    _same(ds, records[("II", "cracked")])
    assert path.is_file()
    data = bytearray(path.read_bytes())  # tampered: its checksum fails, so it is not read
    data[-100] ^= 0xFF
    path.write_bytes(bytes(data))
    _same(ds, records[("II", "cracked")])
    assert cache.valid(path, _simulation_key(*job))  # and the entry was rebuilt


def test_without_a_disk_cache_the_records_are_held(job, tmp_path):
    cache = Cache(tmp_path / "off", enabled=False)
    ds = cached_simulation(*job, cache=cache)
    records = CachedRecords(cache)
    records.add(("II", "cracked"), ds, *job)
    assert records[("II", "cracked")] is ds
