"""Output folders that know which inputs made them: re-runs, resumes and clear refusals.

Every command that writes results records the identity of its inputs (the command, a hash of the
effective case, the options that change results, the geardyn version) in the output folder's
``inputs.json`` *before* it writes anything else, with ``"complete": false``, and rewrites it with
``"complete": true`` (and which cache entries it reused) as its very last step. So:

- running the same command twice into the same folder just works (the cache makes it fast);
- an interrupted run (Ctrl-C, a kill) leaves a folder whose record says ``complete: false``, and
  re-running the same command continues into it;
- a folder holding results of *different* inputs is refused, naming what differs, unless
  ``--force``;
- a folder with results but no record (an older geardyn, files put there by hand) is refused
  unless ``--force``;
- a folder whose run stopped on an input error (:func:`input_errors_recorded`: a bad time
  step found at the simulation stage, after the maps were written) holds nothing worth
  keeping: the corrected command replaces it without ``--force``.

``geardyn simulate`` writes one file; its identity goes into the file's ``geardyn_inputs``
attribute instead (see :mod:`geardyn.cli.simulate`).
"""

from __future__ import annotations

import contextlib
import json
import os
import tempfile
from collections.abc import Iterator
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from ..errors import InputError

__all__ = ["OutputTarget", "OutputInUse", "RECORD", "identity", "check_writable", "claim_folder", "begin",
           "mark_complete", "input_errors_recorded", "read_record", "differences",
           "refuse_different", "resolve",
           "recorded_inputs", "claim_file",
           "cache_summary", "say_state", "say_cache"]

#: Name of the inputs record in an output folder.
RECORD = "inputs.json"

#: Case values that do not change any result (left out of the identity).
_NOT_RESULTS = {"name", "simulation.max_steps"}


class OutputInUse(InputError):
    """The output already holds results this command must not replace (exit 2).

    The message reads ``<output> <problem>; <remedy>``, e.g. ``--out runs/a holds results of
    different inputs (simulation.record_time 1.0 -> 0.2); ...``.
    """

    def __init__(self, label: str, problem: str, remedy: str):
        super().__init__(label, problem, remedy)
        self.args = (f"{label} {problem}; {remedy}",)

    def __str__(self) -> str:
        return str(self.args[0])


@dataclass(frozen=True)
class OutputTarget:
    """Where a command writes, and how to name it in a message.

    Attributes
    ----------
    path : Path
        The output folder (or file, for ``simulate``).
    given : bool
        Whether the user gave ``--out``; messages name ``--out`` only then.
    """

    path: Path
    given: bool

    @property
    def label(self) -> str:
        """``--out PATH`` if the user gave it, else ``the default output folder PATH``."""
        text = _short(str(self.path))
        if self.given:
            return f"--out {text}"
        kind = "file" if self.path.suffix else "folder"
        return f"the default output {kind} {text}"


