"""Warnings recorded per thread (a Dask worker runs several sweep runs at once in threads).

``warnings.catch_warnings`` swaps the process-wide ``warnings.showwarning`` and filter list, so two
threads inside it at once record each other's warnings, and the one that leaves first restores
the state under the other (the Python documentation says it is not thread-safe before 3.14's
context-aware warnings). Here one process-wide hook, installed once, sends each warning to the
recorder of the thread that raised it; a thread without a recorder gets the usual behaviour.
While any recorder is active an ``"always"`` filter sits at the front of the filter list (so a
warning repeated by a later run is recorded again), and it is removed when the last one ends.
"""

from __future__ import annotations

import contextlib
import threading
import warnings
from collections.abc import Iterator

_local = threading.local()
_lock = threading.Lock()
_active = 0
_original_showwarning = None
_ALWAYS = ("always", None, Warning, None, 0)


def _dispatch(message, category, filename, lineno, file=None, line=None):
    records = getattr(_local, "records", None)
    if records is None:
        _original_showwarning(message, category, filename, lineno, file, line)
    else:
        records.append(warnings.WarningMessage(message, category, filename, lineno, file, line))


@contextlib.contextmanager
def thread_warnings() -> Iterator[list[warnings.WarningMessage]]:
    """Record the warnings raised by the current thread inside the block.

    Yields
    ------
    list of warnings.WarningMessage
        Filled with every warning the current thread raises while the block runs (other
        threads' warnings are not in it); nothing is printed for them.
    """
    global _active, _original_showwarning
    outer = getattr(_local, "records", None)
    records: list[warnings.WarningMessage] = []
    with _lock:
        if _active == 0:
            _original_showwarning = warnings.showwarning
            warnings.showwarning = _dispatch
            warnings.simplefilter("always")  # public; also resets the "once" caches
        _active += 1
    _local.records = records
    try:
        yield records
    finally:
        _local.records = outer
        with _lock:
            _active -= 1
            if _active == 0:
                warnings.showwarning = _original_showwarning
                with contextlib.suppress(ValueError):  # nothing was cached under "always"
                    warnings.filters.remove(_ALWAYS)
