"""``geardyn cache info / clear``: what the cache holds, removing all or some of it, entries in
use left alone, a hit marks an entry as used, bad input as a one-line error."""

from __future__ import annotations

import os
import subprocess
import sys
import time
from pathlib import Path

import pytest
from filelock import FileLock

from geardyn.cache import Cache
from geardyn.cache_admin import cache_usage, parse_age, prune
from geardyn.errors import InputError

from .._cli_fork import run_geardyn

GEARDYN = [sys.executable, "-m", "geardyn"]
DAY = 86400.0


def _cli(*args, cache: Path):
    env = {**os.environ, "GEARDYN_CACHE_DIR": str(cache)}
    return run_geardyn(list(args), capture_output=True, text=True, env=env,
                       timeout=120, stdin=subprocess.DEVNULL)


def _fill(root: Path, now: float) -> Cache:
    """Entries of two kinds: 'maps' 3 x 1000 bytes (used 0, 10 and 40 days ago), 'runs' 2 x 500
    bytes (used 2 and 50 days ago)."""
    cache = Cache(root, enabled=True)
    for kind, size, ages in (("maps", 1000, (0, 10, 40)), ("runs", 500, (2, 50))):
        for i, age in enumerate(ages):
            data = bytes([i]) * size
            cache.get_or_build(kind, f"{kind}{i}", ".bin", lambda d=data: d,
                               lambda d, p: Path(p).write_bytes(d),
                               lambda p: Path(p).read_bytes())
            os.utime(cache.path(kind, f"{kind}{i}", ".bin"), (now - age * DAY,) * 2)
    return cache


def _sidecar(cache, kind, key):
    p = cache.path(kind, key, ".bin")
    return p.with_name(p.name + ".sha256")


def test_usage_counts_entries_sizes_and_last_use(tmp_path):
    now = time.time()
    cache = _fill(tmp_path / "c", now)
    usage = {u.kind: u for u in cache_usage(cache)}
    assert set(usage) == {"maps", "runs"}
    side = _sidecar(cache, "maps", "maps0").stat().st_size
    assert usage["maps"].entries == 3 and usage["maps"].bytes == 3 * 1000 + 3 * side
    assert usage["runs"].entries == 2
    assert usage["maps"].oldest == pytest.approx(now - 40 * DAY, abs=1)
    assert usage["maps"].newest == pytest.approx(now, abs=1)
    assert cache_usage(Cache(tmp_path / "nothing", enabled=True)) == []


def test_prune_by_kind_and_age_removes_file_sidecar_and_lock(tmp_path):
    now = time.time()
    cache = _fill(tmp_path / "c", now)
    dry = prune(cache, older_than=30 * DAY, dry_run=True, now=now)
    assert dry.removed == {"maps": (1, dry.removed["maps"][1]), "runs": (1, dry.removed["runs"][1])}
    assert cache.path("maps", "maps2", ".bin").exists()                 # dry run: nothing gone
    done = prune(cache, kinds=("maps",), older_than=5 * DAY, now=now)
    assert done.entries == 2 and done.kept == 3                       # maps0 and the two runs
    for key in ("maps1", "maps2"):
        p = cache.path("maps", key, ".bin")
        assert not p.exists() and not _sidecar(cache, "maps", key).exists()
        assert not p.with_name(p.name + ".lock").exists()
    assert cache.path("maps", "maps0", ".bin").exists()
    assert cache.path("runs", "runs1", ".bin").exists()               # other kind, 50 days old
    # a removed entry is built again on the next use
    calls = []
    obj, hit = cache.get_or_build("maps", "maps1", ".bin", lambda: calls.append(1) or b"x",
                                  lambda d, p: Path(p).write_bytes(d),
                                  lambda p: Path(p).read_bytes())
    assert (obj, hit, calls) == (b"x", False, [1])


def test_an_entry_in_use_is_left_alone(tmp_path):
    cache = _fill(tmp_path / "c", time.time())
    p = cache.path("runs", "runs0", ".bin")
    with FileLock(str(p.with_name(p.name + ".lock"))):
        res = prune(cache, kinds=("runs",))
    assert res.in_use == 1 and res.entries == 1 and p.exists()


def test_a_hit_marks_the_entry_as_used(tmp_path):
    now = time.time()
    cache = _fill(tmp_path / "c", now)
    p = cache.path("maps", "maps2", ".bin")
    assert p.stat().st_mtime < now - 39 * DAY
    _, hit = cache.get_or_build("maps", "maps2", ".bin", lambda: b"never built",
                                lambda d, q: Path(q).write_bytes(d),
                                lambda q: Path(q).read_bytes())
    assert hit and p.stat().st_mtime > now - 60
    assert prune(cache, older_than=30 * DAY, dry_run=True).removed.get("maps") is None


