"""File input/output with integrity: atomic writes and checked reads.

Every file geardyn writes goes to a temporary file in the destination folder first and is then
renamed over the destination (``os.replace``, atomic on POSIX), so an interrupted run never leaves a
half-written result. Reads turn missing, truncated or foreign files into :class:`DataFileError`.

Temporary files are named ``.<name>.<host>.<pid>.<random><suffix>``: a process killed before its
rename leaves one behind, and the next write of the same destination (or
:func:`remove_stale_temp_files` on the folder) deletes it once it is stale: its owner process is
gone (same host), or it is older than :data:`STALE_SECONDS` (another host sharing the folder).
"""

from __future__ import annotations

import contextlib
import json
import os
import re
import socket
import tempfile
import time
from collections.abc import Iterable, Iterator
from pathlib import Path

from .errors import DataFileError

__all__ = ["atomic_path", "write_bytes_atomic", "write_text_atomic", "write_json_atomic", "json_safe",
           "write_netcdf_atomic", "read_text", "read_netcdf", "temp_prefix", "remove_stale_temp_files",
           "STALE_SECONDS"]

#: Age after which a temporary file of another host (or of a process that cannot be checked) is
#: stale [s].
STALE_SECONDS = 24 * 3600.0
_HOST = re.sub(r"[^A-Za-z0-9_-]", "_", socket.gethostname())[:40] or "host"
#: ``.<name>.<host>.<pid>.<random><suffix>`` (the random part from :func:`tempfile.mkstemp`, or a
#: hex string)
_TEMP = re.compile(r"^\.(?P<name>.+)\.(?P<host>[A-Za-z0-9_-]+)\.(?P<pid>\d+)\.[A-Za-z0-9_]{6,32}"
                   r"(?:\.[A-Za-z0-9]+)?$")


def temp_prefix(dest: str | os.PathLike) -> str:
    """The name prefix of this process's temporary files for ``dest``: ``.<name>.<host>.<pid>.``."""
    return f".{Path(dest).name}.{_HOST}.{os.getpid()}."


def _pid_alive(pid: int) -> bool:
    try:
        os.kill(pid, 0)
    except ProcessLookupError:
        return False
    except (PermissionError, OSError):  # exists but not ours, or cannot tell
        return True
    return True


def _is_stale(path: Path, host: str, pid: int, max_age: float) -> bool:
    if host == _HOST and pid != os.getpid() and not _pid_alive(pid):
        return True
    try:
        return time.time() - path.lstat().st_mtime > max_age
    except OSError:
        return False


def remove_stale_temp_files(folder: str | os.PathLike, name: str | None = None,
                            max_age: float = STALE_SECONDS) -> list[Path]:
    """Delete temporary files (and folders) left in ``folder`` by killed geardyn processes.

    Only entries named like geardyn's temporary files (``.<name>.<host>.<pid>.<random>...``) are
    considered, and only stale ones are removed: the owner process (``pid`` on this host) is gone,
    or the entry is older than ``max_age`` [s]. Temporary files of live processes are kept.

    Parameters
    ----------
    folder : path-like
    name : str, optional
        Only the temporary files of this destination name.
    max_age : float
        Age [s] beyond which any temporary file counts as stale.

    Returns
    -------
    list of Path
        The entries removed.
    """
    import shutil

    removed: list[Path] = []
    try:
        entries = list(Path(folder).iterdir())
    except OSError:
        return removed
    for p in entries:
        m = _TEMP.match(p.name)
        if m is None or (name is not None and m["name"] != name):
            continue
        if not _is_stale(p, m["host"], int(m["pid"]), max_age):
            continue
        try:
            if p.is_dir() and not p.is_symlink():
                shutil.rmtree(p)
            else:
                p.unlink()
            removed.append(p)
        except OSError:  # removed by someone else meanwhile, or not ours to remove
            continue
    return removed


