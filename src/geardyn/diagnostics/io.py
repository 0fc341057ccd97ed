"""Readers for measured data (CSV/text, NumPy .npy/.npz, MATLAB .mat) and simulation results.

All readers return float64 channels keyed by name, in file order, so that a channel can be
picked by name or by position. Problems with the file itself (missing, unreadable, truncated,
corrupt, unsupported format) raise :class:`geardyn.errors.DataFileError`; asking for a channel
the file does not have raises :class:`geardyn.errors.InputError` listing the channels it has.

Layout rules
------------
CSV / text (``.csv``, ``.txt``, ``.tsv``, ``.dat``)
    One channel per column. The delimiter is detected from the first data line (comma,
    semicolon, tab, else whitespace); lines starting with ``#`` are comments, and a comment
    ``# key = value`` (as ``geardyn measure --csv`` writes its provenance) is an entry of the
    file: a number (``fs`` also as ``51200 Hz``) goes to ``scalars``, anything else to
    ``text``. If the first line
    has a non-numeric field it is a header of column names, otherwise columns are named
    ``"0"``, ``"1"``, ... Empty fields are read as NaN (e.g. a shorter column of tachometer
    pulse times); a row with a different number of fields is a truncated/corrupt file.
``.npy``
    A 1-D array is channel ``"0"``; a 2-D array holds one channel per column along its longer
    axis (samples along the longer axis).
``.npz``
    Every 1-D array is a channel under its name; a 2-D array ``a`` gives channels ``a[0]``,
    ``a[1]``, ... (samples along the longer axis); scalars (e.g. ``fs``) go to ``scalars``.
``.mat``
    MATLAB v4-v7.2 via :func:`scipy.io.loadmat`, v7.3 (HDF5) via ``mat73`` (both read the
    MATLAB class of each variable). Numeric variables are channels as for ``.npz``; the numeric
    fields of a struct are channels named ``struct.field``; text (``char``), empty arrays,
    cells and objects are never channels.
"""

from __future__ import annotations

import contextlib
import io
import logging
import os
import re
import warnings
import zipfile
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from geardyn.errors import DataFileError, InputError

from ..units import parse_frequency

__all__ = ["DataTable", "read_table", "read_simulation", "TEXT_SUFFIXES", "NETCDF_SUFFIXES"]

TEXT_SUFFIXES = (".csv", ".txt", ".tsv", ".dat")
NETCDF_SUFFIXES = (".nc", ".nc4", ".netcdf", ".h5", ".hdf5")


@dataclass(frozen=True)
class DataTable:
    """Channels read from one file.

    Attributes
    ----------
    path : str
        The file.
    columns : dict of str to ndarray
        Channel name -> 1-D float64 array (file unit), in file order.
    scalars : dict of str to float
        Scalar numeric entries of ``.npz``/``.mat``/NetCDF files and the ``# key = value``
        comments of text files (e.g. a stored ``fs`` [Hz]).
    text : dict of str to str
        Text entries of ``.mat`` files (``char`` variables and struct fields, dotted like the
        channels), NetCDF files (global attributes) and text files (``# key = value``
        comments), e.g. the ``case_toml`` a record of ``geardyn measure`` carries.
    units : dict of str to str
        Unit of a channel where the file states it (a NetCDF variable's ``units``); a column
        named with its unit (``"acc [g]"``) is read by :func:`unit_in_name`.
    """

    path: str
    columns: dict[str, np.ndarray]
    scalars: dict[str, float] = field(default_factory=dict)
    text: dict[str, str] = field(default_factory=dict)
    units: dict[str, str] = field(default_factory=dict)

    @property
    def names(self) -> list[str]:
        """Channel names in file order."""
        return list(self.columns)

    def get(self, spec: str | int, field_name: str = "column") -> np.ndarray:
        """Channel by name or position.

        Parameters
        ----------
        spec : str or int
            Column name, or 0-based position (a string of digits that is not a name is taken
            as a position).
        field_name : str
            Argument name used in the error message.

        Raises
        ------
        InputError
            No such channel (the message lists the available ones).
        """
        names = self.names
        if isinstance(spec, str) and spec in self.columns:
            return self.columns[spec]
        idx = None
        if isinstance(spec, (int, np.integer)) and not isinstance(spec, bool):
            idx = int(spec)
        elif isinstance(spec, str) and spec.strip().lstrip("-").isdigit():
            idx = int(spec)
        if idx is not None and -len(names) <= idx < len(names):
            return self.columns[names[idx]]
        shown = ", ".join(repr(n) for n in names[:20]) + (" ..." if len(names) > 20 else "")
        raise InputError(field_name, spec,
                         f"a column of {Path(self.path).name}: one of {shown} "
                         f"or a position 0..{len(names) - 1}")


