"""Report figures drawn by a second process while the study goes on (issue 16.6: "figures
rendered in parallel").

Drawing and saving its 22 figures was half of a cold ``geardyn run --quick`` (about 11 s of
21 s on the 2-core machine, measured 2026-11-26: 8.0 s in ``savefig`` alone). matplotlib holds
the interpreter lock, so a drawing thread gained nothing (measured and rejected); a second
process does. :class:`FigureProcess` is a one-worker, spawned process pool: the study hands it
each figure it would have drawn (the drawing function and its arguments, pickled) and goes on
with its own work; :meth:`.paper_result.FigureStore.finish` then collects the PNGs and draws
itself, from the end of the queue, every figure the worker has not started, so the two
processes meet in the middle instead of one waiting for the other.

The PNG bytes are the same as a figure drawn in this process (the same function, matplotlib
and fonts; ``tests/studies/test_figure_process.py``). The process is an accelerator only: a
figure it cannot draw (an error, a broken pool, arguments that do not pickle) is drawn again in
this process, which raises the error, if any, with its own traceback.

It costs memory: a second interpreter with matplotlib, SciPy's FFT and geardyn's drawing code
imported (84 MB; 140-170 MB at the end of a ``--quick`` run, with what it has drawn). What the
study hands over unpickles without xarray, pandas or the case models (records as arrays,
:class:`.paper_result.ImportedOnCall`): until 2026-11-27 they came with it, 40-60 MB more. It
is used where the FE bodies' second process would be
(:func:`geardyn.processes.fe_processes`: ``GEARDYN_FE_PROCESSES=0`` runs
everything in one process), not from a daemon process (a pool's worker may not have children),
and it starts only when ``ready()`` says so: the study waits until its other background
processes (the FE bodies, the kernel compiler) have ended, so that no more than two processes
are alive at once; figures handed over before then are held and sent when it starts. The study
asks again at each progress report (:meth:`.paper_result.FigureStore.poll`), so the worker
starts, and imports matplotlib (:meth:`FigureProcess.warm_up`), as soon as they have ended
rather than at the next figure.
"""

from __future__ import annotations

from collections.abc import Callable

__all__ = ["FigureProcess", "NotPicklable", "figure_process_allowed", "draw_png"]


class NotPicklable(TypeError):
    """A figure's drawing function or arguments do not pickle (a lambda, an open file...): the
    caller draws it itself."""


def figure_process_allowed() -> bool:
    """Whether a second process may draw figures: as for the FE bodies' second process
    (:func:`geardyn.processes.fe_processes`), and not from a daemon process.

    Raises
    ------
    geardyn.errors.InputError
        ``GEARDYN_FE_PROCESSES`` set to anything but 0 or 1.
    """
    import multiprocessing

    from ..processes import fe_processes

    return fe_processes() == 1 and not multiprocessing.current_process().daemon


def draw_png(draw: Callable, args: tuple, kwargs: dict) -> bytes:
    """``draw(*args, **kwargs)`` rendered to PNG bytes (:func:`.paper_result.render_png`); what
    the worker runs for each figure."""
    from .paper_result import render_png

    return render_png(draw(*args, **kwargs))


def _draw_pickled(payload: bytes) -> bytes:
    """In the worker: :func:`draw_png` of the pickled ``(draw, args, kwargs)``."""
    import pickle

    draw, args, kwargs = pickle.loads(payload)
    try:
        return draw_png(draw, args, kwargs)
    finally:
        _let_go()


def _let_go() -> None:
    """In the worker, after each figure: the figure's objects collected and their pages given
    back to the operating system (:func:`geardyn.heap.release_free_memory`), so that the worker
    does not grow with each figure while the study's process draws beside it (at the end of a
    ``geardyn run --quick`` the worker held 170 MB, 133 MB with this; 2026-11-28). What
    survives the collection (the imports, matplotlib's caches) is frozen (:func:`gc.freeze`),
    so the next figure's collection looks only at the objects made since: 15-19 ms a figure
    against 50-60 ms for a full collection (a 3 x 2 figure, measured 2026-11-28). A frozen
    object that becomes garbage later is not collected; the worker lives for one study."""
    import gc

    from ..heap import release_free_memory

    release_free_memory(collect=True)
    gc.freeze()


def _warm_up() -> None:
    """In the worker: import what drawing the report's figures imports (matplotlib, the figure
    modules), before the first figure comes."""
    import matplotlib.pyplot  # noqa: F401

    from . import paper_figures, paper_result  # noqa: F401


