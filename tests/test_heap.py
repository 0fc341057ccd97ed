"""geardyn.heap: freed memory handed back to the operating system (glibc's malloc_trim)."""

from __future__ import annotations

import subprocess
import sys
import textwrap

import pytest

from geardyn import heap

glibc = pytest.mark.skipif(heap._malloc_trim() is None,
                           reason="the C library here has no malloc_trim (not glibc)")

# In a fresh interpreter: 60 MB of 2 kB objects (above Python's small-object allocator, so
# from C's malloc), one more kept after them so that the freed ones are not at the top of the
# heap (which free() itself would give back), all but that one freed; the resident set is
# read from /proc before and after release_free_memory().
_CHILD = textwrap.dedent("""
    import json
    from geardyn.heap import release_free_memory

    def rss_mb():
        with open("/proc/self/status") as fh:
            for line in fh:
                if line.startswith("VmRSS"):
                    return int(line.split()[1]) / 1024

    blocks = [bytearray(2000) for _ in range(30000)]
    pin = bytearray(2000)
    del blocks
    before = rss_mb()
    released = release_free_memory()
    after = rss_mb()
    print(json.dumps({"before": before, "after": after, "released": released,
                      "pin": len(pin)}))
""")


@glibc
def test_freed_pages_below_the_top_of_the_heap_leave_the_resident_set():
    """The pages of 60 MB freed below a live object stay resident after ``free`` (glibc keeps
    them) and leave with ``release_free_memory()``: the resident set falls by at least 40 MB,
    and the call says it released memory."""
    import json

    out = subprocess.run([sys.executable, "-c", _CHILD], capture_output=True, text=True,
                         check=True, timeout=120)
    r = json.loads(out.stdout)
    assert r["released"] is True
    assert r["before"] - r["after"] >= 40.0, r


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
