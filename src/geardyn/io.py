"""File input/output with integrity: atomic writes and checked reads.

Every file geardyn writes goes to a temporary file in the destination folder first and is then
renamed over the destination (``os.replace``, atomic on POSIX), so an interrupted run never leaves a
half-written result. Reads turn missing, truncated or foreign files into :class:`DataFileError`.

Temporary files are named ``.<name>.<host>.<pid>.<random><suffix>``: a process killed before its
rename leaves one behind, and the next write of the same destination (or
:func:`remove_stale_temp_files` on the folder) deletes it once it is stale: its owner process is
gone (same host), or it is older than :data:`STALE_SECONDS` (another host sharing the folder).

NetCDF-4 files are written and read through xarray with :func:`netcdf_engine`: netCDF4-python
(Unidata's netCDF-C library) where it is installed and its HDF5 does not clash with h5py's,
h5netcdf (h5py) otherwise. Both write NetCDF-4 (HDF5) files that either reads; netCDF-C creates
and opens variables in C, h5netcdf in Python, per variable (see :func:`netcdf_engine` for what
that costs). Every access holds :data:`NETCDF_LOCK`.
"""

from __future__ import annotations

import contextlib
import functools
import json
import os
import re
import socket
import tempfile
import threading
import time
from collections.abc import Iterable, Iterator, Mapping
from pathlib import Path

from .errors import DataFileError

__all__ = ["atomic_path", "write_bytes_atomic", "write_text_atomic", "write_json_atomic", "json_safe",
           "write_netcdf_atomic", "read_text", "read_netcdf", "netcdf_engine", "netcdf_versions",
           "open_netcdf", "to_netcdf", "NETCDF_LOCK", "temp_prefix", "remove_stale_temp_files",
           "STALE_SECONDS", "NETCDF_COMPRESSION"]

#: HDF5 compression of the numeric variables geardyn writes (run records, ``results.nc``): zlib
#: level 1 with the byte shuffle filter. Level 1 against 4 on a full ``geardyn run``'s files
#: (2026-11-28, this 2-core host): the seven run records written in 2.33 s against 3.47 s and
#: 2 % larger (52.9 MB against 51.8 MB), ``results.nc`` in 0.46 s against 0.68 s and 1 %
#: larger; read back as fast (0.53 s against 0.58 s for the records). The writing is on the
#: study's path after the simulations.
NETCDF_COMPRESSION = {"zlib": True, "complevel": 1, "shuffle": True}

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


#: Held by every NetCDF file access of geardyn from the file's opening to its closing (re-entrant):
#: netCDF-C is not thread-safe, and two Dask threads of one worker reading stiffness maps at once
#: crashed the process (a segmentation fault in one thread's attribute reads while the other
#: closed its file, 2026-11-27); h5py serialises its own calls anyway.
NETCDF_LOCK = threading.RLock()


@functools.cache
def netcdf_engine() -> str:
    """The xarray engine geardyn writes and reads NetCDF-4 files with: ``"netcdf4"`` where
    netCDF4-python is installed and its HDF5 libraries do not clash with h5py's
    (:func:`hdf5_libraries_clash`), else ``"h5netcdf"``.

    Both give NetCDF-4 (HDF5) files with the same variables, values, attributes and groups,
    which either engine reads (``tests/test_netcdf_engines.py``). netCDF4 is the faster: a
    25-variable record of 100,000 points written in 26-30 ms and read in 19-20 ms, against
    96-98 ms and 78-79 ms with h5netcdf, which creates every variable and its dimension scales
    through h5py in Python (xarray 2026.9.0, netCDF4 1.7.5.1 / netCDF-C 4.10.1, h5netcdf 1.8.2,
    2026-11-27, AMD EPYC, 2 cores). Where zlib dominates, less: a compressed run record of the
    paper's case (24 variables x 50,000 samples) 0.145 s against 0.196 s, read back in 0.028 s
    against 0.122 s (``benchmarks/run.py netcdf``). The choice is made once per process, and
    netCDF4 is not imported where it is not chosen.

    Returns
    -------
    str
        ``"netcdf4"`` or ``"h5netcdf"``.
    """
    import importlib.util

    if importlib.util.find_spec("netCDF4") is None or hdf5_libraries_clash():
        return "h5netcdf"
    try:
        import netCDF4  # noqa: F401
    except ImportError:  # a broken install (its compiled module missing)
        return "h5netcdf"
    return "netcdf4"


