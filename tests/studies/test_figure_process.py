"""Report figures drawn by a second process (issue 16.6, :mod:`geardyn.studies.figure_process`):
the same PNG bytes as drawn here, through the figure cache; held until the process may start;
whatever the process does not draw (not started, failed, broken, stopped) drawn here."""

from __future__ import annotations

import os

import matplotlib

matplotlib.use("Agg")

import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402
import pytest  # noqa: E402

from geardyn.studies.figure_process import FigureProcess, figure_process_allowed  # noqa: E402
from geardyn.studies.paper_result import (  # noqa: E402
    IN_FLIGHT,
    FigureStore,
    RenderedFigure,
    render_png,
)

#: the figures this process drew (the worker's own list is another one, in another process)
CALLS: list = []


def draw(y, *, title="t"):
    CALLS.append(title)
    fig, ax = plt.subplots(figsize=(2.5, 2), layout="constrained")
    ax.plot(np.asarray(y))
    ax.set_title(title)
    ax.set_xlabel("sample")
    return fig


def draw_or_fail(y, *, title="t"):
    if title == "bad":
        raise ValueError("cannot draw 'bad'")
    return draw(y, title=title)


def draw_mapped(y, f, *, title="t"):
    return draw(f(np.asarray(y)), title=title)


def _expected(y, title):
    png = render_png(draw(y, title=title))
    CALLS.pop()
    return png


TITLES = [f"figure {i}" for i in range(8)]


def test_the_process_draws_the_same_pngs_and_the_cache_keeps_them(tmp_path, monkeypatch):
    monkeypatch.setenv("GEARDYN_CACHE_DIR", str(tmp_path / "cache"))
    CALLS.clear()
    y = np.sin(np.linspace(0.0, 6.0, 200))
    ready = {"now": False}
    store = FigureStore(FigureProcess(ready=lambda: ready["now"]))
    store.cached("f0", draw, y, title=TITLES[0])
    store.cached("f1", draw, y, title=TITLES[1])
    assert not store.process.started                   # held while ready() says no
    ready["now"] = True
    for i, title in enumerate(TITLES[2:], start=2):
        store.cached(f"f{i}", draw, y, title=title)    # the held two go first
    assert store.process.started and CALLS == []
    assert len(store) == len(TITLES)
    assert store._in_flight <= IN_FLIGHT               # the rest wait as they are, not pickled
    store["f0"]                                        # waits for the process to draw it
    store.finish()                                     # this process takes the unstarted ones
    assert store.process is None
    assert TITLES[0] not in CALLS
    # whatever this process drew, it drew from the last figure back
    assert CALLS == TITLES[len(TITLES) - len(CALLS):][::-1]
    for i, title in enumerate(TITLES):
        assert isinstance(store[f"f{i}"], RenderedFigure)
        assert store[f"f{i}"].png == _expected(y, title), title
    # collected into the figure cache: a store without a process draws none of them again
    CALLS.clear()
    again = FigureStore()
    for i, title in enumerate(TITLES):
        again.cached(f"f{i}", draw, y, title=title)
        assert again[f"f{i}"].png == store[f"f{i}"].png
    assert CALLS == []
    assert len(list((tmp_path / "cache" / "figure").glob("*.png"))) == len(TITLES)


