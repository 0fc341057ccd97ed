"""What the disk cache holds, and removing entries from it (``geardyn cache info / clear``).

The cache (:mod:`geardyn.cache`) keeps every stiffness map, FE body, simulation, diagnosis,
figure and output file a run computed, so that a re-run is fast; nothing removes them by
itself. The paper's ``geardyn run`` adds about 170 MB; FE bodies are 1-40 MB each. This module
counts the entries by kind and removes them, all or those of some kinds or not used for some
time. An entry is its file and its ``.sha256`` sidecar; "last used" is the file's modification
time, which the cache sets when it stores an entry and again on every hit.

Removing is safe against running geardyn processes: each entry is removed under its own lock,
and an entry whose lock is held (a process is building or checking it) is left alone and
counted as in use. A process that had already opened an entry keeps reading it (POSIX); one
that looks for it afterwards builds it again.
"""

from __future__ import annotations

import os
import re
import time
from dataclasses import dataclass, field
from pathlib import Path

from .cache import Cache
from .errors import InputError

__all__ = ["KindUsage", "PruneResult", "cache_usage", "prune", "parse_age"]

#: Suffixes of the files that belong to an entry but are not the entry.
_SIDE_SUFFIXES = (".sha256", ".lock")

_AGE = re.compile(r"^\s*(\d+(?:\.\d*)?|\.\d+)\s*(s|min|h|d|w)\s*$")
_AGE_UNITS = {"s": 1.0, "min": 60.0, "h": 3600.0, "d": 86400.0, "w": 7 * 86400.0}


def parse_age(text: str, field_name: str = "--older-than") -> float:
    """An age like ``"30 d"``, ``"12h"``, ``"2 w"`` or ``"90 min"`` in seconds.

    Raises
    ------
    InputError
        Anything else (the message names ``field_name``, the value and the allowed forms).
    """
    m = _AGE.match(str(text))
    if not m:
        raise InputError(field_name, text, "a number and a unit: s, min, h, d or w (e.g. "
                                           "'30 d', '12h')")
    return float(m.group(1)) * _AGE_UNITS[m.group(2)]


def _is_entry(path: Path) -> bool:
    """A geardyn entry: a file with the ``.sha256`` sidecar :meth:`Cache.store` writes beside
    it. Any other file under the cache folder is not geardyn's to count or remove (``cache
    clear`` removed a user's CSV files under a folder the cache variable pointed at: a user
    audit, 2026-11-27)."""
    name = path.name
    return (path.is_file() and not name.endswith(_SIDE_SUFFIXES) and ".tmp" not in name
            and not name.startswith(".")
            and path.with_name(name + ".sha256").is_file())


@dataclass(frozen=True)
class KindUsage:
    """Entries of one kind (a sub-folder of the cache).

    Attributes
    ----------
    kind : str
    entries : int
    bytes : int
        Size of the entries and their sidecars [bytes].
    oldest, newest : float or None
        Last use of the least and the most recently used entry [s since the epoch].
    """

    kind: str
    entries: int
    bytes: int
    oldest: float | None
    newest: float | None


def _entries(cache: Cache) -> dict[str, list[Path]]:
    """Kind (sub-folder) -> its entries' files, sorted."""
    root = cache.root
    if not root.is_dir():
        return {}
    return {folder.name: sorted(p for p in folder.iterdir() if _is_entry(p))
            for folder in sorted(p for p in root.iterdir() if p.is_dir())}


def _size(path: Path) -> int:
    total = 0
    for p in (path, path.with_name(path.name + ".sha256")):
        try:
            total += p.stat().st_size
        except OSError:
            continue
    return total


def cache_usage(cache: Cache | None = None) -> list[KindUsage]:
    """Entries, size and last use of each kind in the cache (sorted by kind)."""
    cache = cache or Cache()
    usage = []
    for kind, paths in _entries(cache).items():
        times = []
        for p in paths:
            try:
                times.append(p.stat().st_mtime)
            except OSError:
                continue
        usage.append(KindUsage(kind, len(paths), sum(_size(p) for p in paths),
                               min(times) if times else None, max(times) if times else None))
    return usage


@dataclass
class PruneResult:
    """What :func:`prune` removed (or would remove, ``dry_run``).

    Attributes
    ----------
    removed : dict of str -> (int, int)
        Kind -> (entries, bytes).
    in_use : int
        Entries left alone because a process held their lock.
    kept : int
        Entries younger than the age limit, or of other kinds.
    """

    removed: dict[str, tuple[int, int]] = field(default_factory=dict)
    in_use: int = 0
    kept: int = 0

    @property
    def entries(self) -> int:
        """Entries removed."""
        return sum(n for n, _ in self.removed.values())

    @property
    def bytes(self) -> int:
        """Bytes freed."""
        return sum(b for _, b in self.removed.values())


def prune(cache: Cache | None = None, *, kinds: tuple[str, ...] | None = None,
          older_than: float | None = None, dry_run: bool = False,
          now: float | None = None) -> PruneResult:
    """Remove cache entries: of ``kinds`` (default all) and unused for more than ``older_than``
    seconds (default any age).

    Parameters
    ----------
    cache : Cache, optional
        Default: the user's cache (:func:`geardyn.cache.cache_dir`).
    kinds : tuple of str, optional
        Sub-folders to prune; each must exist in the cache.
    older_than : float, optional
        Age [s] of the last use beyond which an entry goes (>= 0).
    dry_run : bool
        Count what would go, remove nothing.
    now : float, optional
        The present [s since the epoch] (tests).

    Raises
    ------
    InputError
        A kind that is not in the cache, or a negative age.
    """
    from filelock import FileLock, Timeout

    cache = cache or Cache()
    all_entries = _entries(cache)
    if kinds is not None:
        present = list(all_entries)
        # a kind with a space ("map values") may be typed unquoted as map_values or map-values
        spelled = {k.replace(" ", "_"): k for k in present} | {k.replace(" ", "-"): k
                                                               for k in present}
        kinds = [spelled.get(k, k) for k in kinds]
        for k in kinds:
            if k not in present:
                raise InputError("--kind", k, "one of the kinds in the cache: "
                                 + (", ".join(repr(p) for p in present) or "(the cache is empty)"))
    if older_than is not None and not older_than >= 0:
        raise InputError("--older-than", older_than, "an age >= 0")
    now = time.time() if now is None else now
    result = PruneResult()
    for kind, paths in all_entries.items():
        if kinds is not None and kind not in kinds:
            result.kept += len(paths)
            continue
        n = size = 0
        for path in paths:
            try:
                age = now - path.stat().st_mtime
            except OSError:
                continue  # removed meanwhile
            if older_than is not None and age <= older_than:
                result.kept += 1
                continue
            lock_path = path.with_name(path.name + ".lock")
            lock = FileLock(str(lock_path))
            try:
                lock.acquire(timeout=0)
            except Timeout:
                result.in_use += 1
                continue
            try:
                b = _size(path)
                if not dry_run:
                    cache.discard(path)
                n += 1
                size += b
            finally:
                lock.release()
            if not dry_run:
                try:
                    os.unlink(lock_path)
                except OSError:  # another process removed it, or holds it: an empty file
                    continue
        if n:
            result.removed[kind] = (n, size)
    return result
