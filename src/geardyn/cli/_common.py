"""Shared pieces of the command-line tool: common options, case loading, error handling.

Every command takes ``--config FILE`` and repeatable ``--set dotted.key=value``. Errors a user can
cause (:class:`geardyn.errors.GeardynError`) print one line (at most :data:`MAX_ERROR_CHARS`
characters) naming the field, the value and what is allowed, and exit with status 2; Ctrl-C
exits with 130 (see :func:`_say_interrupted`); nothing prints a traceback unless ``GEARDYN_DEBUG=1``.
"""

from __future__ import annotations

import contextlib
import errno
import functools
import os
import sys
from collections.abc import Callable
from pathlib import Path
from typing import Annotated, Any, TypeVar

import typer
from rich.console import Console
from rich.markup import escape

from ..errors import GeardynError

__all__ = ["ConfigOption", "SetOption", "OutOption", "ForceOption",
           "load_case_from_cli", "handle_errors", "one_line", "warning_line", "choice",
           "console", "err_console", "progress_bar", "StageProgress", "MAX_ERROR_CHARS"]

F = TypeVar("F", bound=Callable[..., Any])

console = Console()
err_console = Console(stderr=True)

ConfigOption = Annotated[
    Path | None,
    typer.Option("--config", "-c", help="Case file (TOML). Default: the paper's case shipped with "
                                        "geardyn.", show_default=False),
]
SetOption = Annotated[
    list[str] | None,
    typer.Option("--set", "-s", help="Override a case value: dotted.key=value (repeatable), e.g. "
                                     "--set pinion.teeth=25 --set simulation.dt='5e-6 s'.",
                 show_default=False),
]
OutOption = Annotated[
    Path,
    typer.Option("--out", "-o", help="Output folder."),
]
ForceOption = Annotated[
    bool,
    typer.Option("--force", "-f", help="Replace results of other inputs in the output (a re-run "
                                       "with the same inputs needs no --force)."),
]

#: Longest error line the CLI prints [characters].
MAX_ERROR_CHARS = 480


def choice(option: str, value: str | None, allowed: tuple[str, ...]) -> str | None:
    """``value`` matched case-insensitively against ``allowed`` (None stays None)."""
    from ..errors import InputError

    if value is None:
        return None
    for a in allowed:
        if value.strip().lower() == a.lower():
            return a
    raise InputError(option, value, " or ".join(repr(a) for a in allowed) + " (any case)")


def load_case_from_cli(config: Path | None, overrides: list[str] | None):
    """Load the case named by ``--config`` (or the paper's) with the ``--set`` overrides."""
    from ..config import load_case

    return load_case(config, overrides or [])


def one_line(text: str, limit: int = MAX_ERROR_CHARS) -> str:
    """``text`` on one line (whitespace runs collapsed) and at most ``limit`` characters."""
    text = " ".join(str(text).split())
    return text if len(text) <= limit else text[: limit - 26] + " ... (message shortened)"


#: Set by the Ctrl-C handler of :func:`handle_errors`. A KeyboardInterrupt raised inside a
#: callback that Python cannot raise from is swallowed: llvmlite's ctypes callbacks while numba
#: compiles ("Exception ignored on calling ctypes callback function"), the garbage collector's
#: callbacks (distributed's ``GCDiagnosis`` in a sweep's first process: a Ctrl-C that landed
#: there was lost and the sweep ran to its end, seen 2026-11-27). :func:`_unraisable` delivers
#: it to the main thread again; the progress callbacks (:class:`StageProgress`) also raise it
#: at their next tick. ``"redeliver"``: a delivery by :func:`_interrupt_main_soon` is still
#: due (whoever raises the interrupt first clears it, so it is raised once).
_INTERRUPT = {"pending": False, "redeliver": False}


def _on_sigint(signum, frame) -> None:
    _INTERRUPT["pending"] = True
    _INTERRUPT["redeliver"] = False
    raise KeyboardInterrupt