def test_what_the_process_does_not_draw_is_drawn_here(tmp_path, monkeypatch):
    """Never ready: all drawn here. A figure whose drawing fails there is drawn here and raises
    here. Arguments that do not pickle: drawn here, the figures after it still go. A worker
    killed mid-run: the rest drawn here. Stopped with figures queued: those too. ``cached_here``
    never goes to the process."""
    import multiprocessing

    monkeypatch.setenv("GEARDYN_CACHE_DIR", str(tmp_path / "cache"))
    y = np.cos(np.linspace(0.0, 3.0, 50))

    CALLS.clear()
    never = FigureStore(FigureProcess(ready=lambda: False))
    for title in TITLES[:3]:
        never.cached(title, draw, y, title=title)
    never.cached_here("here", draw, y, title="here")
    assert CALLS == ["here"]
    assert [t for t in never] == [*TITLES[:3], "here"]
    assert {k: v.png for k, v in never.items()} == {t: _expected(y, t)
                                                    for t in [*TITLES[:3], "here"]}
    assert CALLS == ["here", *reversed(TITLES[:3])]     # drawn here, from the last one back

    monkeypatch.setenv("GEARDYN_NO_CACHE", "1")         # every figure goes to the process
    CALLS.clear()
    failing = FigureStore(FigureProcess())
    failing.cached("bad", draw_or_fail, y, title="bad")
    failing.cached("good", draw_or_fail, y, title="good")
    with pytest.raises(ValueError, match="cannot draw 'bad'"):
        failing["bad"]                                   # failed there, drawn (and failed) here
    assert failing["good"].png == _expected(y, "good")

    CALLS.clear()
    unpicklable = FigureStore(FigureProcess())
    unpicklable.cached("lambda", draw_mapped, y, lambda v: 2.0 * v, title="lambda")
    unpicklable.cached("after it", draw, y, title="after it")
    assert unpicklable["after it"].png == _expected(y, "after it")
    assert CALLS == []                                   # not held up: drawn by the process
    assert unpicklable["lambda"].png == render_png(draw(2.0 * y, title="lambda"))
    assert CALLS == ["lambda", "lambda"]                 # the lambda's figure drawn here
    unpicklable.finish()

    before = set(multiprocessing.active_children())
    broken = FigureStore(FigureProcess())
    broken.cached("a", draw, y, title="a")
    broken["a"]                                          # drawn by the process
    (worker,) = set(multiprocessing.active_children()) - before
    worker.kill()
    worker.join(timeout=30)
    for title in ("b", "c"):
        broken.cached(title, draw, y, title=title)
    broken.finish()
    assert [broken[t].png for t in "abc"] == [_expected(y, t) for t in "abc"]

    stopped = FigureStore(FigureProcess())
    for title in TITLES:
        stopped.cached(title, draw, y, title=title)
    stopped.close()                                      # e.g. Ctrl-C: the queue dropped
    assert stopped.process is None
    CALLS.clear()
    stopped.finish()                                     # the held ones drawn here, last first
    held = TITLES[IN_FLIGHT:]
    assert CALLS[:len(held)] == held[::-1]
    assert set(CALLS[len(held):]) <= set(TITLES[:IN_FLIGHT])   # the sent ones, if dropped
    assert [stopped[t].png for t in TITLES] == [_expected(y, t) for t in TITLES]


def test_who_may_have_a_figure_process(monkeypatch):
    import multiprocessing

    from geardyn.stiffness.fe.background import FE_PROCESSES_ENV
    from geardyn.studies.paper import _figure_process
    from geardyn.studies.paper_result import StudyResult

    monkeypatch.setenv(FE_PROCESSES_ENV, "0")
    assert not figure_process_allowed()
    assert _figure_process(StudyResult(out=".")) is None
    monkeypatch.setenv(FE_PROCESSES_ENV, "1")
    assert figure_process_allowed()
    result = StudyResult(out=".")
    proc = _figure_process(result)
    assert isinstance(proc, FigureProcess) and not proc.started

    class Alive:
        def is_alive(self):
            return True

    result.background.append(Alive())   # e.g. the FE bodies' process: not yet
    assert proc.submit(draw, (np.arange(3.0),), {}) is None and not proc.started

    class Daemon:
        daemon = True

    with monkeypatch.context() as m:
        m.setattr(multiprocessing, "current_process", lambda: Daemon())
        assert not figure_process_allowed()   # a pool's worker may not have children
    monkeypatch.setenv(FE_PROCESSES_ENV, "2")
    with pytest.raises(ValueError, match=FE_PROCESSES_ENV):
        figure_process_allowed()
    assert os.environ[FE_PROCESSES_ENV] == "2"


def _raw(store, key):
    """The store's entry for ``key`` as it is (a pending figure is not collected)."""
    return dict.__getitem__(store, key)


def _wait(predicate, what, timeout=60.0):
    import time

    t0 = time.monotonic()
    while not predicate():
        assert time.monotonic() - t0 < timeout, what
        time.sleep(0.01)


def draw_sigint_state():
    """A figure titled by how the process that draws it treats Ctrl-C."""
    import signal

    ignored = signal.getsignal(signal.SIGINT) == signal.SIG_IGN
    return draw([0.0, 1.0], title="SIGINT ignored" if ignored else "SIGINT not ignored")


