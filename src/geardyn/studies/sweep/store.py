"""The sweep's Zarr store: template, chunk writes, status, reading.

Layout: Zarr format 2 with consolidated metadata (readable by every Zarr implementation; strings
as fixed-width ``<U``, which the v2 specification defines, where Zarr 3 still marks every string
type unstable). One dimension ``run``; every variable is chunked along it in batches of
``batch_size`` runs, so one Dask task writes exactly one chunk of each variable.

Crash safety: zarr-python's ``LocalStore`` (since 3.1.3, zarr-python PR #3412; zarr 2's
``DirectoryStore`` did the same) writes each chunk to ``<key>.<uuid>.partial`` and renames it
over the key (``tests/sweep/test_store.py`` checks this on the installed version), so a chunk is
either the old one or the new one. A task writes its data chunks first, then the batch's
checksum (:mod:`.integrity`), and the status chunk last: a batch killed in between is still
pending and is redone with the same values; a finished batch whose chunks were later deleted,
garbled or swapped fails its checksum on resume and is redone too. Only zarr's public API is
used (``zarr.open_group`` and array slicing; a batch's chunks through
``zarr.api.asynchronous``, all at once). Stale
``*.partial`` files are removed when a sweep resumes. With a store that does not write
atomically the design degrades gracefully: a torn data chunk belongs to a batch whose status was
never written (so it is redone), and a torn (undecodable) status chunk counts as pending. Writes
are not fsynced: a power cut (not a killed process) may lose recent chunks of the page cache.
"""

from __future__ import annotations

import contextlib
import json
import math
import os
import shutil
import threading
import time
import uuid
import warnings
from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

from ...config import Case
from ...errors import DataFileError, GeardynError, InputError
from ...io import remove_stale_temp_files, temp_prefix
from .evaluate import Evaluator, Output
from .integrity import (
    CHECKSUM_CHARS,
    CHECKSUM_VAR,
    _consolidated_ok,
    batch_digest,
    check_metadata,
    open_store_group,
    plan_digest,
    verify_store,
)
from .spec import STORE_FORMAT, Sweep, SweepPlan

__all__ = ["STATUS_PENDING", "STATUS_OK", "STATUS_FAILED", "ERROR_CHARS", "open_sweep",
           "store_status"]

#: Status codes of the ``status`` variable.
STATUS_PENDING, STATUS_OK, STATUS_FAILED = 0, 1, 2
STATUS_MEANINGS = "pending ok failed"
#: Longest error message kept per run [characters]; longer ones are cut with an ellipsis.
ERROR_CHARS = 400

# ============================================================================================
# the Zarr store
# ============================================================================================
ZARR_FORMAT = 2
_CORE_VARS = ("status", "error", "warning", "worker", "run_seconds")


def _is_store(path: Path) -> bool:
    return (path / ".zgroup").is_file() or (path / "zarr.json").is_file()


def _read_attrs(path: Path) -> dict:
    try:
        g = open_store_group(path, "r")
        return dict(g.attrs)
    except Exception as exc:  # corrupt metadata of any kind
        raise DataFileError(path, f"is not a readable Zarr store ({type(exc).__name__}: {exc})"
                            ) from None


