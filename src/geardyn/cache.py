"""Content-addressed on-disk cache with checksums and atomic writes.

Entries are keyed by a hash of their inputs (the caller builds a JSON-serialisable description of
everything the result depends on, including the geardyn version). Each entry is a file plus a
``.sha256`` sidecar holding the file's checksum and the inputs' key; a missing, truncated or
corrupted entry fails the check, is deleted, and is rebuilt by the caller. Writes are atomic
(temporary file, then rename), so two processes building the same entry at once leave one valid
entry.

The cache folder is ``$GEARDYN_CACHE_DIR`` if set, else ``~/.cache/geardyn``. Set
``GEARDYN_NO_CACHE=1`` to bypass it.
"""

from __future__ import annotations

import contextlib
import hashlib
import json
import os
from collections.abc import Callable
from pathlib import Path
from typing import TypeVar

from .io import write_bytes_atomic, write_text_atomic

__all__ = ["cache_dir", "cache_key", "Cache", "default_cache"]

T = TypeVar("T")


def cache_dir() -> Path:
    """The cache folder (``$GEARDYN_CACHE_DIR`` or ``~/.cache/geardyn``)."""
    env = os.environ.get("GEARDYN_CACHE_DIR")
    return Path(env) if env else Path.home() / ".cache" / "geardyn"


def cache_key(payload: object) -> str:
    """SHA-256 (hex, 32 characters) of the canonical JSON of ``payload``."""
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
    """Exclusive advisory lock on ``<entry>.lock`` (POSIX ``flock``; no-op elsewhere)."""
    path.parent.mkdir(parents=True, exist_ok=True)
    try:
        import fcntl
    except ImportError:  # pragma: no cover - not POSIX
        yield
        return
    with open(path.with_name(path.name + ".lock"), "a+") as fh:
        fcntl.flock(fh.fileno(), fcntl.LOCK_EX)
        try:
            yield
        finally:
            fcntl.flock(fh.fileno(), fcntl.LOCK_UN)


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
        """True if ``path`` exists and matches its sidecar checksum and key."""
        side = path.with_name(path.name + ".sha256")
        try:
            meta = json.loads(side.read_text())
            return meta.get("key") == key and meta.get("sha256") == _sha256_file(path)
        except (OSError, ValueError):
            return False

    def discard(self, path: Path) -> None:
        """Delete an entry and its sidecar (missing files are fine)."""
        for p in (path, path.with_name(path.name + ".sha256")):
            with contextlib.suppress(FileNotFoundError):
                p.unlink()

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
            ``load(path)`` reads it back.

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
            if path.exists():
                if self.valid(path, key):
                    try:
                        return load(path), True
                    except Exception:  # unreadable despite checksum (format change): rebuild
                        self.discard(path)
                else:
                    self.discard(path)
            obj = build()
            self.store(obj, path, key, save)
        return obj, False

    def store(self, obj: object, path: Path, key: str, save: Callable[[object, Path], None]) -> None:
        """Write ``obj`` to ``path`` atomically, then its sidecar."""
        path.parent.mkdir(parents=True, exist_ok=True)
        tmp = path.with_name(f".{path.name}.{os.getpid()}.tmp{path.suffix}")
        try:
            save(obj, tmp)
            digest = _sha256_file(tmp)
            os.replace(tmp, path)
        except BaseException:
            with contextlib.suppress(FileNotFoundError):
                tmp.unlink()
            raise
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


def default_cache() -> Cache:
    """The cache in :func:`cache_dir`, honouring ``GEARDYN_NO_CACHE``."""
    return Cache()