def draw_when_released(path, *, title="slow"):
    """A figure drawn once the file ``path`` exists (at most a minute later)."""
    import time

    t0 = time.monotonic()
    while not os.path.exists(path) and time.monotonic() - t0 < 60.0:
        time.sleep(0.01)
    return draw([0.0, 1.0], title=title)


def test_one_spawned_worker_that_ignores_ctrl_c_and_close_does_not_wait(tmp_path):
    """Mutation testing (2026-11-26) found these unchecked: the pool has one worker, spawned
    (not forked from a process with threads), which ignores Ctrl-C even when the pool was
    started outside the main thread (where the parent cannot ignore it while starting);
    ``close()`` neither waits for the figure being drawn nor lets the queued ones run, and a
    closed process starts no new worker."""
    import threading
    import time

    proc = FigureProcess()
    box = {}
    starter = threading.Thread(target=lambda: box.update(
        first=proc.submit(draw_sigint_state, (), {})))
    starter.start()
    starter.join()
    assert box["first"].result(timeout=120) == _expected([0.0, 1.0], "SIGINT ignored")
    assert proc._pool._max_workers == 1
    assert proc._pool._mp_context.get_start_method() == "spawn"
    t0 = time.monotonic()
    while box["first"] in proc._futures:   # a drawn figure's PNG is not kept here
        assert time.monotonic() - t0 < 5.0
        time.sleep(0.01)

    release = tmp_path / "release"
    slow = proc.submit(draw_when_released, (str(release),), {})
    more = [proc.submit(draw, ([1.0, float(i)],), {"title": f"queued {i}"}) for i in range(4)]
    # while the worker draws the slow figure, the pool moves one or two more into the worker's
    # queue (their futures marked running: drawn anyway) and nothing else moves; the others
    # wait in the pool (pending): those close() drops
    state = {"running": -1, "since": time.monotonic()}

    def settled() -> bool:
        n = sum(f.running() for f in more)
        if n != state["running"]:
            state.update(running=n, since=time.monotonic())
        return slow.running() and n >= 1 and time.monotonic() - state["since"] > 0.5

    _wait(settled, "the worker did not take the slow figure")
    pending = [f for f in more if not f.running() and not f.done()]
    assert len(pending) >= 2
    t0 = time.monotonic()
    proc.close()
    assert time.monotonic() - t0 < 5.0   # it does not wait for the figure being drawn
    release.touch()
    assert all(f.cancelled() for f in pending)
    assert proc.submit(draw, ([1.0],), {}) is None and not proc.started


def test_a_worker_that_cannot_start_or_has_broken_is_not_asked_again(monkeypatch):
    """Once the pool cannot be started, or is broken, every later figure is drawn here at once:
    no new start (seconds each) and no new submit per figure."""
    import concurrent.futures

    from geardyn.studies.figure_process import NotPicklable

    starts = []

    def no_pool(*args, **kwargs):
        starts.append(kwargs)
        raise OSError("no process to be had")

    monkeypatch.setattr(concurrent.futures, "ProcessPoolExecutor", no_pool)
    proc = FigureProcess()
    assert proc.submit(draw, ([1.0],), {}) is None
    assert proc.submit(draw, ([2.0],), {}) is None
    assert len(starts) == 1 and not proc.started

    class Broken:
        submits = 0

        def submit(self, *args):
            Broken.submits += 1
            raise RuntimeError("A process in the process pool was terminated abruptly")

        def shutdown(self, **kwargs):
            pass

    proc = FigureProcess()
    proc._pool = Broken()
    assert proc.submit(draw, ([1.0],), {}) is None
    assert proc.submit(draw, ([2.0],), {}) is None
    assert Broken.submits == 1

    with pytest.raises(NotPicklable) as info:   # says what pickle said, by its type
        FigureProcess().submit(lambda: None, (), {})
    cause = info.value.__cause__
    assert str(info.value) == f"{type(cause).__name__}: {cause}"