def _template(sweep: Sweep, plan: SweepPlan, digest: str, evaluator: Evaluator, outputs,
              coords: dict, batch: int):
    """The store's dataset: coordinates and status eager, results lazy (dask, not written)."""
    import dask.array as da
    import xarray as xr

    from ..._version import __version__

    n = plan.n_runs
    ds = xr.Dataset(coords={"run": ("run", np.arange(n, dtype=np.int64),
                                    {"long_name": "run number"})})
    for p in plan.parameters:
        attrs = {"long_name": p.long_name, "sweep_role": p.role}
        if p.units:
            attrs["units"] = p.units
        if p.role == "link":
            attrs["linked_to"] = p.source
        ds.coords[p.key] = ("run", plan.values[p.key], attrs)
    ds.coords["seed"] = ("run", plan.seeds, {"long_name": "per-run random seed "
                                                          "(SeedSequence(seed, spawn_key=(run,)))"})
    for name, (vals, attrs) in coords.items():
        ds.coords[name] = (name, vals, attrs)
    ds["status"] = ("run", np.zeros(n, dtype=np.int8), {
        "long_name": "run status", "flag_values": [STATUS_PENDING, STATUS_OK, STATUS_FAILED],
        "flag_meanings": STATUS_MEANINGS})
    for name, (dtype, fill, attrs) in _RUN_VARS.items():
        ds[name] = ("run", da.full(n, fill, dtype=dtype, chunks=batch), attrs)
    for o in outputs:
        ds[o.name] = (("run", *o.dims), da.full((n, *o.shape), np.nan,
                                                chunks=(batch, *o.shape)),
                      {"units": o.units, "long_name": o.long_name})
    ds[CHECKSUM_VAR] = ("batch", da.full(-(-n // batch), "", dtype=f"<U{CHECKSUM_CHARS}",
                                         chunks=1),
                        {"long_name": "SHA-256 of the values of the batch's runs, written before "
                                      "their status (see geardyn.studies.sweep.integrity)"})
    ds.attrs = {
        "title": f"geardyn sweep {sweep.spec.name}",
        "description": sweep.spec.description,
        "geardyn_sweep": STORE_FORMAT,
        "geardyn_version": __version__,
        "software": json.dumps(_software_versions()),
        "sweep_name": sweep.spec.name,
        "sweep_hash": digest,
        "sweep_file": sweep.text,
        "sweep_origin": sweep.origin,
        "sweep_definition": json.dumps(sweep.definition(), default=float),
        "base_case": _case_toml(sweep.base_case),
        "evaluator": json.dumps(evaluator.identity()),
        "swept_parameters": [p.key for p in plan.parameters],
        "axes": [a.key for a in sweep.axes],
        "grid_shape": list(plan.grid_shape),
        "n_samples": plan.n_samples,
        "sampling": sweep.spec.sample.method if sweep.spec.sample else "none",
        "seed": sweep.spec.seed,
        "batch_size": batch,
        "n_runs": n,
        "created": time.strftime("%Y-%m-%dT%H:%M:%SZ", time.gmtime()),
        "status_codes": "0 pending, 1 ok, 2 failed",
        "checksum_variables": sorted([*_CORE_VARS, *(o.name for o in outputs)]),
        # the swept values and seeds, written once: their own checksum (verify_store)
        "plan_variables": sorted([*(p.key for p in plan.parameters), "seed"]),
        "plan_checksum": plan_digest({**{p.key: plan.values[p.key] for p in plan.parameters},
                                      "seed": plan.seeds}),
    }
    return ds


def _case_toml(case: Case) -> str:
    from ...config import case_to_toml

    return case_to_toml(case)


def _software_versions() -> dict:
    import dask
    import distributed
    import numba
    import scipy
    import xarray
    import zarr

    return {"numpy": np.__version__, "scipy": scipy.__version__, "numba": numba.__version__,
            "xarray": xarray.__version__, "zarr": zarr.__version__, "dask": dask.__version__,
            "distributed": distributed.__version__}


def _create_store(out: Path, ds, batch: int) -> None:
    """Write the template into a temporary folder and rename it to ``out`` (atomic)."""
    encoding: dict[str, dict] = {}
    for name, v in ds.variables.items():
        if "run" in v.dims and name != "run" and name not in ds.coords:
            enc: dict[str, Any] = {"chunks": (batch, *v.shape[1:])}
            if v.dtype.kind == "f":
                enc["_FillValue"] = np.nan
            encoding[name] = enc
    encoding[CHECKSUM_VAR] = {"chunks": (1,)}
    remove_stale_temp_files(out.parent, out.name)  # left by a process killed while creating
    tmp = out.with_name(f"{temp_prefix(out)}{uuid.uuid4().hex[:12]}.partial")
    try:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore", category=UserWarning)
            ds.to_zarr(str(tmp), mode="w-", compute=False, zarr_format=ZARR_FORMAT,
                       consolidated=True, encoding=encoding)
        try:
            os.rename(tmp, out)
        except OSError:
            if out.exists():
                raise DataFileError(out, "was created by another process at the same time; "
                                         "re-run the command to resume it") from None
            raise
    except BaseException:
        shutil.rmtree(tmp, ignore_errors=True)
        raise
    backup = _SET_ASIDE.pop(out, None)  # the store --force replaces: now it may go
    if backup is not None:
        shutil.rmtree(backup, ignore_errors=True)


def _remove_partials(out: Path) -> int:
    """Delete temporary files of writes killed mid-way (zarr's ``*.<hex>.partial``)."""
    n = 0
    for p in out.rglob("*.partial"):
        with contextlib.suppress(OSError):
            p.unlink()
            n += 1
    return n


def _open_group(out: Path, mode: str = "r+"):
    return open_store_group(out, mode)


def store_status(out: str | os.PathLike, *, repair: bool = False) -> np.ndarray:
    """The ``status`` of every run of a sweep store (0 pending, 1 ok, 2 failed).

    A status chunk that cannot be read (a write torn by a crash on a store that does not write
    atomically) counts as pending; with ``repair`` it is rewritten as pending so the batch is
    computed again.
    """
    g = _open_group(Path(out), "r+" if repair else "r")
    arr = g["status"]
    with contextlib.suppress(Exception):  # a torn chunk: read chunk by chunk below
        return np.asarray(arr[:], dtype=np.int8)
    n, b = arr.shape[0], arr.chunks[0]
    out_status = np.zeros(n, dtype=np.int8)
    for a in range(0, n, b):
        try:
            out_status[a:a + b] = arr[a:a + b]
        except Exception:
            if repair:
                arr[a:a + b] = np.zeros(min(b, n - a), dtype=np.int8)
    return out_status


@dataclass(frozen=True)
class RunRecord:
    """The outcome of one run, as written to the store.

    Attributes
    ----------
    status : int
        :data:`STATUS_OK` or :data:`STATUS_FAILED`.
    values : dict
        Output name -> float64 array (empty for a failed run).
    error : str
        The failure message ("" if ok).
    warning : str
        Distinct warnings raised during the run, joined by " | " ("" if none).
    seconds : float
        Wall time [s].
    worker : str
        ``host:pid`` of the process that computed it.
    """

    status: int
    values: dict
    error: str = ""
    warning: str = ""
    seconds: float = math.nan
    worker: str = ""


#: Per-run bookkeeping variables: name -> (dtype, fill, attrs).
_RUN_VARS: dict[str, tuple[str, Any, dict]] = {
    "error": (f"<U{ERROR_CHARS}", "", {"long_name": "error message of a failed run"}),
    "warning": (f"<U{ERROR_CHARS}", "", {"long_name": "warnings raised during the run"}),
    "worker": ("<U64", "", {"long_name": "host:pid of the worker process that ran it"}),
    "run_seconds": ("<f8", np.nan, {"units": "s", "long_name": "wall time of the run"}),
}


def _write_batch(out: str, start: int, stop: int, results: Mapping[int, RunRecord],
                 outputs: Sequence[Output], batch_size: int) -> None:
    """Write one chunk ``[start, stop)`` (``start`` a multiple of the store's ``batch_size``):
    data variables first, then the batch's checksum, the status last.

    ``results`` maps run -> :class:`RunRecord` for the runs computed; the other runs of the
    chunk keep their stored values (a resumed chunk). The chunks of the data variables are
    written concurrently (:func:`_write_in_order`); the checksum
    (:func:`.integrity.batch_digest` of every value of the chunk, the status included) is
    written once all of them are in place, and the status chunk after it.
    """
    full = len(results) == stop - start
    n = stop - start
    specs: list[tuple[str, tuple, Any, Any, Callable[[RunRecord], Any]]] = [
        (o.name, o.shape, np.float64, np.nan,
         lambda rec, name=o.name: rec.values.get(name, np.nan)) for o in outputs]
    specs += [(name, (), dtype, fill,
               lambda rec, name=name: getattr(rec, "seconds" if name == "run_seconds" else name))
              for name, (dtype, fill, _) in _RUN_VARS.items()]
    if full:
        blocks = [np.full((n, *shape), fill, dtype=dtype) for _, shape, dtype, fill, _ in specs]
        status = np.full(n, STATUS_PENDING, dtype=np.int8)
    else:  # keep the runs of the chunk that are not recomputed
        g = open_store_group(out, "r")
        blocks = [np.array(g[sp[0]][start:stop], dtype=sp[2]) for sp in specs]
        status = np.array(g["status"][start:stop], dtype=np.int8)
    for blk, (_, _, _, _, get) in zip(blocks, specs, strict=True):
        for run, rec in results.items():
            blk[run - start] = get(rec)
    for run, rec in results.items():
        status[run - start] = rec.status
    columns = {sp[0]: blk for sp, blk in zip(specs, blocks, strict=True)} | {"status": status}
    batch = start // batch_size
    region = slice(start, stop)
    digest = np.array([batch_digest(start, stop, columns)], dtype=f"<U{CHECKSUM_CHARS}")
    _write_in_order(out, [(sp[0], region, blk) for sp, blk in zip(specs, blocks, strict=True)],
                    [(CHECKSUM_VAR, slice(batch, batch + 1), digest),
                     ("status", region, status)])  # last: the batch is done from here


def _write_in_order(out: str, together: Sequence[tuple[str, slice, np.ndarray]],
                    then: Sequence[tuple[str, slice, np.ndarray]]) -> None:
    """Write the regions ``together`` all at once, then each of ``then`` in turn, once the
    previous one is in place.

    One event loop does it through zarr's asynchronous API (``zarr.api.asynchronous.open_group``,
    ``AsyncGroup.getitem``, ``AsyncArray.setitem``), so every chunk of ``together`` is encoded
    and written concurrently. zarr's synchronous API makes one round trip to its I/O thread per
    array: four batches of the sweep benchmark (13 runs of the paper's case, 76 arrays each),
    replayed in one process, took 0.095-0.132 s a batch from eight threads against
    0.060-0.065 s here (2026-11-27, AMD EPYC, 2 cores). The opened arrays are kept for the
    next batch (:func:`_store_arrays`).
    """
    import asyncio

    async def write() -> None:
        names = [name for name, _, _ in together] + [name for name, _, _ in then]
        arrays = await _store_arrays(out, names)
        await asyncio.gather(*(arrays[name].setitem(sel, value) for name, sel, value in together))
        for name, sel, value in then:
            await arrays[name].setitem(sel, value)

    try:
        asyncio.get_running_loop()
    except RuntimeError:  # no loop in this thread (a Dask task's thread): the usual case
        asyncio.run(write())
        return
    from concurrent.futures import ThreadPoolExecutor

    with ThreadPoolExecutor(max_workers=1) as pool:  # called from a coroutine: its own thread
        pool.submit(asyncio.run, write()).result()


#: Arrays opened by :func:`_store_arrays`: (store path, thread) -> (version, {name: AsyncArray}).
_OPENED: dict[tuple[str, int], tuple[tuple[int, ...], dict[str, Any]]] = {}
_OPENED_MAX = 8
_OPENED_LOCK = threading.Lock()


async def _store_arrays(out: str, names: Sequence[str]) -> dict[str, Any]:
    """The store's arrays ``names`` (zarr ``AsyncArray``), opened once per version of the store
    in each thread.

    Opening the group and its 76 arrays parses the consolidated metadata: 21-24 ms of each
    13-run batch of the paper's case (2026-11-27). A store's *version* is the inode, size and
    modification and change times of its ``.zmetadata`` (a store created again, or its
    metadata rebuilt, is another version and is opened afresh); a store without consolidated
    metadata is opened every time. The arrays hold the path, shape, chunks and codecs, no
    data and nothing of an event loop.
    """
    import asyncio

    from zarr.api import asynchronous as zarr_async

    try:
        st = (Path(out) / ".zmetadata").stat()
        version: tuple[int, ...] | None = (st.st_ino, st.st_size, st.st_mtime_ns, st.st_ctime_ns)
    except OSError:
        version = None
    key = (out, threading.get_ident())
    held = _OPENED.get(key)
    arrays = dict(held[1]) if held is not None and held[0] == version else {}
    missing = list(dict.fromkeys(n for n in names if n not in arrays))
    if missing:
        consolidated = version is not None and _consolidated_ok(Path(out))
        g = await zarr_async.open_group(out, mode="r+", use_consolidated=True if consolidated
                                        else False)
        arrays.update(zip(missing, await asyncio.gather(*(g.getitem(n) for n in missing)),
                          strict=True))
        if consolidated:
            with _OPENED_LOCK:  # the oldest entries out (one per store and thread)
                _OPENED.pop(key, None)
                while len(_OPENED) >= _OPENED_MAX:
                    _OPENED.pop(next(iter(_OPENED)))
                _OPENED[key] = (version, arrays)
    return arrays


def _clip(text: str, n: int = ERROR_CHARS) -> str:
    return text if len(text) <= n else text[:n - 1] + "\u2026"


def _message(exc: BaseException) -> str:
    text = str(exc)
    if not isinstance(exc, GeardynError):
        text = f"{type(exc).__name__}: {text}"
    return _clip(text)


def _check_values_shapes(values: Mapping[str, Any], outputs: Sequence[Output]) -> dict:
    clean: dict[str, Any] = {}
    for o in outputs:
        if o.name not in values:
            raise InputError("evaluator", o.name, "a value for every declared output "
                                                  f"(missing {o.name})")
        v = np.asarray(values[o.name], dtype=np.float64)
        if v.shape != o.shape:
            raise InputError("evaluator", f"{o.name} of shape {v.shape}", f"shape {o.shape}")
        clean[o.name] = v
    return clean



#: Stores that ``--force`` set aside until their replacement exists: new path -> old store.
_SET_ASIDE: dict[Path, Path] = {}


def restore_set_aside(out: Path) -> bool:
    """Put back the store that ``--force`` set aside for ``out`` when no new store was created
    (an error or an interrupt before it); True if it was put back."""
    backup = _SET_ASIDE.pop(out, None)
    if backup is None or not backup.exists():
        return False
    if out.exists():  # a new store exists after all: the old one goes
        shutil.rmtree(backup, ignore_errors=True)
        return False
    os.rename(backup, out)
    return True


def _definition_changes(stored: str | None, new: dict | None, limit: int = 2) -> str:
    """What differs between a store's ``sweep_definition`` (JSON) and ``new``: "axes.x: [..] ->
    [..]; ..." (at most ``limit`` keys), or "" when either is unknown."""
    if not stored or new is None:
        return ""
    try:
        old = json.loads(stored)
        new = json.loads(json.dumps(new, default=float))
    except (TypeError, ValueError):
        return ""

    def flat(node, prefix=""):
        if (isinstance(node, list) and node and all(
                isinstance(e, list) and len(e) == 2 and isinstance(e[0], str) for e in node)):
            node = dict(node)  # the axes: [[key, values], ...], in order
        if isinstance(node, dict):
            out = {}
            for k, v in node.items():
                out.update(flat(v, f"{prefix}.{k}" if prefix else str(k)))
            return out
        return {prefix: node}

    a, b = flat(old), flat(new)
    keys = [k for k in sorted(set(a) | set(b)) if a.get(k) != b.get(k)]

    def short(v) -> str:
        text = json.dumps(v)
        return text if len(text) <= 30 else text[:27] + "..."

    parts = [f"{k}: {short(a.get(k))} -> {short(b.get(k))}" for k in keys[:limit]]
    more = f"; and {len(keys) - limit} more" if len(keys) > limit else ""
    return "; ".join(parts) + more


def _check_out(out: Path, digest: str, force: bool, definition: dict | None = None) -> bool:
    """True if ``out`` holds this sweep (resume); False if it must be created."""
    if not out.exists() or (out.is_dir() and not any(out.iterdir())):
        return False  # new (an empty folder is replaced by the store)
    if not out.is_dir() or not _is_store(out):
        raise DataFileError(out, "exists and is not a Zarr store; choose another --out")
    attrs = _read_attrs(out)
    if "geardyn_sweep" not in attrs and (out / CHECKSUM_VAR).is_dir():
        check_metadata(out, rebuild=False)  # a sweep store that lost its attributes: say which
    if "geardyn_sweep" not in attrs:
        raise DataFileError(out, "is a Zarr store but not a geardyn sweep; choose another --out")
    if attrs.get("sweep_hash") == digest:
        return True
    if force:
        # set aside, not deleted: the old store goes only once the new one exists (an
        # interrupted --force deleted it with nothing in its place: a user audit, 2026-11-27)
        backup = out.with_name(f"{out.name}.replaced-by-pid{os.getpid()}")
        if backup.exists():
            shutil.rmtree(backup)
        os.rename(out, backup)
        _SET_ASIDE[out] = backup
        return False
    from ..._version import __version__

    what = _definition_changes(attrs.get("sweep_definition"), definition)
    if not what and attrs.get("geardyn_version") != __version__:
        what = f"geardyn {attrs.get('geardyn_version')} -> {__version__}"
    raise InputError("--out", str(out), f"a new store, or the store of this same sweep: it "
                                        f"holds a different sweep ('{attrs.get('sweep_name')}'"
                                        + (f"; changed: {what}" if what else ", another "
                                           "definition or geardyn version")
                                        + "); pass --force to replace it (its finished runs are "
                                        "lost), or choose another --out")


def _outputs_from_store(out: Path) -> tuple[Output, ...]:
    """The result variables as laid out in an existing store."""
    import xarray as xr

    with xr.open_zarr(str(out), consolidated=_consolidated_ok(out)) as ds:
        return tuple(Output(str(name), v.attrs.get("units", ""), v.attrs.get("long_name", ""),
                            tuple(str(d) for d in v.dims[1:]), tuple(v.shape[1:]))
                     for name, v in ds.data_vars.items()
                     if name not in _CORE_VARS and v.dims[:1] == ("run",))


# ============================================================================================
# reading
# ============================================================================================
def open_sweep(path: str | os.PathLike, *, only_ok: bool = False, unstack: bool = False,
               verify: bool = True):
    """Open a sweep store with xarray.

    Parameters
    ----------
    path : path-like
        The Zarr store.
    only_ok : bool
        Keep only the runs whose status is ok.
    unstack : bool
        Reshape a grid sweep (axes only, no sampling, no failed filtering) into one dimension
        per axis, named by its dotted key.
    verify : bool
        Check every finished batch against its checksum first
        (:func:`~geardyn.studies.sweep.integrity.verify_store`; this reads the whole store once).
        Stores written before checksums existed are opened unchecked.

    Returns
    -------
    xarray.Dataset

    Raises
    ------
    DataFileError
        Not a sweep store, damaged metadata, or (with ``verify``) batches whose values do not
        match their checksums: the message names them; resuming the sweep recomputes them.
    """
    import xarray as xr

    from ..._optional import require_extra

    require_extra("sweep")  # zarr (and dask for the lazy arrays): a clear error naming the extra
    p = Path(path)
    if not _is_store(p):
        raise DataFileError(p, "is not a Zarr store")
    metadata = check_metadata(p, rebuild=False)
    ds = xr.open_zarr(str(p), consolidated=metadata == "ok")
    if "geardyn_sweep" not in ds.attrs:
        raise DataFileError(p, "is not a geardyn sweep store")
    if verify and "checksum_variables" in ds.attrs:
        check = verify_store(p)
        if not check.ok:
            raise DataFileError(p, f"is damaged: {check.summary(3)}; re-run the same `geardyn "
                                   "sweep` command to recompute those runs (or open_sweep(..., "
                                   "verify=False) to read it as it is)")
    if only_ok:
        ds = ds.isel(run=np.flatnonzero(ds["status"].values == STATUS_OK))
    if unstack:
        axes = list(ds.attrs.get("axes", []))
        if int(ds.attrs.get("n_samples", 1)) != 1 or not axes:
            raise InputError("unstack", True, "a sweep with axes and no sampled dimensions")
        ds = ds.set_index(run=axes).unstack("run")
    return ds