def _check_path(path) -> Path:
    p = Path(path)
    if not p.exists():
        raise DataFileError(p, "no such file")
    if p.is_dir():
        raise DataFileError(p, "is a directory, not a data file")
    if not os.access(p, os.R_OK):
        raise DataFileError(p, "not readable (permission denied)")
    if p.stat().st_size == 0:
        raise DataFileError(p, "empty file")
    return p


def read_table(path) -> DataTable:
    """Read a measured-data file into named float64 channels (see the module docstring).

    Parameters
    ----------
    path : str or path-like
        ``.csv``/``.txt``/``.tsv``/``.dat``, ``.npy``, ``.npz`` or ``.mat``.

    Returns
    -------
    DataTable

    Raises
    ------
    DataFileError
        Missing, empty, unreadable, truncated or corrupt file; unsupported format.
    """
    p = _check_path(path)
    suffix = p.suffix.lower()
    if suffix in TEXT_SUFFIXES:
        return _read_text(p)
    if suffix == ".npy":
        return _read_npy(p)
    if suffix == ".npz":
        return _read_npz(p)
    if suffix == ".mat":
        return _read_mat(p)
    if suffix in NETCDF_SUFFIXES:
        return _read_netcdf_table(p)
    raise DataFileError(p, f"unsupported format {suffix!r}; use .csv/.txt/.tsv/.dat, .npy, "
                           ".npz, .mat (measured data) or .nc (geardyn simulation result)")


# --------------------------------------------------------------------------------------------
def _read_text(p: Path) -> DataTable:
    try:
        with open(p, encoding="utf-8-sig") as fh:
            lines = fh.read().splitlines()
    except UnicodeDecodeError as exc:
        raise DataFileError(p, f"not a text file ({exc.reason} at byte {exc.start})") from exc
    except OSError as exc:  # pragma: no cover - races
        raise DataFileError(p, f"cannot read: {exc}") from exc
    body = [(i + 1, ln) for i, ln in enumerate(lines)
            if ln.strip() and not ln.lstrip().startswith("#")]
    if not body:
        raise DataFileError(p, "no data lines")
    first = body[0][1]
    # ';' first: a European spreadsheet writes ';' between fields and ',' in numbers
    delim = ";" if ";" in first else "," if "," in first else "\t" if "\t" in first else None

    def fields(line: str) -> list[str]:
        return [t.strip() for t in (line.split(delim) if delim else line.split())]

    head = fields(first)
    header = None
    try:  # (with ';' between fields a first row of numbers may have decimal commas)
        [float(t.replace(",", ".") if delim == ";" else t) for t in head]
    except ValueError:  # the column names, as written (a comma in a name stays)
        header = [h.strip('"').strip("'") or str(i) for i, h in enumerate(head)]
        body = body[1:]
    if not body:
        raise DataFileError(p, "a header but no data rows")
    # a comma in any data line of a ';'-separated file is a decimal comma (a recorder's
    # pre-trigger rows may be whole numbers: not only the first rows tell)
    decimal_comma = delim == ";" and any("," in ln for _, ln in body)

    def split(line: str) -> list[str]:
        toks = fields(line)
        return [t.replace(",", ".") for t in toks] if decimal_comma else toks

    ncol = len(head)
    data = None
    # fast path (C parser); the line loop below gives precise messages and NaN fields
    with contextlib.suppress(ValueError):
        if decimal_comma:  # the C parser on the text with decimal points
            fast = np.loadtxt(io.StringIO("\n".join(ln.replace(",", ".") for _, ln in body)),
                              delimiter=delim, comments="#", ndmin=2, dtype=np.float64)
        else:
            fast = np.loadtxt(p, delimiter=delim, comments="#", ndmin=2, encoding="utf-8-sig",
                              skiprows=body[0][0] - 1, dtype=np.float64)
        if fast.shape == (len(body), ncol):
            data = fast
    if data is None:
        data = _parse_lines(p, body, ncol, split)
    names = header or [str(i) for i in range(ncol)]
    if len(set(names)) != len(names):
        raise DataFileError(p, f"duplicate column names in the header: {names}")
    scalars, text = _comment_entries(lines)
    return DataTable(str(p), {n: data[:, j].copy() for j, n in enumerate(names)}, scalars, text,
                     _units_comment(lines, names))


