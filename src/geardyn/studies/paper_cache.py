"""What ``geardyn run`` keeps in the on-disk cache besides maps, records and figures (issue 16).

A run of the same inputs into a new output folder (a "warm" run) used to spend most of its
time re-deriving what an earlier run had already derived from the same cached maps and
records: the diagnoses (mostly the PWVDs, about 0.55 s per record) and the compressed NetCDF
output files (about 0.26 s per simulation record, 0.4 s per stiffness map). Both are pure
functions of their inputs, so they are cached like the figures
(:meth:`~.paper_result.FigureStore.cached`):

* :func:`cached_diagnosis`: a :func:`geardyn.diagnostics.diagnose` result (kind
  ``diagnosis``), keyed by a fingerprint of its inputs (the signals, the shaft angle, the
  times, every setting), geardyn's sources and the NumPy/SciPy versions; stored without the
  PWVD distributions (which the run drops after drawing its figures anyway) as a NumPy ``.npz``
  archive of the arrays plus a JSON description of the result's dataclasses, read back with
  ``allow_pickle=False``: the loaded result equals the computed one bit for bit, type for type.
* :func:`write_output`: an output file (kind ``output``) keyed by a fingerprint of the data it
  encodes, the writer's settings, geardyn's sources, the versions of NumPy and xarray and the
  NetCDF engine with its libraries (:func:`geardyn.io.netcdf_versions`); a warm run copies the
  bytes (:meth:`geardyn.cache.Cache.write_file`).

The entries are ordinary cache entries (checksum and key in a sidecar, checked before use;
written to a temporary file and renamed; rebuilt when damaged) and honour ``GEARDYN_NO_CACHE``.
"""

from __future__ import annotations

import dataclasses
import hashlib
import importlib
import json
from collections.abc import Callable
from pathlib import Path

import numpy as np

from ..io import netcdf_versions
from .paper_result import _digest, _source_digest

__all__ = ["fingerprint", "cached_diagnosis", "write_output", "without_distributions",
           "save_dataset", "load_dataset",
           "DIAGNOSIS_CACHE_VERSION", "OUTPUT_CACHE_VERSION"]

#: Bump when a cached diagnosis changes meaning or layout, so cached ones are recomputed.
DIAGNOSIS_CACHE_VERSION = "1"
#: Bump when a cached output file changes meaning, so cached ones are written again.
OUTPUT_CACHE_VERSION = "1"


def fingerprint(*parts) -> str:
    """SHA-256 (hex) of a canonical fingerprint of ``parts`` (arrays by dtype, shape and bytes;
    datasets by variables and attributes; see :func:`~.paper_result._digest`)."""
    h = hashlib.sha256()
    _digest(parts, h)
    return h.hexdigest()


def _versions(*modules: str) -> dict[str, str]:
    """The installed versions of the distributions ``modules`` (for cache keys), read from
    their metadata: importing xarray for its ``__version__`` took 0.5 s of the FE bodies'
    second process before it could draw the mesh figure (2026-11-28). A module without
    distribution metadata answers its ``__version__``."""
    from importlib.metadata import PackageNotFoundError, version

    out = {}
    for name in modules:
        try:
            out[name] = version(name)
        except PackageNotFoundError:
            out[name] = str(getattr(importlib.import_module(name), "__version__", "?"))
    return out


# --------------------------------------------------------------------------------------------
# diagnoses
# --------------------------------------------------------------------------------------------
def without_distributions(diag):
    """``diag`` (a :class:`~geardyn.diagnostics.pipeline.DiagnosisResult`) with each signal's
    PWVD distributions emptied to shape (0, 0) (angles, orders and settings kept)."""
    def empty(p):
        return dataclasses.replace(p, distribution=np.zeros((0, 0)))

    return dataclasses.replace(diag, signals={
        name: dataclasses.replace(sd, pwvd_tsa=empty(sd.pwvd_tsa),
                                  pwvd_residual=empty(sd.pwvd_residual))
        for name, sd in diag.signals.items()})


