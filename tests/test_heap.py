"""geardyn.heap: freed memory handed back to the operating system (glibc's malloc_trim)."""

from __future__ import annotations

import pytest

from geardyn import heap

glibc = pytest.mark.skipif(heap._malloc_trim() is None,
                           reason="the C library here has no malloc_trim (not glibc)")


def _rss_mb() -> float:
    with open("/proc/self/status") as fh:
        for line in fh:
            if line.startswith("VmRSS"):
                return int(line.split()[1]) / 1024
    raise AssertionError("no VmRSS in /proc/self/status")


@glibc
def test_freed_pages_below_the_top_of_the_heap_leave_the_resident_set():
    """60 MB of 2 kB objects (above Python's small-object allocator, so from C's malloc), one
    more kept after them so that the freed ones are not at the top of the heap (which free()
    itself gives back): once freed, their pages stay resident (glibc keeps them) until
    ``release_free_memory()``, after which the resident set is at least 40 MB lower and the
    call says it released memory. In this process, as the study calls it."""
    blocks = [bytearray(2000) for _ in range(30000)]
    pin = bytearray(2000)
    del blocks
    before = _rss_mb()
    released = heap.release_free_memory()
    after = _rss_mb()
    assert released is True
    assert before - after >= 40.0, (before, after)
    assert len(pin) == 2000


def test_a_collection_only_when_asked(monkeypatch):
    """The garbage collector runs only with ``collect=True`` (a collection in the study's
    process raised its later peak: the module's docstring)."""
    import gc

    calls = []
    monkeypatch.setattr(gc, "collect", lambda *a: calls.append(a) or 0)
    heap.release_free_memory()
    assert calls == []
    heap.release_free_memory(collect=True)
    assert calls == [()]


def test_without_malloc_trim_nothing_is_done(monkeypatch):
    """Where the C library has no ``malloc_trim`` (macOS, musl, Windows) the call does nothing
    and says so."""
    monkeypatch.setattr(heap, "_malloc_trim", lambda: None)
    assert heap.release_free_memory() is False
    assert heap.release_free_memory(collect=True) is False


@glibc
def test_nothing_in_use_is_freed():
    """Objects alive across the call keep their contents (the trim frees free pages only)."""
    import numpy as np

    a = np.arange(2_000_000, dtype=float)
    b = [bytes([i % 256]) * 3000 for i in range(2000)]
    heap.release_free_memory(collect=True)
    np.testing.assert_array_equal(a, np.arange(2_000_000, dtype=float))
    assert all(x == bytes([i % 256]) * 3000 for i, x in enumerate(b))