#: A ``# key = value`` comment line of a text file.
_COMMENT_ENTRY = re.compile(r"^\s*#\s*([A-Za-z_][A-Za-z0-9_]*)\s*=\s*(.*?)\s*$")


def _comment_entries(lines: list[str]) -> tuple[dict[str, float], dict[str, str]]:
    """The ``# key = value`` comments of a text file: numbers (``fs`` in Hz, with or without
    the unit) as scalars, the rest as text; a key given twice keeps its first value."""
    scalars: dict[str, float] = {}
    text: dict[str, str] = {}
    for line in lines:
        m = _COMMENT_ENTRY.match(line)
        if m is None or m.group(1) in scalars or m.group(1) in text:
            continue
        key, value = m.group(1), m.group(2)
        try:
            scalars[key] = float(value)
        except ValueError:
            if is_rate_key(key):  # "# fs = 20 kHz", "# sample_rate = 51200 Hz"
                with contextlib.suppress(ValueError):  # not a frequency: kept as text
                    scalars[key] = parse_frequency(value, key)
                    continue
            text[key] = value
    return scalars, text



#: Names a file may give its sample rate [Hz], compared without case and underscores (``fs``,
#: ``Fs``, ``FS``, ``sampleRate``, ``sample_rate``, ``SamplingRate``...; a struct field's last
#: part, ``data.sampleRate``, counts too).
RATE_KEYS = ("fs", "samplerate", "samplingrate", "samplingfrequency", "samplefrequency",
             "srate", "fsample", "fsamp")


def is_rate_key(key: str) -> bool:
    """Whether ``key`` names a sample rate (:data:`RATE_KEYS`)."""
    return str(key).rsplit(".", 1)[-1].replace("_", "").lower() in RATE_KEYS


def stored_rate(scalars: dict) -> tuple[str, float] | None:
    """The sample rate a file stores: ``(its name, value)``, ``fs`` first, else the first entry
    whose name is a sample rate's (:data:`RATE_KEYS`); None if there is none."""
    if "fs" in scalars:
        return "fs", scalars["fs"]
    for key, value in scalars.items():
        if is_rate_key(key):
            return key, value
    return None


_UNIT_IN_NAME = re.compile(r"[\[(]\s*([^\[\]()]{1,20}?)\s*[\])]\s*$")


def unit_in_name(name: str) -> str:
    """The unit a column name ends with, in brackets or parentheses (``"acc [g]"`` -> ``"g"``,
    ``"force (N)"`` -> ``"N"``), else ``""``."""
    m = _UNIT_IN_NAME.search(str(name))
    # "data[0]" names column 0 of a matrix: an index, not a unit
    return m.group(1) if m and not m.group(1).strip().isdigit() else ""


_UNITS_COMMENT = re.compile(r"^\s*#\s*units\s*:\s*(.*)$", re.I)


def _units_comment(lines: list[str], names: list[str]) -> dict[str, str]:
    """Units of the columns from a ``# units: time [s], acc [m/s^2], ...`` comment line (as
    ``geardyn measure --csv`` writes it): column name -> unit."""
    for line in lines:
        m = _UNITS_COMMENT.match(line)
        if m is None:
            continue
        out = {}
        for item in m.group(1).split(","):
            item = item.strip()
            unit = unit_in_name(item)
            cut = max(item.rfind("["), item.rfind("("))  # "acc [g]" or "force (N)"
            name = item[:cut].strip() if cut > 0 else ""
            if unit and name in names:
                out[name] = unit
        return out
    return {}