def _short(text: str, n: int = 160) -> str:
    return text if len(text) <= n else text[: n // 2 - 2] + "..." + text[-(n // 2 - 2):]


def resolve(out: Path | None, default: Path) -> OutputTarget:
    """The output target for an ``--out`` value that may be absent."""
    return OutputTarget(default if out is None else Path(out), out is not None)


def _flatten(node: Any, prefix: str = "") -> dict[str, Any]:
    if isinstance(node, dict):
        flat: dict[str, Any] = {}
        for k, v in node.items():
            flat.update(_flatten(v, f"{prefix}.{k}" if prefix else str(k)))
        return flat
    return {prefix: node}


def identity(command: str, case=None, options: dict[str, Any] | None = None,
             files: dict[str, Path] | None = None) -> dict[str, Any]:
    """What makes a command's results what they are.

    Parameters
    ----------
    command : str
        ``"run"``, ``"stiffness"``...
    case : geardyn.config.Case, optional
        The effective case (after ``--config`` and ``--set``); its values (not its provenance or
        name) are hashed.
    options : dict, optional
        Command-line options that change the results (JSON-serialisable).
    files : dict of str -> Path, optional
        Input files; their SHA-256 is part of the identity.
    """
    from .._version import __version__
    from ..cache import cache_key
    from ..io import json_safe

    ident: dict[str, Any] = {"command": command, "options": json_safe(options or {}),
                             "geardyn": __version__}
    if case is not None:
        from ..config import deep_copy_case_data

        values = {k: v for k, v in _flatten(json_safe(deep_copy_case_data(case))).items()
                  if k not in _NOT_RESULTS}
        ident["case_name"] = case.name
        ident["case_hash"] = cache_key(values)
        ident["case"] = values
    if files:
        import hashlib

        digests = {}
        for name, path in files.items():
            h = hashlib.sha256()
            with open(path, "rb") as fh:
                for chunk in iter(lambda fh=fh: fh.read(1 << 20), b""):
                    h.update(chunk)
            digests[name] = {"path": str(path), "sha256": h.hexdigest()}
        ident["files"] = digests
    return ident


def differences(old: dict[str, Any], new: dict[str, Any]) -> list[str]:
    """What differs between two identities, in words (empty: the same inputs)."""
    if old.get("command") != new.get("command"):
        return [f"they were made by 'geardyn {old.get('command')}'"]
    diff = []
    if old.get("case_hash") != new.get("case_hash"):
        a, b = old.get("case") or {}, new.get("case") or {}
        # a key on one side only: a field another geardyn version added or removed (not a
        # difference of inputs), or, made by this version, a value left out of the identity
        # when empty (``faults``: a fault added to a case file was "up to date", 2026-11-27)
        same_version = old.get("geardyn") == new.get("geardyn")
        keys = sorted([k for k in set(a) & set(b) if a[k] != b[k]]
                      + [k for k in set(a) ^ set(b) if same_version or k == "faults"])
        for k in keys:
            diff += _value_differences(k, a.get(k), b.get(k))
    oa, ob = old.get("options") or {}, new.get("options") or {}
    diff += [f"{k} {_short(repr(oa.get(k)), 40)} -> {_short(repr(ob.get(k)), 40)}"
             for k in sorted(set(oa) | set(ob)) if oa.get(k) != ob.get(k)]
    fa, fb = old.get("files") or {}, new.get("files") or {}
    files = []
    for k in sorted(set(fa) | set(fb)):
        was, now = (fa.get(k) or {}), (fb.get(k) or {})
        if was.get("sha256") == now.get("sha256"):
            continue
        if was.get("path") and now.get("path") and was["path"] != now["path"]:
            # another file (paper.nc's results, now paper.csv: a user audit), not an edit
            files.append(f"{k} {_short(was['path'], 40)} -> {_short(now['path'], 40)}")
        else:
            files.append(f"the content of {k} {_short((now or was).get('path', ''), 60)}")
    return files + diff  # another input file first: it explains the rest


def _value_differences(key: str, a: Any, b: Any) -> list[str]:
    """``key old -> new`` for one identity value; a list of tables (``faults``) entry by entry
    and key by key (``faults[0].type 'spall' -> 'breakage'``), so that what differs is not cut
    out of a long repr."""
    if isinstance(a, dict) and isinstance(b, dict):
        order = sorted(set(a) | set(b), key=lambda k: (k != "type", str(k)))  # a fault's type first
        return [line for k in order if a.get(k) != b.get(k)
                for line in _value_differences(f"{key}.{k}", a.get(k), b.get(k))]
    if isinstance(a, list) and b is None or a is None and isinstance(b, list):
        a, b = a or [], b or []  # a list of tables left out of the identity when empty
    if (isinstance(a, list) and isinstance(b, list)
            and any(isinstance(x, dict) for x in (*a, *b))):
        out = []
        for i in range(max(len(a), len(b))):
            x, y = (a[i] if i < len(a) else None), (b[i] if i < len(b) else None)
            if x != y:
                out += _value_differences(f"{key}[{i}]", x, y)
        return out

    def shown(v: Any) -> str:
        if v is None:
            return "(none)"
        if isinstance(v, dict):  # a table added or removed: its set values
            return _short(", ".join(f"{k} = {w!r}" for k, w in v.items() if w is not None), 120)
        return _short(repr(v), 40)

    return [f"{key} {shown(a)} -> {shown(b)}"]


def refuse_different(target: OutputTarget, diff: list[str]) -> InputError:
    """The error for an output holding results of different inputs."""
    shown = "; ".join(diff[:3]) + (f"; and {len(diff) - 3} more" if len(diff) > 3 else "")
    return OutputInUse(target.label, f"holds results of different inputs ({shown})",
                       "pass --force to replace them, or choose another output with --out")



def recorded_inputs(path: Path) -> dict[str, Any] | None:
    """The inputs identity (:func:`identity`) a geardyn NetCDF output carries in its
    ``geardyn_inputs`` attribute; None for a file that is not one (or unreadable)."""
    import json

    import h5py

    try:
        with h5py.File(path, "r") as f:
            text = f.attrs.get("geardyn_inputs")
        text = text.decode() if isinstance(text, bytes) else text
        ident = json.loads(text) if text else None
    except (OSError, ValueError, TypeError):
        return None
    return ident if isinstance(ident, dict) else None


def claim_file(target: OutputTarget, ident: dict[str, Any], *, force: bool,
               companions: tuple[Path, ...] = (), companions_needed: bool = True) -> bool:
    """Whether the NetCDF output ``target`` (written atomically, with its inputs in the
    ``geardyn_inputs`` attribute) already holds the results of ``ident`` with its
    ``companions`` beside it: then there is nothing to compute (True). A file of other inputs,
    or one geardyn did not write, is refused without ``force`` (:class:`OutputInUse`); so is a
    companion file where the output itself is missing. With ``companions_needed=False`` the
    output alone decides (the caller writes missing companions from it)."""
    path = target.path
    if not path.exists():
        present = [c for c in companions if c.exists()]
        if present and not force:
            raise OutputInUse(target.label, f"has no result but {present[0]} exists",
                              "pass --force to replace it, or choose another output with --out")
        return False
    old = recorded_inputs(path)
    if old is None:
        if not force:
            raise OutputInUse(target.label, "is an existing file that is not a geardyn result "
                                            "of known inputs",
                              "pass --force to replace it, or choose another file with --out")
        return False
    diff = differences(old, ident)
    if diff and not force:
        raise refuse_different(target, diff)
    return not diff and not force and (not companions_needed
                                       or all(c.exists() for c in companions))

#: Suffixes of the copies a record command writes beside its NetCDF file (``--csv``, ``--mat``).
COPY_SUFFIXES = (".csv", ".mat")


def check_record_name(target: OutputTarget, copies: tuple[str, ...] = COPY_SUFFIXES) -> None:
    """Refuse a NetCDF record's ``--out`` named as one of its copies (``y.mat``): the record
    is NetCDF whatever its name, so ``y.mat`` was a NetCDF file MATLAB cannot read, and
    ``--mat`` wrote the copy over the record (a user audit, 2026-11-27)."""
    suffix = target.path.suffix.lower()
    if suffix in copies:
        flag = {".csv": "--csv", ".mat": "--mat"}[suffix]
        raise InputError("--out", str(target.path),
                         f"the NetCDF record's file name, e.g. "
                         f"{target.path.with_suffix('.nc').name} ({flag} writes "
                         f"{target.path.name} beside it)")


def copies_to_refresh(out: Path, inputs_json: str, wanted: tuple[Path, ...]
                      ) -> tuple[list[Path], list[Path]]:
    """The CSV and MATLAB copies of the record ``out`` (of inputs ``inputs_json``, its
    ``geardyn_inputs``) to write and to remove.

    To write: each ``wanted`` copy that is missing or is not a copy of these inputs (its
    :data:`geardyn.io.COPY_STAMP` differs or is missing). To remove: a copy beside ``out`` that
    is not wanted and is stamped as a copy of other inputs (a record this one replaced), so no
    copy of another record is left looking like this one's; a file without a stamp is not
    geardyn's to remove.
    """
    from ..io import copy_inputs_sha256, inputs_sha256

    stamp = inputs_sha256(inputs_json)
    write = [c for c in wanted if not c.exists() or copy_inputs_sha256(c) != stamp]
    remove = []
    for suffix in COPY_SUFFIXES:
        c = out.with_suffix(suffix)
        if c in wanted or not c.is_file():
            continue
        other = copy_inputs_sha256(c)
        if other is not None and other != stamp:
            remove.append(c)
    return write, remove


def check_writable(target: OutputTarget, *, folder: bool = True) -> None:
    """Refuse, before any work, an output that cannot be written.

    ``folder=True``: the target must be a folder (or not exist yet, under a writable folder);
    ``folder=False``: a file path (not an existing folder) in a writable folder.
    """
    p = target.path
    if folder and p.exists() and not p.is_dir():
        raise InputError(target.label, "an existing file", "a folder (or a path that does not "
                                                           "exist yet)")
    if not folder and p.is_dir():
        raise InputError(target.label, "an existing folder", "a file path")
    probe = p if folder else p.parent
    probe = Path(os.path.abspath(probe))
    while not probe.exists():
        if probe.parent == probe:
            break
        probe = probe.parent
    if not probe.is_dir():
        raise InputError(target.label, _short(str(probe)),
                         "a path whose parent folders are folders (this one is a file, not a "
                         "folder)")
    try:
        fd, tmp = tempfile.mkstemp(prefix=".geardyn-write-test.", dir=probe)
    except OSError as exc:
        raise InputError(target.label, f"cannot write in {_short(str(probe))} "
                                       f"({exc.strerror or exc})",
                         "a folder you can write to" + ("" if target.given else
                                                        " (choose one with --out)")) from None
    os.close(fd)
    os.unlink(tmp)


def read_record(folder: Path) -> dict[str, Any] | None:
    """The folder's inputs record, or None if there is none (or it is unreadable)."""
    try:
        data = json.loads((folder / RECORD).read_text(encoding="utf-8"))
    except (OSError, ValueError):
        return None
    return data if isinstance(data, dict) and "identity" in data else None


def claim_folder(target: OutputTarget, ident: dict[str, Any], *, force: bool,
                 results: list[str], record: bool = True) -> str:
    """Check that ``target`` may receive the results of ``ident`` and record the inputs first.

    Parameters
    ----------
    target : OutputTarget
    ident : dict
        From :func:`identity`.
    force : bool
        Replace results of other inputs.
    results : list of str
        Names of the files and folders this command writes (a folder holding one of them
        without a record is refused unless ``force``; those of other inputs are removed when
        this run replaces them, ``"replace"`` and ``"retry"``).
    record : bool
        Write the record (``complete: false``) now; ``False`` for a command that computes
        everything before writing its first file: it calls :func:`begin` just before that.

    Returns
    -------
    str
        ``"new"``, ``"continue"`` (same inputs, earlier run interrupted), ``"again"`` (same
        inputs, earlier run complete), ``"replace"`` (``--force`` over other results) or
        ``"retry"`` (other inputs over a run that stopped on an input error).
    """
    folder = target.path
    check_writable(target, folder=True)
    old = read_record(folder) if folder.is_dir() else None
    if old is not None:
        diff = differences(old["identity"], ident)
        if not diff:
            state = "again" if old.get("complete") else "continue"
        elif force:
            state = "replace"
        elif old.get("input_error") and not old.get("complete"):
            state = "retry"  # its inputs were refused: nothing of value to protect
        else:
            raise refuse_different(target, diff)
    else:
        existing = [name for name in results if (folder / name).exists()]
        if existing and not force:
            raise OutputInUse(target.label, f"holds earlier results ({existing[0]}) whose "
                                            "inputs are not recorded (no inputs.json)",
                              "pass --force to replace them, or choose another output with "
                              "--out")
        state = "replace" if existing else "new"
    if state in ("replace", "retry"):
        # the results of other inputs go before this run writes its own: a --force run with
        # other options left the earlier run's figures beside the new metrics.json (a user
        # audit, 2026-11-27)
        _remove_results(folder, results)
    if record:
        begin(target, ident)
    return state


def _remove_results(folder: Path, results: list[str]) -> None:
    """Remove the named results (files or folders) of ``folder`` that exist."""
    import shutil

    for name in results:
        p = folder / name
        if p.is_dir() and not p.is_symlink():
            shutil.rmtree(p)
        elif p.exists() or p.is_symlink():
            p.unlink()


def begin(target: OutputTarget, ident: dict[str, Any]) -> None:
    """Write the inputs record with ``complete: false`` (before the first result file)."""
    _write_record(target.path, {"identity": ident, "complete": False})


@contextlib.contextmanager
def input_errors_recorded(target: OutputTarget, ident: dict[str, Any]) -> Iterator[None]:
    """Record in the folder's inputs record that the command stopped on an input error.

    For a command that writes results stage by stage after :func:`claim_folder`: a stage can
    refuse an input only it checks (``geardyn run``: the time step against the map's mesh
    stiffness, at the simulation stage). The folder then holds the earlier stages' files of
    inputs that were refused, and the record says so (``"input_error"``, the message), so that
    the corrected command replaces them (state ``"retry"``) instead of being refused as
    different inputs. Any other exception (a crash, Ctrl-C) leaves the record as it was: the
    same command continues the run.
    """
    try:
        yield
    except InputError as exc:
        _write_record(target.path, {"identity": ident, "complete": False,
                                    "input_error": str(exc)})
        raise


def mark_complete(target: OutputTarget, ident: dict[str, Any], lookups: list[dict] | None = None,
                  **extra: Any) -> None:
    """Rewrite the record with ``complete: true`` (the last write of a command)."""
    record: dict[str, Any] = {"identity": ident, "complete": True, **extra}
    if lookups is not None:
        record["cache"] = cache_summary(lookups)
    _write_record(target.path, record)


def cache_summary(lookups: list[dict]) -> dict[str, Any]:
    """Cache hits and builds by kind, from :func:`geardyn.cache.record_lookups`."""
    out: dict[str, Any] = {}
    # each entry once: built if it was computed during the run (by this process or another),
    # else reused; a map read three times is not three reuses
    entries: dict[tuple[str, str], bool] = {}
    for item in lookups:
        k = (item["kind"], item["key"])
        entries[k] = entries.get(k, True) and bool(item["hit"])
    for (kind, _), hit in entries.items():
        k = out.setdefault(kind, {"hits": 0, "built": 0})
        k["hits" if hit else "built"] += 1
    return out


def say_state(state: str, target: OutputTarget) -> None:
    """One line on stderr saying what a re-run does with the earlier results."""
    from rich.markup import escape

    from ._common import err_console

    where = escape(str(target.path))
    text = {"continue": f"continuing the interrupted run in {where} (same inputs)",
            "again": f"same inputs as the results in {where}: running again (the cache makes it "
                     "fast)",
            "replace": f"--force: replacing the earlier results in {where}",
            "retry": f"the earlier run into {where} stopped on an input error: replacing its "
                     f"partial results"}.get(state)
    if text:
        err_console.print(f"[dim]{text}[/dim]", highlight=False, soft_wrap=True)


def say_cache(lookups: list[dict]) -> None:
    """One line on stderr: what came from the cache and what was computed."""
    from ._common import err_console

    summary = cache_summary(lookups)
    if summary:
        parts = [f"{kind} {v['hits']} reused / {v['built']} computed" for kind, v in
                 sorted(summary.items())]
        err_console.print(f"[dim]cache: {'; '.join(parts)}[/dim]", highlight=False, soft_wrap=True)


def _write_record(folder: Path, record: dict[str, Any]) -> None:
    from ..io import write_json_atomic

    folder.mkdir(parents=True, exist_ok=True)
    write_json_atomic(folder / RECORD, record)