def _bundled_hdf5(package: str) -> set[str]:
    """File names of the HDF5 libraries a wheel of ``package`` bundles (``<package>.libs/``
    beside it on Linux and Windows, ``<package>/.dylibs/`` on macOS), found without importing
    it; empty where it bundles none (conda shares one HDF5) or is not installed."""
    import importlib.util

    try:
        spec = importlib.util.find_spec(package)
    except (ImportError, ValueError):
        return set()
    if spec is None or not spec.submodule_search_locations:
        return set()
    names: set[str] = set()
    for location in spec.submodule_search_locations:
        pkg = Path(location)
        for folder in (pkg.parent / f"{pkg.name}.libs", pkg.parent / f"{pkg.name.lower()}.libs",
                       pkg / ".dylibs"):
            with contextlib.suppress(OSError):
                names |= {n for n in os.listdir(folder)
                          if n.lower().startswith(("libhdf5", "hdf5"))}
    return names


def hdf5_libraries_clash(first: str = "netCDF4", second: str = "h5py") -> bool:
    """Whether the wheels of ``first`` and ``second`` (netCDF4's and h5py's) bundle an HDF5
    library under the same file name.

    The name carries a hash of the file, so the same name is the same build, and the dynamic
    loader loads it once, bound to the HDF5 of whichever package was imported first: then
    the other's dimension scales fail (``NetCDF: Problem with HDF5 dimscales`` from netCDF4
    after h5py, ``Unspecified error in H5DSis_scale`` from h5py after netCDF4). Seen with
    h5py 3.10.0 and netCDF4 1.7.1.post1 (both ``libhdf5_hl-123198ff.so.310.0.2``) and with
    h5py 3.15.1 and netCDF4 1.7.4; h5py 3.13.0 with netCDF4 1.7.3 (HDF5 1.14.6 in both, other
    builds) and h5py 3.16.0 with netCDF4 1.7.5.1 work (2026-11-27, Linux x86-64).
    """
    return bool(_bundled_hdf5(first) & _bundled_hdf5(second))


def netcdf_versions() -> dict[str, str]:
    """The engine of :func:`netcdf_engine` and the versions of the libraries that write its
    files (for cache keys of output files: other libraries, other bytes)."""
    import importlib

    engine = netcdf_engine()
    out = {"engine": engine}
    if engine == "netcdf4":
        nc = importlib.import_module("netCDF4")
        out |= {"netCDF4": str(nc.__version__), "netcdf-c": str(nc.__netcdf4libversion__),
                "hdf5": str(nc.__hdf5libversion__)}
    else:
        import h5netcdf
        import h5py

        out |= {"h5netcdf": str(h5netcdf.__version__), "h5py": str(h5py.__version__),
                "hdf5": str(h5py.version.hdf5_version)}
    return out


def open_netcdf(path: str | os.PathLike, **kwargs):
    """``xarray.open_dataset(path, engine=netcdf_engine(), **kwargs)`` (through netCDF4 it
    reads NetCDF-3 files too). Hold :data:`NETCDF_LOCK` from this call until the dataset is
    closed.

    Returns
    -------
    xarray.Dataset
        Lazily loaded; close it (or use it as a context manager).
    """
    import xarray as xr

    return xr.open_dataset(path, engine=netcdf_engine(), **kwargs)


def to_netcdf(ds, path: str | os.PathLike, **kwargs) -> None:
    """``ds.to_netcdf(path, engine=netcdf_engine(), **kwargs)`` under :data:`NETCDF_LOCK`
    (``kwargs``: xarray's ``mode``, ``group``, ``encoding``...)."""
    with NETCDF_LOCK:
        ds.to_netcdf(path, engine=netcdf_engine(), **kwargs)