def _parse_lines(p: Path, body, ncol: int, split) -> np.ndarray:
    data = np.empty((len(body), ncol), dtype=np.float64)
    for r, (lineno, line) in enumerate(body):
        toks = split(line)
        if len(toks) != ncol:
            what = ("lines before the column names (an acquisition system's preamble) must "
                    "start with '#'" if r == 0 else "truncated or corrupt file?")
            raise DataFileError(p, f"line {lineno} has {len(toks)} fields, expected {ncol} "
                                   f"({what})")
        try:
            data[r] = [float(t) if t else np.nan for t in toks]
        except ValueError as exc:
            hint = ("; lines before the column names (an acquisition system's preamble) must "
                    "start with '#'" if r == 0 else "")
            raise DataFileError(p, f"line {lineno}: non-numeric value ({exc}){hint}") from exc
    return data


def _split_2d(name: str, arr: np.ndarray, out: dict, scalars: dict) -> None:
    arr = np.asarray(arr)
    if arr.dtype.kind not in "biuf":
        return  # strings, structs, cells: not channels
    arr = np.squeeze(arr).astype(np.float64)
    if arr.ndim == 0:
        scalars[name] = float(arr)
    elif arr.ndim == 1:
        out[name] = arr
    elif arr.ndim == 2:
        if arr.shape[0] < arr.shape[1]:
            arr = arr.T
        for j in range(arr.shape[1]):
            out[f"{name}[{j}]"] = np.ascontiguousarray(arr[:, j])
    # higher dimensions are not channels: ignored


def _read_npy(p: Path) -> DataTable:
    try:
        arr = np.load(p, allow_pickle=False)
    except (ValueError, OSError, EOFError) as exc:
        raise DataFileError(p, f"not a readable .npy file ({exc})") from exc
    if arr.dtype.kind not in "biuf":
        raise DataFileError(p, f"holds {arr.dtype} data, not numbers")
    arr = np.squeeze(arr).astype(np.float64)
    if arr.ndim == 1:
        return DataTable(str(p), {"0": arr})
    if arr.ndim != 2:
        raise DataFileError(p, f"array of shape {arr.shape}; expected 1-D or 2-D")
    if arr.shape[0] < arr.shape[1]:
        arr = arr.T
    return DataTable(str(p), {str(j): np.ascontiguousarray(arr[:, j])
                              for j in range(arr.shape[1])})


def _read_npz(p: Path) -> DataTable:
    cols: dict[str, np.ndarray] = {}
    scalars: dict[str, float] = {}
    try:
        with np.load(p, allow_pickle=False) as z:
            for name in z.files:
                _split_2d(name, z[name], cols, scalars)
    except (ValueError, OSError, EOFError, zipfile.BadZipFile, KeyError) as exc:
        raise DataFileError(p, f"not a readable .npz file ({exc})") from exc
    if not cols:
        raise DataFileError(p, "no numeric 1-D or 2-D arrays")
    return DataTable(str(p), cols, scalars)


def _read_mat(p: Path) -> DataTable:
    """MATLAB file: v4-v7.2 through :func:`scipy.io.loadmat`, v7.3 (HDF5) through ``mat73``.

    Both readers honour the MATLAB class of each variable: ``char`` variables come back as
    text and empty arrays as empty (or None), and neither is taken as a channel; structs come
    back as dicts whose numeric fields are channels named ``struct.field`` (nested:
    ``a.b.c``); cell arrays, tables and objects are not channels. Warnings the readers emit
    while failing are dropped (the error says what is wrong); on success they are passed on.
    """
    import scipy.io
    from scipy.io.matlab import matfile_version

    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        try:
            with open(p, "rb") as fh:
                major, _minor = matfile_version(fh)
        except Exception as exc:  # scipy raises ValueError / MatReadError on a bad header
            raise DataFileError(p, f"not a readable MATLAB file ({type(exc).__name__}: {exc})") from exc
        if major == 2:
            content = _load_mat73(p)
        else:
            try:
                content = scipy.io.loadmat(p, simplify_cells=True)
            except Exception as exc:  # ValueError, MatReadError, OSError, TypeError...
                raise DataFileError(p, f"not a readable MATLAB file ({type(exc).__name__}: "
                                       f"{exc})") from exc
    cols: dict[str, np.ndarray] = {}
    scalars: dict[str, float] = {}
    text: dict[str, str] = {}
    for name, value in content.items():
        if not name.startswith("__"):
            _mat_variable(name, value, cols, scalars, text)
    if not cols:
        why = f"; the reader said: {str(caught[0].message)[:200]}" if caught else ""
        raise DataFileError(p, "no numeric vector or matrix variables (text, empty arrays, "
                               f"cells and objects are not signals){why}")
    for w in caught:
        warnings.warn_explicit(w.message, w.category, w.filename, w.lineno)
    return DataTable(str(p), cols, scalars, text)


