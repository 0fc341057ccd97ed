"""What a run says it reused: an entry written during the run (by the FE bodies' second
process, or earlier in the run) is computed, not reused, and each entry counts once (a cold
``geardyn run`` reported "fe 4 reused / 1 computed" with 2 entries in an empty cache: a user
audit, 2026-11-27)."""

from __future__ import annotations

import time

from geardyn.cache import Cache, record_lookups
from geardyn.cli._outputs import cache_summary


def _get(cache: Cache, key: str):
    return cache.get_or_build("stiffness", key, ".txt", lambda: key,
                              save=lambda obj, p: p.write_text(obj),
                              load=lambda p: p.read_text())


def test_entries_written_during_the_run_are_computed_and_counted_once(tmp_path, monkeypatch):
    monkeypatch.delenv("GEARDYN_NO_CACHE", raising=False)
    cache = Cache(tmp_path)
    _get(cache, "old")  # before the run
    time.sleep(0.05)
    with record_lookups() as rec:
        _get(cache, "old")                     # reused
        _get(Cache(tmp_path), "new")           # built (as by another process)
        _get(cache, "new")                     # loaded, but written during the run
        _get(cache, "new")
    assert [r["hit"] for r in rec] == [True, False, False, False]
    assert [r.get("built_during_run", False) for r in rec] == [False, False, True, True]
    assert cache_summary(rec) == {"stiffness": {"hits": 1, "built": 1}}


def test_a_full_disk_leaves_results_uncached_not_failed(tmp_path, monkeypatch):
    """A sweep whose cache filled its disk failed every run ("Permission denied" from
    netCDF-C), and a re-run kept them failed (a user audit, 2026-11-27): a full disk now
    leaves the result uncached, with one warning; another error still raises."""
    import errno
    import shutil as sh
    from collections import namedtuple

    import pytest

    import geardyn.cache as gc

    monkeypatch.delenv("GEARDYN_NO_CACHE", raising=False)
    monkeypatch.setattr(gc, "_SAID_FULL", set())
    cache = Cache(tmp_path / "c")

    def full(*args, **kwargs):
        raise OSError(errno.ENOSPC, "No space left on device")

    monkeypatch.setattr(Cache, "store", full)
    with pytest.warns(gc.CacheFullWarning, match="full disk"):
        assert _get(cache, "a") == ("a", False)
    target = tmp_path / "out.txt"
    assert cache.write_file("output", "k", target, lambda p: p.write_text("bytes")) is False
    assert target.read_text() == "bytes"

    def denied(*args, **kwargs):
        raise PermissionError(errno.EACCES, "Permission denied")

    monkeypatch.setattr(Cache, "store", denied)
    usage = namedtuple("usage", "total used free")
    monkeypatch.setattr(sh, "disk_usage", lambda p: usage(1 << 30, 1 << 30, 1 << 10))
    assert _get(cache, "b") == ("b", False)  # "Permission denied" on a full disk: full
    monkeypatch.setattr(sh, "disk_usage", lambda p: usage(1 << 40, 0, 1 << 39))
    with pytest.raises(PermissionError):  # with room on the disk: a real error
        _get(cache, "c")