def test_the_window_of_figures_in_flight_and_what_is_let_go(tmp_path, monkeypatch):
    """Mutation testing (2026-11-26): nothing checked that the process is kept at
    :data:`IN_FLIGHT` figures, that each one drawn lets the next go (without this process asking),
    that a drawn figure's arguments are let go, that a figure drawn here while held is not sent
    as well, that an unpicklable figure does not stop the ones behind it, or that ``finish``
    and reading a figure leave no figure pending."""
    monkeypatch.setenv("GEARDYN_NO_CACHE", "1")
    y = np.linspace(0.0, 1.0, 30)
    CALLS.clear()

    store = FigureStore(FigureProcess())
    for title in TITLES[:6]:
        store.cached(title, draw, y, title=title)
    assert store._in_flight == IN_FLIGHT and len(store._held) == 6 - IN_FLIGHT
    _wait(lambda: all(_raw(store, t).future is not None and _raw(store, t).future.done()
                      for t in TITLES[:6]), "the process did not draw every figure by itself")
    _wait(lambda: store._in_flight == 0, "a drawn figure was not counted out")
    assert not store._held and CALLS == []
    for title in TITLES[:6]:
        job = _raw(store, title)
        assert job.args == () and job.kwargs == {}   # let go once drawn
    assert store.get(TITLES[0]).png == _expected(y, TITLES[0])
    assert isinstance(_raw(store, TITLES[0]), RenderedFigure) and None not in store
    assert store.get("no such figure", "default") == "default"
    store.finish()
    assert all(isinstance(v, RenderedFigure) for v in dict.values(store))

    ready = {"now": False}
    held = FigureStore(FigureProcess(ready=lambda: ready["now"]))
    held.cached("here", draw, y, title="here")
    held.cached("lambda", draw_mapped, y, lambda v: v + 1.0, title="lambda")
    held.cached("behind", draw, y, title="behind")
    assert held["here"].png == _expected(y, "here")   # drawn here, while held
    ready["now"] = True
    held.cached("last", draw, y, title="last")
    # "here" is not sent again; "lambda" cannot be sent; "behind" and "last" go
    assert not held._held and held._in_flight == 2
    assert _raw(held, "behind").future is not None and _raw(held, "lambda").future is None
    held.finish()
    assert CALLS == ["here", "lambda"]
    assert all(isinstance(v, RenderedFigure) for v in dict.values(held))
    assert held["lambda"].png == render_png(draw(y + 1.0, title="lambda"))


def test_a_figure_another_store_has_cached_meanwhile_is_read_from_the_cache(tmp_path,
                                                                            monkeypatch):
    """Two stores hand the same figure to their processes; the first to collect it fills the
    figure cache, the second reads it from there; a third store finds it cached when handed
    the figure and starts no process at all."""
    monkeypatch.setenv("GEARDYN_CACHE_DIR", str(tmp_path / "cache"))
    y = np.linspace(0.0, 2.0, 40)
    a, b = FigureStore(FigureProcess()), FigureStore(FigureProcess())
    a.cached("f", draw, y, title="shared")
    b.cached("f", draw, y, title="shared")
    from geardyn.cache import record_lookups

    png = a["f"].png
    with record_lookups() as lookups:
        assert b["f"].png == png
    assert [(r["kind"], r["hit"]) for r in lookups] == [("figure", True)]
    a.finish()
    b.finish()
    c = FigureStore(FigureProcess())
    with record_lookups() as lookups:
        c.cached("f", draw, y, title="shared")
    assert not c.process.started and isinstance(_raw(c, "f"), RenderedFigure)
    assert [(r["kind"], r["hit"]) for r in lookups] == [("figure", True)]
    assert c["f"].png == png


def draw_slow_here(y, here: int, *, title="t"):
    """:func:`draw`, 0.6 s slower in the process ``here`` (the test's) than in the worker."""
    import time

    if os.getpid() == here:
        time.sleep(0.6)
    return draw(y, title=title)


def test_at_finish_the_process_gets_one_figure_at_a_time(monkeypatch):
    """While ``finish`` draws the held figures here, the process is sent the next figure only
    once it has drawn the last (:data:`IN_FLIGHT_AT_FINISH`): no figure waits in its queue
    while this process, out of figures, waits for it. Each figure takes 0.6 s longer here,
    so the worker finishes its two in flight while this process draws; with the window left at
    :data:`IN_FLIGHT`, the first of them drawn lets another go at once."""
    monkeypatch.setenv("GEARDYN_NO_CACHE", "1")
    y = np.linspace(0.0, 1.0, 30)
    store = FigureStore(FigureProcess())
    store.cached("warm", draw, y, title="warm")
    store["warm"]                             # the worker is up and has drawn a figure
    sent_at: list = []
    submit = store.process.submit

    def counting_submit(*args, **kwargs):
        sent_at.append(store._in_flight)       # (called under the store's lock)
        return submit(*args, **kwargs)

    store.process.submit = counting_submit
    titles = TITLES[:6]
    for title in titles:
        store.cached(title, draw_slow_here, y, os.getpid(), title=title)
    assert sent_at == [0, 1] and len(store._held) == 4
    del sent_at[:]
    store.finish()
    assert sent_at and set(sent_at) == {0}, sent_at   # sent to the worker, one at a time
    for title in titles:
        assert store[title].png == _expected(y, title)