def _load_mat73(p: Path) -> dict:
    try:
        import mat73
    except ImportError as exc:  # pragma: no cover - mat73 is a declared dependency
        raise DataFileError(p, "MATLAB v7.3 (HDF5) file: reading it needs mat73 "
                               "(pip install mat73), or save it with -v7") from exc
    # mat73 reports skipped variables (no MATLAB class, unsupported types) through the root
    # logger, which would print them on stderr: collect them and pass them on as warnings
    notes: list[str] = []

    def _collect(record) -> bool:
        if record.pathname.replace("\\", "/").split("/")[-2:-1] == ["mat73"]:
            notes.append(record.getMessage())
            return False
        return True

    root = logging.getLogger()
    root.addFilter(_collect)
    try:
        content = mat73.loadmat(str(p))
    except Exception as exc:  # h5py OSError, mat73 TypeError/ValueError on odd content
        raise DataFileError(p, f"not a readable MATLAB v7.3/HDF5 file ({type(exc).__name__}: "
                               f"{exc})") from exc
    finally:
        root.removeFilter(_collect)
    for note in notes:
        warnings.warn(f"{p.name}: MATLAB v7.3 reader skipped a variable: {note}", UserWarning,
                      stacklevel=4)
    return content


def _mat_variable(name: str, value, cols: dict, scalars: dict, text: dict | None = None) -> None:
    """Add a MATLAB variable: numeric arrays as channels/scalars, struct fields recursively,
    text (``char``) to ``text``."""
    if isinstance(value, dict):  # struct (scipy simplify_cells, mat73): fields as a.b
        for key, field_value in value.items():
            _mat_variable(f"{name}.{key}", field_value, cols, scalars, text)
        return
    if isinstance(value, str) and text is not None:
        text[name] = value  # char: not a signal, but e.g. a record's case_toml
        return
    if value is None or isinstance(value, (str, bytes, list, tuple)):
        return  # empty (mat73), char, cell array: not signals
    arr = np.asarray(value)
    if arr.dtype.kind not in "biuf" or arr.size == 0:
        return  # text, cells, objects, complex, empty arrays: not signals
    _split_2d(name, arr, cols, scalars)


def _read_netcdf_table(p: Path) -> DataTable:
    """A NetCDF file as measured data: every 1-D numeric variable (coordinates included, e.g.
    ``time``) is a channel; numeric global attributes (e.g. ``fs``) are scalars, text ones
    (e.g. ``case_toml``) text."""
    from ..io import NETCDF_LOCK

    with NETCDF_LOCK:  # from the file's opening to its closing
        return _netcdf_table(p)


def _netcdf_table(p: Path) -> DataTable:
    """:func:`_read_netcdf_table`'s reading, with :data:`geardyn.io.NETCDF_LOCK` held."""
    try:
        from ..io import open_netcdf

        ds = open_netcdf(p)
    except Exception as exc:  # netCDF4, h5netcdf and h5py raise OSError, ValueError, KeyError...
        raise DataFileError(p, f"not a readable NetCDF4/HDF5 file ({type(exc).__name__}: "
                               f"{exc})") from exc
    cols: dict[str, np.ndarray] = {}
    scalars: dict[str, float] = {}
    text: dict[str, str] = {}
    units: dict[str, str] = {}
    try:
        for name, var in {**dict(ds.coords), **dict(ds.data_vars)}.items():
            if var.ndim == 1 and var.dtype.kind in "biuf":
                cols[str(name)] = np.asarray(var.values, dtype=np.float64)
                if isinstance(var.attrs.get("units"), str) and var.attrs["units"].strip():
                    units[str(name)] = var.attrs["units"].strip()
        for k, v in ds.attrs.items():
            if isinstance(v, int | float | np.integer | np.floating) and not isinstance(v, bool):
                scalars[str(k)] = float(v)
            elif isinstance(v, str):
                text[str(k)] = v
    finally:
        ds.close()
    if not cols:
        raise DataFileError(p, "no numeric 1-D variables")
    return DataTable(str(p), cols, scalars, text, units)


