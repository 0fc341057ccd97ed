"""Warnings of concurrent runs in one threaded worker are recorded with the run that raised them
(issue 19: ``warnings.catch_warnings`` is process-wide, so two runs in threads swapped or lost
each other's warnings)."""

from __future__ import annotations

import threading
import warnings

import geardyn
from geardyn._thread_warnings import thread_warnings
from geardyn.studies.sweep.execute import _evaluate_one


def _in_threads(*targets):
    out = [None] * len(targets)

    def call(i, fn):
        out[i] = fn()

    threads = [threading.Thread(target=call, args=(i, fn)) for i, fn in enumerate(targets)]
    for t in threads:
        t.start()
    for t in threads:
        t.join(60)
    return out


def test_two_runs_in_threads_record_only_their_own_warnings():
    """Both runs are inside the recorder when both warn (a barrier orders it, no timing): each
    record names exactly its own warning, raised twice from the same line (not deduplicated
    away by the 'default' filter's once-per-location registry)."""
    case = geardyn.paper_case()
    inside, warned = threading.Barrier(2, timeout=30), threading.Barrier(2, timeout=30)

    def evaluator(name):
        def ev(case, seed):
            inside.wait()
            for _ in range(2):
                warnings.warn(f"from run {name}", RuntimeWarning, stacklevel=1)
            warned.wait()
            raise ValueError(f"run {name} stops here")
        return ev

    a, b = _in_threads(lambda: _evaluate_one(case, {}, evaluator("A"), 0, ()),
                       lambda: _evaluate_one(case, {}, evaluator("B"), 0, ()))
    assert a.warning == "RuntimeWarning: from run A"
    assert b.warning == "RuntimeWarning: from run B"
    assert "run A stops here" in a.error and "run B stops here" in b.error


def test_the_recorder_restores_the_process_state_and_nests():
    before_filters, before_hook = list(warnings.filters), warnings.showwarning
    with thread_warnings() as outer:
        warnings.warn("outer", UserWarning, stacklevel=1)
        with thread_warnings() as inner:
            warnings.warn("inner", UserWarning, stacklevel=1)
        warnings.warn("outer again", UserWarning, stacklevel=1)
    assert [str(w.message) for w in outer] == ["outer", "outer again"]
    assert [str(w.message) for w in inner] == ["inner"]
    assert warnings.filters == before_filters and warnings.showwarning is before_hook


def test_a_thread_without_a_recorder_is_not_recorded(monkeypatch):
    """A thread outside any recorder keeps the usual warning path (here a stand-in hook)."""
    shown = []
    monkeypatch.setattr(warnings, "showwarning",
                        lambda message, *args, **kw: shown.append(str(message)))
    inside, warned = threading.Event(), threading.Event()

    def other():
        inside.wait(30)
        warnings.warn("not mine", UserWarning, stacklevel=1)
        warned.set()

    t = threading.Thread(target=other)
    t.start()
    with thread_warnings() as mine:
        inside.set()
        warned.wait(30)
        warnings.warn("mine", UserWarning, stacklevel=1)
    t.join(30)
    assert [str(w.message) for w in mine] == ["mine"]
    assert shown == ["not mine"]