def _unraisable(default):
    """A :data:`sys.unraisablehook` that keeps a Ctrl-C swallowed by a callback (Python would
    print "Exception ignored ..." and a traceback) as a pending interrupt and delivers it to
    the main thread again (:func:`_thread.interrupt_main` from a thread of its own, 1 ms later:
    raised there at its next check, outside the callback), drops what such a Ctrl-C leaves behind (see
    :func:`_half_built_llvm_object`, :func:`_dask_gc_timer_cut_short`), and passes every other
    unraisable exception to ``default``."""

    def hook(args) -> None:
        if isinstance(args.exc_value, KeyboardInterrupt):
            _INTERRUPT["pending"] = True
            _INTERRUPT["redeliver"] = True
            import _thread

            # from a thread of its own, a moment later: the main thread gets it at its next
            # check, out of this hook and the callback (called here, or from a thread this
            # hook waits for, the handler would raise inside the hook)
            _thread.start_new_thread(_interrupt_main_soon, ())
            return
        if _half_built_llvm_object(args) or _dask_gc_timer_cut_short(args):
            return
        default(args)

    return hook


def _interrupt_main_soon() -> None:
    """Raise the pending Ctrl-C in the main thread, 1 ms from now, unless it has been raised
    meanwhile (a progress tick) or the command is over (its handler no longer
    :func:`_on_sigint`: the interrupt was handled, or this is not a command's process)."""
    import _thread
    import signal
    import time

    time.sleep(0.001)
    if _INTERRUPT["redeliver"] and signal.getsignal(signal.SIGINT) is _on_sigint:
        _INTERRUPT["redeliver"] = False
        _thread.interrupt_main()


def _dask_gc_timer_cut_short(args) -> bool:
    """Whether an unraisable exception is distributed's garbage-collection timer
    (``distributed.gc.GCDiagnosis._gc_callback``) asserting that its previous collection
    ended: a Ctrl-C raised inside that callback cut the previous one short, and every later
    collection of the process then prints ``AssertionError`` with a traceback."""
    obj = getattr(args, "object", None)
    return (isinstance(args.exc_value, AssertionError)
            and str(getattr(obj, "__module__", "") or "").startswith("distributed.gc"))


def _half_built_llvm_object(args) -> bool:
    """Whether an unraisable exception is llvmlite's ``__del__`` of an object whose
    construction a Ctrl-C cut short (numba compiling): ``AttributeError: ... no attribute
    '_as_parameter_'``, printed with a traceback while the process ends after the interrupt."""
    obj = getattr(args, "object", None)
    return (isinstance(args.exc_value, AttributeError)
            and "_as_parameter_" in str(args.exc_value)
            and str(getattr(obj, "__module__", "") or "").startswith("llvmlite"))


def raise_pending_interrupt() -> None:
    """Raise KeyboardInterrupt if a Ctrl-C arrived and was swallowed on the way."""
    if _INTERRUPT["pending"]:
        _INTERRUPT["redeliver"] = False
        raise KeyboardInterrupt


def _say_interrupted() -> None:
    """Print the interruption line and exit with status 130.

    If the Ctrl-C landed while Python ran ``exec`` on a string (``dataclasses`` does this when a
    module defines a dataclass, so it happens during imports), CPython remembers an "unhandled"
    KeyboardInterrupt and, after a clean shutdown, ends the process by SIGINT instead of with
    status 130. A shell reports both as ``$? = 130``; a parent process sees return code -2.
    """
    err_console.print("[yellow]interrupted[/yellow]: finished results and caches are "
                      "kept; re-run the same command to continue.", soft_wrap=True)
    raise typer.Exit(130) from None


#: ``errno`` values of a full disk or an exhausted quota.
_FULL_DISK = frozenset(getattr(errno, name) for name in ("ENOSPC", "EDQUOT")
                       if hasattr(errno, name))


