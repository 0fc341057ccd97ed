"""Content-addressed on-disk cache with checksums and atomic writes.

Entries are keyed by a hash of their inputs (the caller builds a JSON-serialisable description of
everything the result depends on, including the geardyn version, and hashes it with
:func:`cache_key`, the one hashing convention of geardyn's caches). Each entry is a file plus a
``.sha256`` sidecar holding the file's checksum and the inputs' key; a missing, truncated or
corrupted entry fails the check, is deleted, and is rebuilt by the caller. The caller's ``load``
may also refuse an entry whose content records other inputs (a stiffness map compares its stored
``inputs_hash`` with the key): such an entry is rebuilt too. Writes are atomic (temporary file,
then rename), so two processes building the same entry at once leave one valid entry; temporary
files of killed builders are removed once stale (:func:`geardyn.io.remove_stale_temp_files`).
Entries are locked with :mod:`filelock` (``fcntl.flock`` on POSIX, ``msvcrt.locking`` on
Windows).

The cache folder is ``$GEARDYN_CACHE_DIR`` if set, else the platform's user cache folder from
:func:`platformdirs.user_cache_dir` (``$XDG_CACHE_HOME/geardyn``, by default
``~/.cache/geardyn``, on Linux; ``~/Library/Caches/geardyn`` on macOS;
``%LOCALAPPDATA%\\geardyn\\Cache`` on Windows). Set ``GEARDYN_NO_CACHE=1`` to bypass it.
"""

from __future__ import annotations

import contextlib
import hashlib
import json
import os
import time
from collections.abc import Callable
from pathlib import Path
from typing import TypeVar

from .errors import DataFileError
from .io import atomic_path, remove_stale_temp_files, write_bytes_atomic, write_text_atomic

__all__ = ["cache_dir", "cache_key", "Cache", "default_cache", "record_lookups"]

T = TypeVar("T")


def cache_dir() -> Path:
    """The cache folder: ``$GEARDYN_CACHE_DIR``, else the platform's user cache folder for
    ``geardyn`` (:func:`platformdirs.user_cache_dir`, which honours ``XDG_CACHE_HOME``)."""
    env = os.environ.get("GEARDYN_CACHE_DIR")
    if env:
        return Path(env)
    from platformdirs import user_cache_dir

    return Path(user_cache_dir("geardyn", appauthor=False))


def cache_key(payload: object) -> str:
    """SHA-256 (hex, 32 characters) of the canonical JSON of ``payload``.

    Canonical: keys sorted, no spaces, UTF-8; what JSON cannot hold is written with ``repr``.
    The one hashing convention of geardyn's caches and stores (stiffness maps, FE bodies, sweep
    identities).
    """
    text = json.dumps(payload, sort_keys=True, separators=(",", ":"), default=repr)
    return hashlib.sha256(text.encode("utf-8")).hexdigest()[:32]


def _sha256_file(path: Path) -> str:
    h = hashlib.sha256()
    with open(path, "rb") as fh:
        for chunk in iter(lambda: fh.read(1 << 20), b""):
            h.update(chunk)
    return h.hexdigest()


@contextlib.contextmanager
def _entry_lock(path: Path):
    """Exclusive lock on ``<entry>.lock`` (:class:`filelock.FileLock`: ``flock`` on POSIX,
    ``msvcrt.locking`` on Windows), held while the entry is checked, built and stored."""
    from filelock import FileLock

    lock_path = path.with_name(path.name + ".lock")
    try:
        path.parent.mkdir(parents=True, exist_ok=True)
        lock = FileLock(str(lock_path))
        lock.acquire()
    except OSError as exc:
        raise DataFileError(lock_path, f"cannot be used as the cache entry's lock ({exc}); "
                                       "remove it, or set GEARDYN_NO_CACHE=1") from None
    try:
        yield
    finally:
        lock.release()


def _touch(path: Path) -> None:
    """Mark an entry as used now (its modification time: ``geardyn cache clear --older-than``
    removes what was not used for a while). A read-only cache keeps its times."""
    try:
        os.utime(path)
    except OSError:
        return