def set_netcdf_attrs(path: str | os.PathLike, attrs: Mapping[str, str]) -> None:
    """Set global (root group) text attributes of an existing NetCDF-4 file in place, through
    the library :func:`netcdf_engine` names, as xarray's ``to_netcdf`` sets them.

    For a file copied from the cache whose bytes are a function of its inputs but for a few
    attributes of the run that wrote it (its run times and output paths): the caller copies
    into a temporary path, sets them here, then renames it.

    Parameters
    ----------
    path : path-like
        An existing NetCDF-4 file, opened for appending.
    attrs : mapping of str to str
        Attribute name -> value; an existing attribute of that name is replaced.
    """
    with NETCDF_LOCK:
        if netcdf_engine() == "netcdf4":
            import netCDF4

            with netCDF4.Dataset(os.fspath(path), "a") as nc:
                for key, value in attrs.items():
                    nc.setncattr(key, value)
        else:
            import h5netcdf

            with h5netcdf.File(os.fspath(path), "a") as f:
                for key, value in attrs.items():
                    f.attrs[key] = value


def write_netcdf_atomic(ds, path: str | os.PathLike) -> None:
    """Write an xarray Dataset to NetCDF-4 (engine :func:`netcdf_engine`) atomically."""
    with atomic_path(path, suffix=".nc") as tmp:
        to_netcdf(ds, tmp)


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
    p = Path(path)
    if not p.exists():
        raise DataFileError(p, "no such file")
    if p.is_dir():
        raise DataFileError(p, "is a directory, not a NetCDF file")
    try:
        with NETCDF_LOCK, open_netcdf(p) as ds:
            ds = ds.load()
    except Exception as exc:  # netCDF4, h5py and h5netcdf raise many types for bad files
        raise DataFileError(p, f"is not a readable NetCDF-4 file ({type(exc).__name__}: {exc})"
                            ) from None
    missing = [v for v in required if v not in ds.variables]
    if missing:
        raise DataFileError(p, f"lacks the variable(s) {', '.join(missing)}")
    return ds


#: Attribute (MATLAB copy) and ``#`` header key (CSV copy) of the SHA-256 of the inputs of the
#: record a copy was written from (:func:`inputs_sha256`).
COPY_STAMP = "geardyn_inputs_sha256"


def inputs_sha256(inputs: object) -> str:
    """SHA-256 (hex) of a record's inputs (``geardyn_inputs``: a dict, or its JSON text) in a
    canonical JSON form (sorted keys), so that a CSV or MATLAB copy of the record can be told
    from a copy of another record with :func:`copy_inputs_sha256`."""
    import hashlib

    if isinstance(inputs, str):
        inputs = json.loads(inputs)
    text = json.dumps(inputs, sort_keys=True, separators=(",", ":"), default=str)
    return hashlib.sha256(text.encode("utf-8")).hexdigest()


def copy_inputs_sha256(path: str | os.PathLike) -> str | None:
    """The :data:`COPY_STAMP` of a CSV copy (a ``# geardyn_inputs_sha256 = ...`` line of its
    header) or a MATLAB copy (``attrs.geardyn_inputs_sha256``, else the SHA-256 of its
    ``attrs.geardyn_inputs``); None where the file has none or cannot be read (a file geardyn
    did not write, or wrote before the stamp)."""
    p = Path(path)
    try:
        if p.suffix.lower() == ".csv":
            with open(p, encoding="utf-8", errors="replace") as fh:
                for _ in range(200):
                    line = fh.readline()
                    if not line.startswith("#"):
                        return None
                    key, sep, value = line[1:].partition("=")
                    if sep and key.strip() == COPY_STAMP:
                        return value.strip()
            return None
        from scipy.io import loadmat

        attrs = loadmat(p, variable_names=["attrs"], squeeze_me=True,
                        struct_as_record=False).get("attrs")
        if attrs is None:
            return None
        stamp = getattr(attrs, COPY_STAMP, None)
        if isinstance(stamp, str) and stamp:
            return stamp
        inputs = getattr(attrs, "geardyn_inputs", None)
        return inputs_sha256(inputs) if isinstance(inputs, str) and inputs else None
    except (OSError, ValueError, TypeError, NotImplementedError):
        return None