def diagnosis_key(inputs: dict) -> str:
    """Cache key of ``diagnose(**inputs)`` (see the module docstring)."""
    return fingerprint("diagnosis", DIAGNOSIS_CACHE_VERSION, inputs, _source_digest(),
                       _versions("numpy", "scipy"))[:32]


def cached_diagnosis(inputs: dict, key: str | None = None, cache=None):
    """``diagnose(**inputs)`` through the cache, without its PWVD distributions.

    Parameters
    ----------
    inputs : dict
        Keyword arguments of :func:`geardyn.diagnostics.diagnose`.
    key : str, optional
        :func:`diagnosis_key` of ``inputs`` (computed if not given).
    cache : Cache, optional
        Default :func:`geardyn.cache.default_cache`.

    Returns
    -------
    (DiagnosisResult, DiagnosisResult or None)
        The result without distributions, and the same result when it was computed here (None
        when it came from the cache). The distributions are not computed at all
        (``diagnose(..., pwvd_distributions=False)``, equal to dropping them afterwards; the
        figures compute the two they draw).
    """
    from ..cache import default_cache
    from ..diagnostics import diagnose

    cache = cache or default_cache()
    key = key or diagnosis_key(inputs)
    diag, hit = cache.get_or_build(
        "diagnosis", key, ".npz", lambda: diagnose(**inputs, pwvd_distributions=False),
        save_tree, load_tree)
    return diag, (None if hit else diag)


#: Modules whose dataclasses a stored tree may name (:func:`load_tree` refuses others).
_TREE_MODULES = ("geardyn.diagnostics.",)


def _encode(obj, arrays: dict):
    """JSON description of ``obj``; arrays and NumPy scalars go to ``arrays`` (by name)."""
    if obj is None or type(obj) in (bool, int, str):
        return obj
    if type(obj) is float:
        return {"float": obj.hex()}
    if isinstance(obj, (np.ndarray, np.generic)):
        a = np.asarray(obj)
        if a.dtype.hasobject:
            raise TypeError(f"cannot store an object array ({a.dtype})")
        name = f"a{len(arrays)}"
        arrays[name] = a
        return {"array": name, "scalar": isinstance(obj, np.generic)}
    if dataclasses.is_dataclass(obj) and not isinstance(obj, type):
        cls = type(obj)
        return {"dataclass": f"{cls.__module__}:{cls.__qualname__}",
                "fields": {f.name: _encode(getattr(obj, f.name), arrays)
                           for f in dataclasses.fields(obj)}}
    if type(obj) is dict:
        return {"dict": [[_encode(k, arrays), _encode(v, arrays)] for k, v in obj.items()]}
    if type(obj) in (list, tuple):
        return {type(obj).__name__: [_encode(v, arrays) for v in obj]}
    raise TypeError(f"cannot store a {type(obj).__name__}")


def _decode(node, arrays):
    if node is None or type(node) in (bool, int, str):
        return node
    if "float" in node:
        return float.fromhex(node["float"])
    if "array" in node:
        a = arrays[node["array"]]
        return a[()] if node["scalar"] else a
    if "dataclass" in node:
        module, _, qualname = node["dataclass"].partition(":")
        if not module.startswith(_TREE_MODULES):
            raise ValueError(f"a stored tree names the class {node['dataclass']!r}")
        cls = getattr(importlib.import_module(module), qualname)
        if not (dataclasses.is_dataclass(cls) and isinstance(cls, type)):
            raise ValueError(f"{node['dataclass']!r} is not a dataclass")
        names = {f.name for f in dataclasses.fields(cls)}
        if set(node["fields"]) != names:
            raise ValueError(f"stored fields of {qualname} differ from its fields")
        obj = object.__new__(cls)  # the stored state as it was, without re-running __init__
        for name, value in node["fields"].items():
            object.__setattr__(obj, name, _decode(value, arrays))
        return obj
    if "dict" in node:
        return {_decode(k, arrays): _decode(v, arrays) for k, v in node["dict"]}
    if "list" in node:
        return [_decode(v, arrays) for v in node["list"]]
    if "tuple" in node:
        return tuple(_decode(v, arrays) for v in node["tuple"])
    raise ValueError(f"unknown stored node {sorted(node)}")