class Cache:
    """A folder of checksummed entries.

    Parameters
    ----------
    root : path-like, optional
        Folder; default :func:`cache_dir`.
    enabled : bool, optional
        ``False`` makes every lookup miss and every store a no-op; default: on unless
        ``GEARDYN_NO_CACHE`` is set.
    """

    def __init__(self, root: str | os.PathLike | None = None, enabled: bool | None = None):
        self.root = Path(root) if root is not None else cache_dir()
        self.enabled = (os.environ.get("GEARDYN_NO_CACHE", "") in ("", "0")) if enabled is None \
            else enabled

    def path(self, kind: str, key: str, suffix: str) -> Path:
        """Where the entry ``kind/key+suffix`` lives."""
        return self.root / kind / f"{key}{suffix}"

    def valid(self, path: Path, key: str) -> bool:
        """True if ``path`` is a readable file matching its sidecar checksum and key."""
        side = path.with_name(path.name + ".sha256")
        if not (path.is_file() and side.is_file()):  # a folder, a FIFO (would block), a dangling link
            return False
        try:
            meta = json.loads(side.read_text())
            return (isinstance(meta, dict) and meta.get("key") == key
                    and meta.get("sha256") == _sha256_file(path))
        except (OSError, ValueError):
            return False

    def discard(self, path: Path) -> None:
        """Delete an entry and its sidecar (missing files are fine).

        Raises
        ------
        DataFileError
            The entry or its sidecar is a folder, or cannot be deleted: the cache does not remove
            what it did not write.
        """
        for p in (path, path.with_name(path.name + ".sha256")):
            if p.is_dir() and not p.is_symlink():
                raise DataFileError(p, "is a folder where a cache entry belongs; remove it, or "
                                       "set GEARDYN_NO_CACHE=1")
            try:
                p.unlink()
            except FileNotFoundError:
                continue
            except OSError as exc:
                raise DataFileError(p, f"is a damaged cache entry that cannot be removed ({exc}); "
                                       "remove it, or set GEARDYN_NO_CACHE=1") from None

    def get_or_build(self, kind: str, key: str, suffix: str,
                     build: Callable[[], T], save: Callable[[T, Path], None],
                     load: Callable[[Path], T]) -> tuple[T, bool]:
        """Return the cached object for ``key`` or build, store and return it.

        Parameters
        ----------
        kind : str
            Sub-folder (``"stiffness"``, ``"fe"``...).
        key : str
            Hash of the inputs (:func:`cache_key`).
        suffix : str
            File suffix, e.g. ``".nc"``.
        build : callable
            Computes the object on a miss.
        save : callable
            ``save(obj, path)`` writes the object to ``path`` (a temporary path; the cache renames
            it into place).
        load : callable
            ``load(path)`` reads it back; it raises if the content is not what ``key`` describes
            (e.g. a stored inputs hash that differs from ``key``), and the entry is rebuilt.

        Returns
        -------
        (object, bool)
            The object, and whether it came from the cache.
        """
        path = self.path(kind, key, suffix)
        if not self.enabled:
            return build(), False
        # One builder per entry: a second process wanting the same entry waits for the first
        # and then loads its result, so concurrent runs do the work once and leave one valid
        # entry.
        with _entry_lock(path):
            remove_stale_temp_files(path.parent, path.name)
            if path.exists() or path.with_name(path.name + ".sha256").exists():
                if self.valid(path, key):
                    try:
                        obj = load(path)
                        _note_lookup(kind, key, True, path)
                        _touch(path)
                        return obj, True
                    except Exception:  # unreadable despite checksum (format change), or its
                        self.discard(path)  # content records other inputs: rebuild
                else:
                    self.discard(path)
            obj = build()
            try:
                self.store(obj, path, key, save)
            except Exception as exc:  # a full disk: the cache is an optimisation, the result
                if not _disk_full(path, exc):  # stands without it
                    raise
                _say_full(path, exc)
        _note_lookup(kind, key, False)
        return obj, False

    def write_file(self, kind: str, key: str, target: str | os.PathLike,
                   write: Callable[[Path], None]) -> bool:
        """Write the file ``target`` through the cache: a copy of the entry for ``key`` if there
        is a valid one, else ``write(path)`` into a new entry that is then copied.

        For output files that are a pure function of ``key`` (the caller hashes the data, the
        writer's settings and the versions of the libraries that encode it), so that a run into
        another folder copies the bytes instead of encoding and compressing them again. The
        entry is checked like any other (checksum and key in the sidecar) while its lock is
        held, and ``target`` is written atomically. Without the cache ``write(target)`` runs
        (atomically).

        Parameters
        ----------
        kind : str
            Sub-folder of the cache.
        key : str
            Hash of everything the file's bytes depend on.
        target : path-like
            The file to write (its suffix is the entry's).
        write : callable
            ``write(path)`` writes the file to ``path`` (a temporary path).

        Returns
        -------
        bool
            Whether the bytes came from the cache.
        """
        import shutil

        target = Path(target)
        if not self.enabled:
            with atomic_path(target, suffix=target.suffix) as tmp:
                write(tmp)
            return False
        path = self.path(kind, key, target.suffix)
        with _entry_lock(path):
            remove_stale_temp_files(path.parent, path.name)
            hit = False
            if path.exists() or path.with_name(path.name + ".sha256").exists():
                hit = self.valid(path, key)
                if not hit:
                    self.discard(path)
                else:
                    _touch(path)
            if not hit:
                try:
                    self.store(None, path, key, lambda _obj, tmp: write(tmp))
                except Exception as exc:
                    if not _disk_full(path, exc):
                        raise
                    _say_full(path, exc)  # written straight to the target instead
                    with atomic_path(target, suffix=target.suffix) as tmp:
                        write(tmp)
                    _note_lookup(kind, key, False)
                    return False
            with atomic_path(target, suffix=target.suffix) as tmp:
                shutil.copyfile(path, tmp)
        _note_lookup(kind, key, hit, path)
        return hit

    def store(self, obj: object, path: Path, key: str, save: Callable[[object, Path], None]) -> None:
        """Write ``obj`` to ``path`` atomically, then its sidecar."""
        with atomic_path(path, suffix=path.suffix) as tmp:
            save(obj, tmp)
            digest = _sha256_file(tmp)
        write_text_atomic(path.with_name(path.name + ".sha256"),
                          json.dumps({"key": key, "sha256": digest}))

    def put_bytes(self, kind: str, key: str, suffix: str, data: bytes) -> Path:
        """Store raw bytes under ``key``; returns the entry's path."""
        path = self.path(kind, key, suffix)
        path.parent.mkdir(parents=True, exist_ok=True)
        write_bytes_atomic(path, data)
        write_text_atomic(path.with_name(path.name + ".sha256"),
                          json.dumps({"key": key, "sha256": hashlib.sha256(data).hexdigest()}))
        return path