@pytest.mark.parametrize("text, seconds", [("30 d", 30 * DAY), ("12h", 12 * 3600.0),
                                           ("1.5 w", 1.5 * 7 * DAY), ("90 min", 5400.0),
                                           ("0 s", 0.0)])
def test_parse_age(text, seconds):
    assert parse_age(text) == pytest.approx(seconds)


@pytest.mark.parametrize("text", ["30", "d", "-1 d", "3 weeks", "1e3 s", ""])
def test_parse_age_refuses_with_the_field_and_the_forms(text):
    with pytest.raises(InputError, match="--older-than.*s, min, h, d or w"):
        parse_age(text)


def test_prune_refuses_an_unknown_kind(tmp_path):
    cache = _fill(tmp_path / "c", time.time())
    with pytest.raises(InputError, match="--kind.*'maps', 'runs'"):
        prune(cache, kinds=("mpas",))


@pytest.mark.slow
def test_the_commands(tmp_path):
    root = tmp_path / "c"
    _fill(root, time.time())
    r = _cli("cache", "info", cache=root)
    assert r.returncode == 0, r.stderr
    assert str(root) in r.stdout and "maps" in r.stdout and "runs" in r.stdout
    assert "all" in r.stdout and " 5 " in r.stdout
    r = _cli("cache", "clear", "--older-than", "30 d", "--dry-run", cache=root)
    assert r.returncode == 0 and "would remove 2 entries" in r.stdout, r.stdout + r.stderr
    r = _cli("cache", "clear", "--older-than", "30 d", cache=root)          # no --yes, no tty
    assert r.returncode == 2 and "--yes" in r.stderr and "Traceback" not in r.stderr
    assert len([ln for ln in r.stderr.splitlines() if ln.strip()]) == 1
    r = _cli("cache", "clear", "--older-than", "30 d", "--yes", cache=root)
    assert r.returncode == 0 and "removed 2 entries" in r.stdout and "3 kept" in r.stdout
    for bad in (["--kind", "nope"], ["--older-than", "soon"]):
        r = _cli("cache", "clear", *bad, "--yes", cache=root)
        assert r.returncode == 2 and "Traceback" not in r.stderr, r.stderr
        assert bad[0] in r.stderr and bad[1] in r.stderr
    r = _cli("cache", "clear", "--yes", cache=root)
    assert r.returncode == 0 and "removed 3 entries" in r.stdout
    r = _cli("cache", "info", cache=root)
    assert r.returncode == 0 and " 0 " in r.stdout
    r = _cli("cache", "info", cache=tmp_path / "never-made")
    assert r.returncode == 0 and "empty" in r.stdout


def test_a_kind_with_a_space_may_be_typed_with_an_underscore_or_a_hyphen(tmp_path):
    """``map values`` (the study's map numbers) is the one kind with a space: ``--kind
    map_values`` or ``map-values`` name it without shell quotes."""
    now = time.time()
    cache = Cache(tmp_path / "c", enabled=True)
    for key in ("a", "b"):
        cache.get_or_build("map values", key, ".json", lambda: b"{}",
                           lambda d, p: Path(p).write_bytes(d), lambda p: Path(p).read_bytes())
    for spelling in ("map_values", "map-values"):
        dry = prune(cache, kinds=(spelling,), dry_run=True, now=now)
        assert dry.removed["map values"][0] == 2, spelling
    with pytest.raises(InputError, match="--kind"):
        prune(cache, kinds=("map__values",))


def test_files_geardyn_did_not_write_are_neither_counted_nor_removed(tmp_path):
    """``cache clear --kind measurements --yes`` removed a user's CSV files under a folder the
    cache variable pointed at (a user audit, 2026-11-27): an entry is a file with geardyn's
    ``.sha256`` sidecar."""
    cache = _fill(tmp_path / "c", time.time())
    mine = tmp_path / "c" / "measurements"
    mine.mkdir()
    for k in range(3):
        (mine / f"run{k}.csv").write_text("1\n")
    (tmp_path / "c" / "maps" / "notes.txt").write_text("mine")
    kinds = {u.kind: u.entries for u in cache_usage(cache)}
    assert kinds.get("measurements", 0) == 0
    r = _cli("cache", "clear", "--yes", cache=tmp_path / "c")
    assert r.returncode == 0, r.stderr
    assert sorted(p.name for p in mine.iterdir()) == ["run0.csv", "run1.csv", "run2.csv"]
    assert (tmp_path / "c" / "maps" / "notes.txt").read_text() == "mine"
    assert sum(u.entries for u in cache_usage(cache)) == 0  # geardyn's own are gone