@contextlib.contextmanager
def atomic_path(path: str | os.PathLike, suffix: str = "") -> Iterator[Path]:
    """Yield a temporary path beside ``path``; on success rename it to ``path``.

    On any exception (including KeyboardInterrupt) the temporary file is removed and ``path`` is
    left as it was. Stale temporary files of ``path`` left by killed processes are removed first
    (:func:`remove_stale_temp_files`).
    """
    dest = Path(path)
    dest.parent.mkdir(parents=True, exist_ok=True)
    remove_stale_temp_files(dest.parent, dest.name)
    fd, tmp = tempfile.mkstemp(prefix=temp_prefix(dest), suffix=suffix or ".tmp", dir=dest.parent)
    os.close(fd)
    tmp_path = Path(tmp)
    try:
        yield tmp_path
        os.chmod(tmp_path, 0o666 & ~_umask())  # mkstemp makes 0600; results are ordinary files
        os.replace(tmp_path, dest)
    except BaseException:
        with contextlib.suppress(FileNotFoundError):
            tmp_path.unlink()
        raise


def _umask() -> int:
    mask = os.umask(0)
    os.umask(mask)
    return mask


def write_bytes_atomic(path: str | os.PathLike, data: bytes) -> None:
    """Write ``data`` to ``path`` atomically (fsync before the rename)."""
    with atomic_path(path) as tmp:
        with open(tmp, "wb") as fh:
            fh.write(data)
            fh.flush()
            os.fsync(fh.fileno())


def write_text_atomic(path: str | os.PathLike, text: str) -> None:
    """Write UTF-8 ``text`` to ``path`` atomically."""
    write_bytes_atomic(path, text.encode("utf-8"))


def json_safe(obj: object) -> object:
    """A copy of ``obj`` that strict JSON accepts: NaN and infinities become ``None`` (null),
    NumPy scalars and arrays become Python numbers and lists, tuples become lists."""
    import math

    import numpy as np

    if isinstance(obj, dict):
        return {str(k): json_safe(v) for k, v in obj.items()}
    if isinstance(obj, list | tuple):
        return [json_safe(v) for v in obj]
    if isinstance(obj, np.ndarray):
        return [json_safe(v) for v in obj.tolist()]
    if isinstance(obj, np.bool_):
        return bool(obj)
    if isinstance(obj, np.integer):
        return int(obj)
    if isinstance(obj, float | np.floating):
        v = float(obj)
        return v if math.isfinite(v) else None
    return obj


def write_json_atomic(path: str | os.PathLike, obj: object) -> None:
    """Write ``obj`` as indented strict JSON to ``path`` atomically (NaN written as null)."""
    write_text_atomic(path, json.dumps(json_safe(obj), indent=2, allow_nan=False) + "\n")


def write_netcdf_atomic(ds, path: str | os.PathLike) -> None:
    """Write an xarray Dataset to NetCDF-4 (h5netcdf engine) atomically."""
    with atomic_path(path, suffix=".nc") as tmp:
        ds.to_netcdf(tmp, engine="h5netcdf")


def read_text(path: str | os.PathLike, kind: str = "text file") -> str:
    """Read a UTF-8 text file, turning every failure into a :class:`DataFileError`.

    Parameters
    ----------
    path : path-like
    kind : str
        What the file should be, for the message (``"case file"``, ``"sweep file"``).
    """
    p = Path(path)
    try:
        return p.read_text(encoding="utf-8")
    except FileNotFoundError:
        raise DataFileError(p, "no such file") from None
    except IsADirectoryError:
        raise DataFileError(p, f"is a directory, not a {kind}") from None
    except (OSError, UnicodeDecodeError) as exc:
        raise DataFileError(p, f"cannot be read ({exc})") from None


def read_netcdf(path: str | os.PathLike, required: Iterable[str] = ()):
    """Open a NetCDF file fully into memory, with clear errors.

    Parameters
    ----------
    path : path-like
    required : iterable of str
        Variables that must be present.

    Raises
    ------
    DataFileError
        Missing, unreadable, truncated or not NetCDF/HDF5, or lacking a required variable.
    """
    import xarray as xr

    p = Path(path)
    if not p.exists():
        raise DataFileError(p, "no such file")
    if p.is_dir():
        raise DataFileError(p, "is a directory, not a NetCDF file")
    try:
        with xr.open_dataset(p, engine="h5netcdf") as ds:
            ds = ds.load()
    except Exception as exc:  # h5py/h5netcdf raise many types for bad files
        raise DataFileError(p, f"is not a readable NetCDF-4 file ({type(exc).__name__}: {exc})"
                            ) from None
    missing = [v for v in required if v not in ds.variables]
    if missing:
        raise DataFileError(p, f"lacks the variable(s) {', '.join(missing)}")
    return ds