def handle_errors(fn: F) -> F:
    """Turn geardyn errors into one clear line and exit code 2 (130 on Ctrl-C)."""

    @functools.wraps(fn)
    def wrapper(*args: Any, **kwargs: Any) -> Any:
        import signal
        import threading

        old = None
        old_hook = sys.unraisablehook
        if threading.current_thread() is threading.main_thread():
            _INTERRUPT["pending"] = False
            old = signal.signal(signal.SIGINT, _on_sigint)
            sys.unraisablehook = _unraisable(old_hook)
        try:
            return fn(*args, **kwargs)
        except typer.Exit:
            raise
        except GeardynError as exc:
            if os.environ.get("GEARDYN_DEBUG"):
                raise
            err_console.print(f"[bold red]error:[/bold red] {escape(one_line(str(exc)))}",
                              highlight=False, soft_wrap=True)
            raise typer.Exit(2) from None
        except KeyboardInterrupt:
            _INTERRUPT["redeliver"] = False  # raised: a delivery still due would raise it again
            _say_interrupted()
        except Exception as exc:  # a bug: say so briefly, keep the traceback for GEARDYN_DEBUG
            if (isinstance(exc, OSError) and exc.errno in _FULL_DISK
                    and not os.environ.get("GEARDYN_DEBUG")):
                # the machine's, not geardyn's (it read "a bug in geardyn", a user audit of
                # 2026-11-27); every output is written to a temporary file first: none is torn
                where = f" (writing {exc.filename})" if exc.filename else ""
                err_console.print(f"[bold red]error:[/bold red] "
                                  f"{escape(one_line((exc.strerror or str(exc)) + where))}: free "
                                  "some space (geardyn's cache: 'geardyn cache info', 'geardyn "
                                  "cache clear') and run the same command again",
                                  highlight=False, soft_wrap=True)
                raise typer.Exit(1) from None
            if _INTERRUPT["pending"]:
                _INTERRUPT["redeliver"] = False
                # a Ctrl-C that landed inside an import which was failing anyway comes out as
                # CPython's "TypeError: expected a message argument" (the ImportError's message
                # could not be built with the interrupt pending): still the user's Ctrl-C
                _say_interrupted()
            if os.environ.get("GEARDYN_DEBUG"):
                raise
            text = one_line(f"{type(exc).__name__}: {exc}", MAX_ERROR_CHARS - 90)
            err_console.print(f"[bold red]internal error:[/bold red] {escape(text)} (a bug in "
                              "geardyn; GEARDYN_DEBUG=1 shows the traceback)", highlight=False,
                              soft_wrap=True)
            raise typer.Exit(1) from None
        finally:
            if old is not None:
                signal.signal(signal.SIGINT, old)
                # after an interrupt the half-built llvmlite objects are collected as the
                # process ends: the hook that keeps their __del__ quiet stays
                if not _INTERRUPT["pending"]:
                    sys.unraisablehook = old_hook
            _INTERRUPT["pending"] = _INTERRUPT["redeliver"] = False

    return wrapper  # type: ignore[return-value]


def progress_bar():
    """A rich progress display for long stages (writes to stderr, hidden when not a terminal
    unless ``GEARDYN_PROGRESS=1``).

    Its columns fit an 80-column terminal: the description is cut with an ellipsis, never
    wrapped. Tasks take a ``count`` field (the text shown as "done/total"); :class:`StageProgress`
    on top of it turns a library ``progress(stage, done, total)`` callback into one bar per stage.
    """
    from rich.progress import (
        BarColumn,
        Progress,
        TextColumn,
        TimeElapsedColumn,
        TimeRemainingColumn,
    )
    from rich.table import Column

    disable = not (err_console.is_terminal or os.environ.get("GEARDYN_PROGRESS"))
    return Progress(
        TextColumn("[bold]{task.description}",
                   table_column=Column(width=30, no_wrap=True, overflow="ellipsis")),
        BarColumn(bar_width=16),
        _CountColumn(table_column=Column(width=13, no_wrap=True, justify="right")),
        TimeElapsedColumn(), TimeRemainingColumn(), console=err_console, disable=disable,
        transient=False, expand=False)


def _count_text(task) -> str:
    """A task's ``count`` field, else ``done/total`` (``done`` alone without a total)."""
    if "count" in task.fields:
        return str(task.fields["count"])
    done = int(task.completed)
    return f"{done}/{int(task.total)}" if task.total else (str(done) if done else "")


def _make_count_column():
    from rich.progress import ProgressColumn
    from rich.text import Text

    class CountColumn(ProgressColumn):
        """``done/total`` of a task, or its ``count`` field (see :class:`StageProgress`)."""

        def render(self, task):
            return Text(_count_text(task), style="progress.download", justify="right")

    return CountColumn


def _CountColumn(**kw):  # noqa: N802 - a column factory (rich is imported lazily)
    return _make_count_column()(**kw)