#: Active lookup recorders (see :func:`record_lookups`); each is a list of dicts.
_RECORDERS: list[tuple[list[dict], float]] = []  # (lookups, wall time the block began)


#: Free bytes below which a failed cache write is taken for a full disk.
_FULL_BELOW = 8 << 20


def _disk_full(path: Path, exc: BaseException) -> bool:
    """Whether writing the cache entry ``path`` failed because its disk is full: ENOSPC or
    EDQUOT, or (netCDF-C and HDF5 report a full disk as "Permission denied" or "HDF error")
    any error while the disk holds less than :data:`_FULL_BELOW` free bytes."""
    import errno
    import shutil

    if isinstance(exc, OSError) and exc.errno in (errno.ENOSPC, errno.EDQUOT):
        return True
    try:
        return shutil.disk_usage(path.parent if path.parent.exists() else cache_dir()).free \
            < _FULL_BELOW
    except OSError:
        return False


_SAID_FULL: set[str] = set()


def _say_full(path: Path, exc: BaseException) -> None:
    """Warn once per cache folder that it is full and results go uncached (a sweep whose
    cache filled its disk failed every run with "Permission denied": a user audit)."""
    import warnings

    folder = str(path.parent.parent)
    if folder in _SAID_FULL:
        return
    _SAID_FULL.add(folder)
    warnings.warn(f"the geardyn cache {folder} is on a full disk ({type(exc).__name__}: "
                  f"{exc}); results are computed without being cached: free space or point "
                  "GEARDYN_CACHE_DIR elsewhere", CacheFullWarning, stacklevel=3)


class CacheFullWarning(UserWarning):
    """The cache's disk is full: results are computed, not cached."""


def _note_lookup(kind: str, key: str, hit: bool, path: Path | None = None) -> None:
    """Record a lookup in every :func:`record_lookups` block. A hit on an entry written after
    the block began was computed during it, by another process (the FE bodies' second process)
    or an earlier lookup: recorded as built (a cold run reported "fe 4 reused", a user audit of
    2026-11-27)."""
    written = None
    if hit and path is not None:
        try:
            written = path.with_name(path.name + ".sha256").stat().st_mtime
        except OSError:
            written = None
    for rec, began in _RECORDERS:
        fresh = hit and written is not None and written >= began
        rec.append({"kind": kind, "key": key, "hit": hit and not fresh,
                    **({"built_during_run": True} if fresh else {})})


@contextlib.contextmanager
def record_lookups():
    """Collect this process's :meth:`Cache.get_or_build` lookups while the block runs.

    Yields a list that receives one ``{"kind", "key", "hit"}`` dict per lookup (``hit`` is True
    when the entry was loaded from the cache as it was before the block began, False when it
    was built, here or, during the block, by another process: ``built_during_run``). The command-line tool
    writes it into its output folder's ``inputs.json``, so a re-run shows what it reused.
    """
    rec: list[dict] = []
    entry = (rec, time.time())
    _RECORDERS.append(entry)
    try:
        yield rec
    finally:
        _RECORDERS.remove(entry)


def default_cache() -> Cache:
    """The cache in :func:`cache_dir`, honouring ``GEARDYN_NO_CACHE``."""
    return Cache()