def test_start_early_starts_the_process_at_the_first_poll_it_may(monkeypatch):
    """``start_early`` lets ``poll`` (each progress report of a study) start the worker as
    soon as ``ready()`` allows, with the held figures or, with none, on its imports; without
    it, or while ``ready()`` says no, nothing starts; ``StudyResult.emit`` polls."""
    import time

    from geardyn.studies.paper_result import StudyResult

    monkeypatch.setenv("GEARDYN_NO_CACHE", "1")
    gate = {"open": False}
    store = FigureStore(FigureProcess(ready=lambda: gate["open"]))
    gate["open"] = True
    store.poll()
    assert not store.process.started            # not asked to start early
    gate["open"] = False
    store.start_early()
    store.poll()
    assert not store.process.started            # not ready
    gate["open"] = True
    store.poll()
    assert not store.process.started            # asked again 50 ms later at the soonest
    time.sleep(0.06)
    result = StudyResult(out=None, figures=store)
    result.emit("stage", 0, 1)                  # a progress report polls
    assert store.process.started
    started = store.process._pool
    store.poll()
    assert store.process._pool is started       # one worker
    y = np.linspace(0.0, 1.0, 30)
    store.cached("f", draw, y, title="f")
    assert store["f"].png == _expected(y, "f")
    store.finish()

    held = FigureStore(FigureProcess(ready=lambda: gate["open"]))
    gate["open"] = False
    held.cached("h", draw, y, title="h")        # held: not ready
    held.start_early()
    gate["open"] = True
    held.poll()
    assert held.process.started and held._in_flight == 1 and not held._held
    assert held["h"].png == _expected(y, "h")
    held.finish()

    none = FigureStore()                        # no figure process: nothing to start
    none.start_early()
    none.poll()
    assert none.process is None


def test_start_early_stops_asking_once_the_process_could_not_start(monkeypatch):
    """A worker that could not be started is not asked again at each later progress report
    (``poll`` stops; the figures are drawn here), and a ``ready()`` that says no is asked
    again."""
    import time

    monkeypatch.setenv("GEARDYN_NO_CACHE", "1")
    asked = {"n": 0, "open": False}

    def ready():
        asked["n"] += 1
        return asked["open"]

    proc = FigureProcess(ready=ready)
    monkeypatch.setattr(proc, "_start", lambda fn, *a: setattr(proc, "_failed", True))
    store = FigureStore(proc)
    store.start_early()
    store.poll()
    assert asked["n"] >= 1 and store._early     # not ready: asked again later
    asked["open"] = True
    time.sleep(0.06)
    store.poll()                                # ready, but the start fails
    assert proc.failed and not proc.started and not store._early
    n = asked["n"]
    time.sleep(0.06)
    store.poll()
    assert asked["n"] == n                      # not asked again
    y = np.linspace(0.0, 1.0, 30)
    store.cached("f", draw, y, title="f")       # drawn here
    assert store["f"].png == _expected(y, "f")