# --------------------------------------------------------------------------------------------
def read_simulation(path, variables, *,
                    field_name: str = "signals") -> tuple[np.ndarray, dict[str, np.ndarray], dict]:
    """Read a geardyn simulation result (NetCDF-4/HDF5 written by xarray,
    :func:`geardyn.io.netcdf_engine`).

    Parameters
    ----------
    path : str or path-like
        The ``.nc`` file.
    variables : sequence of str
        Data variables to read (e.g. ``theta_p`` [rad], ``v_yg`` [m/s], ``omega_p`` [rad/s],
        ``transmission_error`` [rad]).
    field_name : str
        Argument name used in the message about an absent variable.

    Returns
    -------
    time : ndarray
        The ``time`` coordinate [s].
    data : dict of str to ndarray
        The requested variables as float64 (SI units as stored).
    attrs : dict
        Global attributes (e.g. ``pinion_teeth``, ``gear_teeth``) and per-variable units under
        ``"units"``.

    Raises
    ------
    DataFileError
        Missing/corrupt file, or no ``time`` coordinate.
    InputError
        A requested variable is absent (the message lists the data variables present).
    """
    from ..io import NETCDF_LOCK

    p = _check_path(path)
    with NETCDF_LOCK:  # from the file's opening to its closing
        time, data, attrs = _simulation(p, variables, field_name)
    for v, arr in data.items():
        if arr.shape != time.shape:
            raise DataFileError(p, f"variable {v!r} has shape {arr.shape}, not the time "
                                   f"axis {time.shape}")
    return time, data, attrs


def _simulation(p: Path, variables, field_name: str):
    """:func:`read_simulation`'s reading (time, data, attrs), with
    :data:`geardyn.io.NETCDF_LOCK` held."""
    try:
        from ..io import open_netcdf

        ds = open_netcdf(p)
    except ImportError as exc:
        raise DataFileError(p, f"reading NetCDF needs xarray and netCDF4 or h5netcdf ({exc})"
                            ) from exc
    except Exception as exc:  # netCDF4, h5netcdf and h5py raise OSError, ValueError, KeyError...
        raise DataFileError(p, f"not a readable NetCDF4/HDF5 file ({type(exc).__name__}: "
                               f"{exc})") from exc
    try:
        if "time" not in ds.coords and "time" not in ds.variables:
            if "run_files" in ds.attrs:  # the results.nc of `geardyn run`: records are beside it
                runs = p.parent / "runs"
                raise DataFileError(p, "holds the study's tables, maps and diagnostics, not a "
                                       "simulated record; the records are one file per run: "
                                       f"diagnose {runs / 'model_II_cracked.nc'} (or another "
                                       f"file in {runs})")
            raise DataFileError(p, "no 'time' coordinate: not a geardyn simulation result")
        missing = [v for v in variables if v not in ds.data_vars]
        if missing:
            have = ", ".join(sorted(map(str, ds.data_vars)))
            raise InputError(field_name, missing[0] if len(missing) == 1 else missing,
                             f"data variables of {p.name}: {have}")
        try:
            time = np.asarray(ds["time"].values, dtype=np.float64)
            data = {v: np.asarray(ds[v].values, dtype=np.float64).reshape(-1)
                    for v in variables}
        except (OSError, ValueError, TypeError) as exc:
            raise DataFileError(p, f"cannot read the data ({exc}); truncated file?") from exc
        attrs = dict(ds.attrs)
        attrs["units"] = {v: str(ds[v].attrs.get("units", "")) for v in variables}
    finally:
        ds.close()
    return time, data, attrs