class StageProgress:
    """A ``progress(stage, done, total)`` callback drawing one bar per stage on a
    :func:`progress_bar`.

    Each distinct stage gets its own bar with its own count ("11/11"), so a stage never shows
    another stage's count; when a new stage starts, the previous bar is shown finished. A
    ``total`` of 0 or None is a step without a count (no "0/0"). Text after ": " in ``stage`` is
    the bar's current item and does not start a new bar (``"simulation: model II, cracked"``
    updates the ``simulation`` bar).

    ``stages`` names a pipeline's top-level stages: a call ``(name, i, len(stages))`` announces
    stage ``name`` (it is not a count of that stage). An announced stage gets a bar of its own
    only if no sub-stage bar replaces it (``"stiffness"`` is shown by its ``"stiffness (healthy)"``
    and ``"stiffness (cracked)"`` bars); ``"done"`` ends the pipeline.

    If ``$GEARDYN_TEST_READY_FILE`` is set, each stage's name is appended to that file as the
    stage starts (the interrupt tests wait on it instead of sleeping).
    """

    def __init__(self, bar, prefix: str = "", stages: tuple[str, ...] = ()):
        self.bar = bar
        self.prefix = prefix
        self.stages = tuple(stages)
        self.tasks: dict[str, Any] = {}
        self.totals: dict[str, int] = {}
        self.updated: set[str] = set()
        self.current: str | None = None
        self.ready_file = os.environ.get("GEARDYN_TEST_READY_FILE")

    def __call__(self, stage: str, done: int = 0, total: int | None = None) -> None:
        raise_pending_interrupt()
        key, _, item = str(stage).partition(": ")
        total = int(total) if total else 0
        announce = bool(self.stages) and not item and total == len(self.stages) and (
            key in self.stages or key == "done")
        if announce and key == "done":
            self.close()
            return
        if announce:
            self._start(key, f"{self.prefix}{key}", 0)
            self._touch(key)
            return
        label = f"{self.prefix}{key}" + (f": {item}" if item else "")
        if self._start(key, label, total):
            self._touch(key)
        self.totals[key] = total
        self.updated.add(key)
        self.bar.update(self.tasks[key], description=label, completed=done,
                        total=total or None, count=f"{done}/{total}" if total else "")

    def _start(self, key: str, label: str, total: int) -> bool:
        """Make ``key`` the current bar; True if it is new."""
        if key == self.current:
            return False
        cur = self.current
        if cur is not None and cur in self.stages and cur not in self.updated \
                and key not in self.stages:
            # an announced stage shown by its sub-stages' bars: drop its own empty bar
            self.bar.remove_task(self.tasks.pop(cur))
            self.current = None
        self._finish_current()
        self.current = key
        if key in self.tasks:
            return False
        self.tasks[key] = self.bar.add_task(label, total=total or None, count="")
        self.totals[key] = total
        return True

    def stage(self, name: str) -> Callable[[int, int], None]:
        """A ``progress(done, total)`` callback for one named stage."""
        return lambda done, total: self(name, done, total)

    def _finish_current(self) -> None:
        key, self.current = self.current, None
        if key is None or key not in self.tasks:
            return
        task, total = self.tasks[key], self.totals.get(key, 0)
        label = f"{self.prefix}{key}"
        if total:
            self.bar.update(task, description=label, completed=total, count=f"{total}/{total}")
        else:
            self.bar.update(task, description=label, total=1, completed=1, count="done")
        self.bar.stop_task(task)

    def close(self) -> None:
        """Show the last stage finished (call it when the work succeeded)."""
        self._finish_current()

    def _touch(self, key: str) -> None:
        if self.ready_file:
            with contextlib.suppress(OSError), open(self.ready_file, "a", encoding="utf-8") as fh:
                fh.write(key + "\n")


def warning_line(message, category, filename=None, lineno=None, file=None, line=None) -> None:
    """A :func:`warnings.showwarning` replacement: one clean line on stderr (no source path, no
    code), e.g. ``warning: Sainsot's fit is used outside its range ...``."""
    name = getattr(category, "__name__", "Warning")
    tag = "warning" if name in ("UserWarning", "Warning") else f"warning ({name})"
    err_console.print(f"[yellow]{tag}[/yellow]: {escape(one_line(str(message)))}",
                      highlight=False, soft_wrap=True)


def exit_code_of(exc: BaseException) -> int:  # pragma: no cover - helper for scripts
    """Exit status geardyn uses for an exception."""
    return 2 if isinstance(exc, GeardynError) else (130 if isinstance(exc, KeyboardInterrupt)
                                                    else 1)


def eprint(*args: Any) -> None:
    """Print to stderr without markup."""
    print(*args, file=sys.stderr)