def test_what_the_study_hands_over_draws_without_xarray_or_the_case_models(tmp_path):
    """The figure process imports what drawing needs, not what the study's objects would pull
    in: the figures as the study hands them over (Figs. 5-6 by module and name, Fig. 8 from a
    record's arrays, Fig. 11 from diagnoses), pickled here, are unpickled and drawn by
    :func:`~geardyn.studies.figure_process.draw_png` in a fresh interpreter that then holds
    neither xarray, pandas nor pydantic (together about 60 MB and 0.4 s there; it imported
    all three until 2026-11-27, through a record passed as a Dataset and a class of the study
    module). The same PNG bytes as drawn here."""
    import math
    import pickle
    import subprocess
    import sys

    import xarray as xr

    from geardyn.diagnostics import diagnose
    from geardyn.studies import paper_figures as pf
    from geardyn.studies.figure_process import draw_png
    from geardyn.studies.paper import FIG8_VARIABLES, _variables
    from geardyn.studies.paper_result import ImportedOnCall

    w, fs, z = 114.14, 20000.0, 23
    t = np.arange(int(6 * 2 * np.pi / w * fs)) / fs
    theta = w * t
    pulse = np.exp(-0.5 * ((np.mod(theta, 2 * np.pi) - 3.0) / 0.02) ** 2)
    record = xr.Dataset({name: ("time", 1.0 + 0.01 * np.cos(z * theta) + 0.001 * k * pulse)
                         for k, name in enumerate(FIG8_VARIABLES)} | {"theta_p": ("time", theta)},
                        coords={"time": t})
    signals = {"v_yg": 0.01 * np.cos(z * theta) + 0.003 * pulse,
               "omega_p": w + 0.1 * np.cos(z * theta),
               "transmission_error": 0.05 + 1e-5 * pulse}
    diagnosis = diagnose(signals, teeth=z, time=t, angle=theta, samples_per_rev=256)
    curves = {"x": np.linspace(0.0, 1.0, 50), "xlabel": "x [-]", "ylabel": "y [-]",
              "title": "curves", "lines": [{"y": np.linspace(0.0, 2.0, 50), "label": "a"}]}
    jobs = [(ImportedOnCall("geardyn.line_figure", "draw_line_figure"), (curves,), {}),
            (pf.fig8_design_parameters, (_variables(record, FIG8_VARIABLES), 3.0, (0.0, 0.2)),
             {"fault": "crack", "period": 2 * math.pi}),
            (pf.fig_tsa, ({"I": diagnosis, "II": diagnosis},), {})]
    expected = [draw_png(draw, args, kwargs) for draw, args, kwargs in jobs]
    (tmp_path / "jobs.pkl").write_bytes(pickle.dumps(jobs, protocol=pickle.HIGHEST_PROTOCOL))
    code = (
        "import pickle, sys\n"
        "from geardyn.studies.figure_process import _warm_up, draw_png\n"
        "_warm_up()\n"
        "jobs = pickle.loads(open(sys.argv[1], 'rb').read())\n"
        "pngs = [draw_png(d, a, k) for d, a, k in jobs]\n"
        "open(sys.argv[2], 'wb').write(pickle.dumps(pngs))\n"
        "print(' '.join(m for m in ('xarray', 'pandas', 'pydantic') if m in sys.modules))\n")
    out = subprocess.run([sys.executable, "-c", code, str(tmp_path / "jobs.pkl"),
                          str(tmp_path / "pngs.pkl")], capture_output=True, text=True,
                         timeout=300, env={**os.environ, "MPLBACKEND": "Agg"})
    assert out.returncode == 0, out.stderr
    assert out.stdout.strip() == "", out.stdout
    assert pickle.loads((tmp_path / "pngs.pkl").read_bytes()) == expected


_LET_GO_CHILD = """
import gc, json, pickle, weakref
import matplotlib
matplotlib.use("Agg")
import matplotlib.pyplot as plt
from geardyn.studies import figure_process as fp

drawn = []

def draw(n):
    fig, ax = plt.subplots()
    ax.plot(range(n))
    drawn.append(weakref.ref(fig))
    return fig

gc.disable()  # no automatic collection: only the worker's own can free the figure's cycles
before = gc.get_freeze_count()
png = fp._draw_pickled(pickle.dumps((draw, (10,), {})))
print(json.dumps({"png": png[:8].hex(), "figure_alive": drawn[0]() is not None,
                  "frozen_before": before, "frozen_after": gc.get_freeze_count()}))
"""


def test_the_worker_lets_each_figure_go():
    """In the worker (a fresh interpreter here, as the worker is), a figure drawn through
    ``_draw_pickled`` is a PNG and is gone when the call returns: matplotlib's figure holds
    reference cycles that only a collection frees (the automatic one is switched off in the
    child), and what survives the collection is frozen for the next figure's."""
    import json
    import subprocess
    import sys

    out = subprocess.run([sys.executable, "-c", _LET_GO_CHILD], capture_output=True, text=True,
                         check=True, timeout=120)
    r = json.loads(out.stdout)
    assert r["png"] == b"\x89PNG\r\n\x1a\n".hex()
    assert r["figure_alive"] is False
    assert r["frozen_before"] == 0 and r["frozen_after"] > 0
