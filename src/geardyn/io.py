"""File input/output with integrity: atomic writes and checked reads.

Every file geardyn writes goes to a temporary file in the destination folder first and is then
renamed over the destination (``os.replace``, atomic on POSIX), so an interrupted run never leaves a
half-written result. Reads turn missing, truncated or foreign files into :class:`DataFileError`.
"""

from __future__ import annotations

import contextlib
import json
import os
import tempfile
from collections.abc import Iterable, Iterator
from pathlib import Path

from .errors import DataFileError

__all__ = ["atomic_path", "write_bytes_atomic", "write_text_atomic", "write_json_atomic", "json_safe",
           "write_netcdf_atomic", "read_text", "read_netcdf"]


@contextlib.contextmanager
def atomic_path(path: str | os.PathLike, suffix: str = "") -> Iterator[Path]:
    """Yield a temporary path beside ``path``; on success rename it to ``path``.

    On any exception (including KeyboardInterrupt) the temporary file is removed and ``path`` is
    left as it was.
    """
    dest = Path(path)
    dest.parent.mkdir(parents=True, exist_ok=True)
    fd, tmp = tempfile.mkstemp(prefix=f".{dest.name}.", suffix=suffix or ".tmp", dir=dest.parent)
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