def save_tree(obj, path: Path) -> None:
    """Write a tree of dataclasses, containers, scalars and arrays to ``path`` (``.npz``: the
    arrays, and ``__tree__``, the JSON description)."""
    arrays: dict = {}
    tree = json.dumps(_encode(obj, arrays), separators=(",", ":"))
    with open(path, "wb") as fh:
        np.savez(fh, __tree__=np.frombuffer(tree.encode("utf-8"), dtype=np.uint8), **arrays)


def load_tree(path: Path):
    """Read what :func:`save_tree` wrote (no pickles: ``allow_pickle=False``)."""
    with np.load(path, allow_pickle=False) as z:
        arrays = {name: z[name] for name in z.files}
    tree = json.loads(arrays.pop("__tree__").tobytes().decode("utf-8"))
    return _decode(tree, arrays)


def save_dataset(ds, path: Path) -> None:
    """An xarray Dataset of plain variables (numeric arrays with their dims and attrs, as a
    simulation record is) to ``.npz`` through :func:`save_tree`: every array and the type of
    every attribute as they were (a NetCDF round trip turns Python ints and floats into NumPy
    scalars), in the variables' order, without compression. The simulation cache uses it: a
    compressed NetCDF-4 write cost 0.13-0.28 s per record (h5netcdf creates each variable with
    its filters and dimension scales), the ``.npz`` about 0.02 s (issue 16)."""
    tree = {"attrs": dict(ds.attrs), "coords": list(ds.coords),
            "variables": {name: {"dims": list(v.dims), "data": np.asarray(v.values),
                                 "attrs": dict(v.attrs)}
                          for name, v in ds.variables.items()}}
    save_tree(tree, path)


def load_dataset(path: Path, required: tuple[str, ...] = ()):
    """Read what :func:`save_dataset` wrote; ``required`` variables must be there
    (:class:`geardyn.errors.DataFileError` otherwise, which the cache treats as a damaged entry
    and rebuilds)."""
    import xarray as xr

    from ..errors import DataFileError

    tree = load_tree(path)
    if not isinstance(tree, dict) or set(tree) != {"attrs", "coords", "variables"}:
        raise DataFileError(path, "is not a stored dataset")
    variables = {name: xr.Variable(tuple(v["dims"]), v["data"], v["attrs"])
                 for name, v in tree["variables"].items()}
    ds = xr.Dataset(variables, attrs=tree["attrs"]).set_coords(
        [c for c in tree["coords"] if c in variables])
    missing = [v for v in required if v not in ds.variables]
    if missing:
        raise DataFileError(path, f"lacks the variable(s) {', '.join(missing)}")
    return ds


# --------------------------------------------------------------------------------------------
# output files
# --------------------------------------------------------------------------------------------
def write_output(target: Path, what: str, data, settings, write: Callable[[Path], None],
                 cache=None) -> bool:
    """Write the output file ``target`` through the cache (kind ``output``).

    Parameters
    ----------
    target : Path
        The file to write.
    what : str
        What the file is (``"run"``, ``"stiffness map"``), part of the key.
    data : object
        What the file encodes (a Dataset, a map): fingerprinted into the key.
    settings : object
        How it is encoded (compression, float32 variables...): part of the key.
    write : callable
        ``write(path)`` writes the file (used on a miss, and without the cache).
    cache : Cache, optional
        Default :func:`geardyn.cache.default_cache`.

    Returns
    -------
    bool
        Whether the bytes came from the cache.
    """
    from ..cache import default_cache

    cache = cache or default_cache()
    if not cache.enabled:  # no fingerprint to compute
        return cache.write_file("output", "", target, write)
    key = fingerprint("output", OUTPUT_CACHE_VERSION, what, data, settings, _source_digest(),
                      _versions("numpy", "xarray") | netcdf_versions())
    return cache.write_file("output", key[:32], target, write)