def _worker_init() -> None:
    """In the worker: Ctrl-C is the study's business (it stops the pool); the exit skips the
    garbage collector's last passes (:func:`geardyn.processes.skip_collection_at_exit`: the
    study's process waits for this one to end)."""
    import signal

    from ..processes import skip_collection_at_exit

    signal.signal(signal.SIGINT, signal.SIG_IGN)
    skip_collection_at_exit()


class FigureProcess:
    """A one-worker spawned process pool drawing figures (see the module docstring).

    Parameters
    ----------
    ready : callable, optional
        ``ready() -> bool``: whether the worker may be started now (default: always). Asked at
        each :meth:`submit` until it says yes.
    """

    def __init__(self, ready: Callable[[], bool] | None = None):
        self._ready = ready
        self._pool = None
        self._failed = False
        self._futures: set = set()  # submitted, not done: what close() drops

    def _track(self, future):
        """Keep ``future`` until it is done (:meth:`close` cancels those still waiting)."""
        self._futures.add(future)
        future.add_done_callback(self._futures.discard)  # (set.add/discard: atomic)
        return future

    @property
    def started(self) -> bool:
        """Whether the worker process has been started."""
        return self._pool is not None

    @property
    def failed(self) -> bool:
        """Whether the worker could not be started or has broken: it is not asked again."""
        return self._failed

    def submit(self, draw: Callable, args: tuple, kwargs: dict):
        """Hand ``draw(*args, **kwargs)`` to the worker.

        Returns
        -------
        concurrent.futures.Future or None
            The PNG bytes to come; None when the worker is not to be started yet (``ready()``
            said no), could not be started, or has broken: the caller draws the figure itself
            (or hands it over again later).

        Raises
        ------
        NotPicklable
            ``draw`` or its arguments do not pickle (asked only when the process can take the
            figure): the caller draws it itself.
        """
        import pickle

        if self._failed:
            return None
        if self._pool is None and self._ready is not None and not self._ready():
            return None
        try:  # pickled here and now: the figure shows the arguments as they are at this call
            payload = pickle.dumps((draw, args, kwargs), protocol=pickle.HIGHEST_PROTOCOL)
        except Exception as exc:  # noqa: BLE001 - whatever pickle raises for what it cannot take
            raise NotPicklable(f"{type(exc).__name__}: {exc}") from exc
        if self._pool is None:
            return self._start_with(payload)
        try:
            return self._track(self._pool.submit(_draw_pickled, payload))
        except RuntimeError:  # a broken pool (BrokenProcessPool is a RuntimeError), or shut down
            self._failed = True
            return None

    def _start_with(self, payload: bytes):
        """Create the pool and submit the first figure (which spawns the worker)."""
        return self._start(_draw_pickled, payload)

    def warm_up(self):
        """Start the worker (if ``ready()`` allows and it has not started) on
        :func:`_warm_up`, its imports, so that it is ready when the first figure comes.

        Returns
        -------
        concurrent.futures.Future or None
            None when the worker was already started, is not to be started yet, or could
            not be started.
        """
        if self._pool is not None or self._failed or (
                self._ready is not None and not self._ready()):
            return None
        return self._start(_warm_up)

    def _start(self, fn: Callable, *args):
        """Create the pool and submit ``fn(*args)`` (which spawns the worker)."""
        import multiprocessing
        from concurrent.futures import ProcessPoolExecutor

        from ..processes import starting_quietly

        try:
            pool = ProcessPoolExecutor(max_workers=1,
                                       mp_context=multiprocessing.get_context("spawn"),
                                       initializer=_worker_init)
            with starting_quietly():
                future = pool.submit(fn, *args)
        except (OSError, RuntimeError):  # no process to be had: this one draws everything
            self._failed = True
            return None
        self._pool = pool
        return self._track(future)

    def close(self, cancel: bool = True) -> None:
        """Stop the worker after the figure it is drawing (``cancel``: the queued ones are
        dropped); it exits on its own, this process does not wait for it.

        The queued figures are cancelled here: ``shutdown(cancel_futures=True)`` leaves that to
        the pool's manager thread, which skips it once the pool object has been garbage
        collected, as it is as soon as this returns (found by mutation testing, 2026-11-26).
        The pool hands one or two calls to the worker's queue ahead (their futures already
        running): those are drawn before the worker exits.
        """
        pool, self._pool = self._pool, None
        self._failed = True
        if cancel:
            for future in list(self._futures):
                future.cancel()  # (False, and nothing done, for one already running)
        if pool is not None:
            pool.shutdown(wait=False, cancel_futures=cancel)
