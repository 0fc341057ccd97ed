"""What a run of the paper's case study produced, and how it reports progress.

The study (:mod:`.paper`) fills a :class:`StudyResult`; the report (:mod:`.paper_report`) reads
it. Neither this module nor the report imports the study.

Progress protocol
-----------------
``progress(stage, done, total)``: three positional arguments, unchanged from earlier versions.

* Announcements: ``(name, i, 6)`` as stage ``name`` (``"geometry"``, ``"stiffness"``,
  ``"simulation"``, ``"diagnostics"``, ``"measurement"``, ``"report"``: the names of
  ``paper.STAGES``) starts, ``i`` stages having finished; ``("done", 6, 6)`` at the end.
* Counts: ``("<bar>: <item>", done, total)`` or ``("<bar>", done, total)``, one bar per ``<bar>``
  with its own count that runs from 0 to ``total`` and is never reused for another count; the
  text after ``": "`` names the item in progress. Bars: ``"stiffness (healthy)"`` and
  ``"stiffness (cracked)"`` (the map builder's own count: FE solves or PEM grid lines; one step
  when the map comes from the cache), ``"simulation"`` (7 records: model I, I-static and II,
  cracked and healthy, and model II with the paper's start-of-step scheme), ``"diagnostics"``
  (5 records: model I and II, cracked and healthy, and model I-static cracked),
  ``"measurement"`` (10 steps: two simulations with tooth errors, then 8 measured records; 0
  then 10 when the results come from the cache) and ``"report"`` (figures, then the files). A
  count call always carries an item when its ``total`` equals the number of stages, so it
  cannot be mistaken for an announcement.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, field
from pathlib import Path

__all__ = ["StudyResult", "Progress", "Deferred", "FigureStore", "RenderedFigure",
           "render_png", "ImportedOnCall"]

Progress = Callable[[str, int, int], None]


@dataclass
class StudyResult:
    """What a study run produced.

    Attributes
    ----------
    out : Path
        Output folder.
    summary : dict
        The content of ``summary.json``.
    stages : list of str
        Stages completed.
    seconds : dict of str -> float
        Wall time per stage [s].
    maps : dict
        ``"healthy"``, ``"cracked"``: :class:`~geardyn.stiffness.map.StiffnessMap`.
    figures : FigureStore
        Figure name -> :class:`RenderedFigure` (a matplotlib figure stored here is rendered to
        PNG and closed at once, so the run does not hold every figure until the report).
    notes : list of str
        Warnings to show in the report.
    progress : callable, optional
        See the module docstring.
    quick : bool
        Shorter records.
    sims : Mapping
        ``(model, state)`` -> simulation Dataset (:class:`~.paper.CachedRecords` after the
        simulation stage: each access reads the record from the simulation cache).
    diagnoses : dict
        ``(model, state)`` -> diagnosis result.
    crack_angle_rad : float, optional
        Pinion angle of the largest stiffness loss [rad].
    paper_case : bool
        Whether the case's inputs are the paper's (only then is it compared with the paper).
    differences : list of dict
        Physical inputs that differ from the paper's case (``key``, ``paper``, ``case``).
    files : dict of str -> Path
        Files written, by role.
    kernel_compiler : multiprocessing.Process, optional
        A second process that compiles the time-step kernel (``--quick`` on a first run after
        an install) or compiles or loads it after other work (the FE bodies' process of a
        full run): where numba's cache does not hold the kernel yet, the simulation stage
        waits for it, drawing held figures meanwhile, rather than compile it too.
    background : list of multiprocessing.Process
        The study's other second processes (FE bodies, kernel compiler): the figure process
        (:mod:`.figure_process`) starts when they have all ended.
    measured_tsa : dict
        ``(variant, state)`` -> TSA of the housing acceleration [m/s^2] over one revolution
        (measurement stage, :mod:`.paper_measurement`).
    """

    out: Path
    summary: dict = field(default_factory=dict)
    stages: list[str] = field(default_factory=list)
    seconds: dict[str, float] = field(default_factory=dict)
    maps: dict = field(default_factory=dict)
    figures: dict = field(default_factory=lambda: FigureStore())
    notes: list[str] = field(default_factory=list)
    progress: Progress | None = None
    quick: bool = False
    sims: dict = field(default_factory=dict)
    kernel_compiler: object = None
    background: list = field(default_factory=list)
    diagnoses: dict = field(default_factory=dict)
    crack_angle_rad: float | None = None
    paper_case: bool = True
    differences: list = field(default_factory=list)
    files: dict = field(default_factory=dict)
    measured_tsa: dict = field(default_factory=dict)

    def emit(self, stage: str, done: int, total: int) -> None:
        """Report progress (see the module docstring); a no-op without a callback. Each report
        also lets the figure process start if it may (:meth:`FigureStore.poll`)."""
        poll = getattr(self.figures, "poll", None)
        if poll is not None:
            poll()
        if self.progress is not None:
            self.progress(stage, done, total)

    def sub_progress(self, stage: str) -> Callable[[int, int], None] | None:
        """A ``progress(done, total)`` callback reporting under ``stage``."""
        if self.progress is None:
            return None
        return lambda done, total: self.emit(stage, done, total)


#: Resolution of the report's figures [dots per inch] (the report's default).
FIGURE_DPI = 110


class RenderedFigure:
    """A figure already rendered to PNG bytes, with the part of the matplotlib ``Figure`` API
    the report uses (``savefig`` into a binary file object)."""

    __slots__ = ("png",)

    def __init__(self, png: bytes):
        self.png = png

    def savefig(self, fh, format: str = "png", **_ignored) -> None:  # noqa: A002 (matplotlib's name)
        """Write the PNG (rendered at :data:`FIGURE_DPI`, :func:`.report.png_bbox`) to ``fh``."""
        if format != "png":
            raise ValueError(f"a rendered figure is PNG only, not {format!r}")
        fh.write(self.png)


class _Undigestable(Exception):
    """An argument the figure cache cannot fingerprint (the figure is then drawn, not cached)."""


#: NumPy scalar types (``dtype.str`` without the byte order) fingerprinted as the Python scalar
#: they hold: float64, int64, bool, complex128 (what NetCDF gives back for a Python attribute);
#: NumPy strings and bytes too.
_PYTHON_SCALARS = ("f8", "i8", "b1", "c16")


class Deferred:
    """A figure argument known by a fingerprint and computed only if the figure is drawn.

    Passed as a positional or keyword argument of :meth:`FigureStore.cached` (not inside a
    container), which fingerprints it by ``fingerprint`` alone and calls ``compute()`` (once)
    on a cache miss. The fingerprint must identify the value: the hash of everything it
    is computed from (e.g. a diagnosis by its input signals, settings and geardyn's sources).

    Parameters
    ----------
    fingerprint : str
        Hash of the value's inputs.
    compute : callable
        ``compute() -> value``.
    """

    __slots__ = ("fingerprint", "_compute", "_value")

    def __init__(self, fingerprint: str, compute: Callable[[], object]):
        self.fingerprint = str(fingerprint)
        self._compute = compute
        self._value: tuple = ()

    def value(self):
        """The value (computed on the first call)."""
        if not self._value:
            self._value = (self._compute(),)
        return self._value[0]


def _resolve(args: tuple, kwargs: dict) -> tuple[tuple, dict]:
    """``args`` and ``kwargs`` with each :class:`Deferred` replaced by its value."""
    def one(a):
        return a.value() if isinstance(a, Deferred) else a

    return tuple(one(a) for a in args), {k: one(v) for k, v in kwargs.items()}


def _digest(obj, h) -> None:
    """Feed a canonical fingerprint of ``obj`` to the hash ``h`` (arrays by dtype, shape and
    bytes; dataclasses, mappings and sequences element by element; xarray objects by their
    variables, coordinates and attributes)."""
    import dataclasses

    import numpy as np

    if isinstance(obj, np.generic) and (obj.dtype.str[1:] in _PYTHON_SCALARS
                                        or obj.dtype.kind in "US"):
        # a NetCDF round trip turns a Python float/int attribute into np.float64/np.int64: the
        # same value, the same figure (issue 16: the first warm run redrew 6 figures for this)
        obj = obj.item()
    if isinstance(obj, Deferred):
        h.update(f"deferred:{obj.fingerprint};".encode())
    elif obj is None or isinstance(obj, (bool, int, float, complex, str, bytes)):
        h.update(f"{type(obj).__name__}:{obj!r};".encode())
    elif isinstance(obj, np.generic):
        h.update(f"{obj.dtype}:{obj.item()!r};".encode())
    elif isinstance(obj, np.ndarray):
        if obj.dtype.hasobject:
            raise _Undigestable(type(obj))
        h.update(f"nd:{obj.dtype.str}:{obj.shape};".encode())
        h.update(np.ascontiguousarray(obj).tobytes())
    elif dataclasses.is_dataclass(obj) and not isinstance(obj, type):
        h.update(f"dc:{type(obj).__module__}.{type(obj).__qualname__};".encode())
        for f in dataclasses.fields(obj):
            h.update(f.name.encode())
            _digest(getattr(obj, f.name), h)
    elif isinstance(obj, dict):
        h.update(f"dict:{len(obj)};".encode())
        for k in sorted(obj, key=repr):
            _digest(k, h)
            _digest(obj[k], h)
    elif isinstance(obj, (list, tuple)):
        h.update(f"{type(obj).__name__}:{len(obj)};".encode())
        for x in obj:
            _digest(x, h)
    elif hasattr(obj, "model_dump") and hasattr(type(obj), "model_fields"):  # pydantic (Case)
        h.update(f"pyd:{type(obj).__module__}.{type(obj).__qualname__};".encode())
        _digest(obj.model_dump(mode="json"), h)
    elif hasattr(obj, "variables") and hasattr(obj, "attrs"):  # xarray.Dataset
        h.update(b"xr-dataset;")
        for name in sorted(obj.variables):
            v = obj.variables[name]
            _digest((name, v.dims, dict(v.attrs)), h)
            _digest(np.asarray(v.values), h)
        _digest(dict(obj.attrs), h)
    else:
        raise _Undigestable(type(obj))


def _source_digest() -> str:
    """Hash of geardyn's Python sources and the plotting library's version: any change of the
    code or of matplotlib invalidates every cached figure."""
    global _SOURCE_DIGEST
    if _SOURCE_DIGEST is None:
        import hashlib
        from importlib import metadata

        # the installed version, read without importing matplotlib (0.25 s; issue 16)
        h = hashlib.sha256(f"matplotlib {metadata.version('matplotlib')}; dpi {FIGURE_DPI};"
                           .encode())
        root = Path(__file__).resolve().parents[1]
        for path in sorted(root.rglob("*.py")):
            h.update(str(path.relative_to(root)).encode())
            h.update(path.read_bytes())
        _SOURCE_DIGEST = h.hexdigest()
    return _SOURCE_DIGEST


_SOURCE_DIGEST: str | None = None


def render_png(fig) -> bytes:
    """A matplotlib figure as PNG bytes (:data:`FIGURE_DPI`, bounding box by
    :func:`.report.png_bbox`, as the report embeds it); the figure is closed."""
    import io

    import matplotlib.pyplot as plt

    from .report import png_bbox

    buf = io.BytesIO()
    fig.savefig(buf, format="png", dpi=FIGURE_DPI, bbox_inches=png_bbox(fig))
    plt.close(fig)
    return buf.getvalue()


class ImportedOnCall:
    """The function ``module.name``, imported when called.

    It carries the function's ``__module__`` and ``__qualname__``, by which
    :meth:`~.paper_result.FigureStore.cached` keys a figure, so a figure taken from the cache
    does not import the module that draws it. It lives here, in a module the figure process
    imports anyway: a figure handed to that process pickles a reference to this class, and
    unpickling it imported the whole study module (with the case models, pydantic) when it
    lived in :mod:`.paper` (found 2026-11-27).
    """

    def __init__(self, module: str, name: str):
        self.__module__ = module
        self.__qualname__ = name

    def __call__(self, *args, **kwargs):
        import importlib

        return getattr(importlib.import_module(self.__module__), self.__qualname__)(*args,
                                                                                   **kwargs)


#: The drawing function of the study's FE mesh figure (``fig_fe_mesh``): the figure cache keys
#: the figure by its name, so the study and the second process that draws it ahead
#: (:func:`fe_mesh_figure_task`) must both use this one.
PLOT_MESH = ImportedOnCall("geardyn.stiffness.fe", "plot_mesh")


def fe_mesh_figure_task(map_case, cracked: bool) -> None:
    """The study's FE mesh figure (``fig_fe_mesh``) into the figure cache, for the second
    process to call right after it has built the faulty bodies (a ``then`` task of
    :func:`geardyn.stiffness.fe.background.faulty_bodies_in_background`): it holds the cracked
    body's mesh, so it draws the figure without meshing again (about 1.5 s of gmsh on the
    paper's pinion) while the first process evaluates the maps; the first then reads it from
    the cache (or waits for it there, under the entry's lock).

    A failure here is left to the first process, which draws the figure itself and meets (and
    reports) the same error.
    """
    import contextlib

    with contextlib.suppress(Exception):
        FigureStore().cached_here("fig_fe_mesh", PLOT_MESH, map_case, cracked=cracked)


def kernels_and_mesh_figure_task(map_case, cracked: bool) -> None:
    """What the second process of a full ``geardyn run`` does after the faulty bodies: the
    time-step kernel (:func:`geardyn.dynamics.warm.compile_kernels`) and the mesh figure
    (:func:`fe_mesh_figure_task`), the kernel first where numba has to compile it (5-10 s the
    first process would otherwise wait for at its simulations: with the figure first a cold run
    took 50.6-51.1 s against 46.1-47.8 s, 2026-11-28), the figure first where numba holds it
    (loading it takes 0.3 s, and the first process asks for the figure as its maps end).
    """
    from ..dynamics.warm import compile_kernels, kernels_compiled

    if kernels_compiled():
        fe_mesh_figure_task(map_case, cracked)
        compile_kernels()
    else:
        compile_kernels()
        fe_mesh_figure_task(map_case, cracked)


class _Pending:
    """A figure handed to the figure process, or held for it: its name and cache key, how to
    draw it here, and the PNG to come (``future``, None while held). The arguments are let go
    as soon as the process has drawn the figure (they are only needed to draw it here instead),
    so the records and diagnoses a figure shows are not held until the report collects it."""

    __slots__ = ("key", "digest", "draw", "args", "kwargs", "future")

    def __init__(self, key, digest: str | None, draw: Callable, args: tuple, kwargs: dict):
        self.key, self.digest = key, digest
        self.draw, self.args, self.kwargs = draw, args, kwargs
        self.future = None


#: Figures at most in the figure process's hands at once (sent, not drawn yet): each is a
#: pickled copy of its arguments in this process until drawn; the others wait as they are. With
#: no bound, a full run's records pickled for eight figures at once raised this process's peak
#: by about 250 MB (measured 2026-11-26).
IN_FLIGHT = 2

#: The same bound once :meth:`FigureStore.finish` draws the held figures here: the process then
#: gets the next figure only when it has drawn the last, so that no figure waits in its queue
#: while this process, out of figures to draw, waits for it (the end of a first
#: ``geardyn run --quick`` had this process idle about 0.9 s for the queued one, 2026-11-27).
IN_FLIGHT_AT_FINISH = 1


class FigureStore(dict):
    """Figure name -> :class:`RenderedFigure`: a matplotlib figure assigned is rendered to PNG
    (:func:`render_png`) and closed, which keeps a run's memory from growing with every figure
    (measured: the diagnostics and report stages of ``geardyn run --quick`` held about 560 MB of
    figures and their data).

    With a :class:`~.figure_process.FigureProcess` (``process``), :meth:`cached` hands the
    figures it has to draw to that second process and returns at once: at most
    :data:`IN_FLIGHT` at a time, the next one sent as one is drawn, in the order they came.
    Reading a figure (``store[name]``, ``get``, ``items``, ``values``) or :meth:`finish`
    collects them.
    """

    def __init__(self, process=None):
        import threading
        from collections import deque

        super().__init__()
        self.process = process
        self._held: deque = deque()    # handed over, not sent yet, in order
        self._in_flight = 0
        self._limit = IN_FLIGHT         # IN_FLIGHT_AT_FINISH once finish() draws here too
        self._early = False             # start_early(): poll() starts the process when ready
        self._next_poll = 0.0
        self._lock = threading.RLock()  # _held, _in_flight: this thread and the pool's callbacks

    def __setitem__(self, key, fig) -> None:
        if not isinstance(fig, (RenderedFigure, _Pending)) and hasattr(fig, "savefig"):
            fig = RenderedFigure(render_png(fig))
        super().__setitem__(key, fig)

    def __getitem__(self, key):
        value = super().__getitem__(key)
        if isinstance(value, _Pending):
            value = self._collect(key, value)
        return value

    def get(self, key, default=None):
        return self[key] if key in self else default

    def items(self):
        self.finish()
        return super().items()

    def values(self):
        self.finish()
        return super().values()

    def _pending(self) -> list:
        return [k for k, v in super().items() if isinstance(v, _Pending)]

    def _pump(self) -> None:
        """Send held figures, first come first, while fewer than :data:`IN_FLIGHT` are in the
        process's hands (:data:`IN_FLIGHT_AT_FINISH` during :meth:`finish`), from this thread,
        and from the pool's thread as each is drawn."""
        from .figure_process import NotPicklable

        with self._lock:
            while self.process is not None and self._held and self._in_flight < self._limit:
                job = self._held[0]
                try:
                    future = self.process.submit(job.draw, job.args, job.kwargs)
                except NotPicklable:  # drawn here when collected (its future stays None)
                    self._held.popleft()
                    continue
                if future is None:  # not yet (or never): they stay held
                    return
                self._held.popleft()
                job.future = future
                self._in_flight += 1
                future.add_done_callback(lambda f, job=job: self._drawn(job, f))

    def _drawn(self, job: _Pending, future) -> None:
        """The process is done with ``job`` (called from the pool's thread)."""
        if not future.cancelled() and future.exception() is None:
            job.args, job.kwargs = (), {}
        with self._lock:
            self._in_flight -= 1
        self._pump()

    def _collect(self, key, job: _Pending) -> RenderedFigure:
        """The figure of ``job``: the process's PNG, or drawn here when the process did not
        draw it (held, arguments not picklable, cancelled, failed); stored in the figure
        cache."""
        with self._lock:
            if job.future is None and job in self._held:
                self._held.remove(job)  # drawn here, never sent
        png = None
        if job.future is not None and not job.future.cancelled():
            try:
                png = job.future.result()
            except Exception:  # noqa: BLE001 - drawn again below, which raises it here
                png = None
        if png is None:
            png = render_png(job.draw(*job.args, **job.kwargs))
        if job.digest is not None:
            from ..cache import default_cache

            png, _ = default_cache().get_or_build(
                "figure", job.digest, ".png", lambda: png,
                lambda data, path: Path(path).write_bytes(data),
                lambda path: Path(path).read_bytes())
        figure = RenderedFigure(png)
        super().__setitem__(key, figure)
        return figure

    def finish(self) -> None:
        """Collect every figure handed to the process: this process draws those not sent yet,
        from the last one back, while the process goes on from the first; then the process is
        stopped. Cheap when nothing is pending."""
        pending = self._pending()
        if not pending:
            return
        with self._lock:
            self._limit = IN_FLIGHT_AT_FINISH
        self._pump()
        self.draw_held_while(lambda: True)
        for key in pending:
            job = super().__getitem__(key)
            if isinstance(job, _Pending):
                self._collect(key, job)
        self.close()

    def draw_held_while(self, keep_going: Callable[[], bool]) -> int:
        """Draw held figures here (those not sent to the figure process yet), the last first,
        one at a time while ``keep_going()`` says so: for a process that would otherwise wait
        (the study waiting for the kernel that a second process compiles, during which the
        figure process has not started). A figure drawn here goes into the figure cache as
        :meth:`finish` would put it.

        Returns
        -------
        int
            How many figures were drawn.
        """
        drawn = 0
        while keep_going():
            with self._lock:
                job = self._held.pop() if self._held else None
            if job is None:
                break
            self._collect(job.key, job)
            drawn += 1
        return drawn

    def close(self) -> None:
        """Stop the figure process (queued figures dropped); later figures are drawn here."""
        if self.process is not None:
            self.process.close()
            self.process = None

    def start_early(self) -> None:
        """Let :meth:`poll` start the figure process as soon as ``ready()`` allows (the study's
        other background processes have ended), rather than at the next figure handed over.

        A first ``geardyn run --quick`` asked the process to start only at its next figure,
        about a second after the kernel's compiler had ended, and the worker then spent a
        second importing while the second core idled (2026-11-27).
        """
        self._early = self.process is not None

    def poll(self) -> None:
        """Start the figure process if :meth:`start_early` asked for it and ``ready()`` now
        allows: with the held figures, or, with none held, on its imports
        (:meth:`.figure_process.FigureProcess.warm_up`). Cheap (asked at most every 50 ms);
        called by the study at each progress report, in this thread."""
        import time

        if not self._early:
            return
        now = time.monotonic()
        if now < self._next_poll:
            return
        self._next_poll = now + 0.05
        if self.process is None or self.process.started or self.process.failed:
            self._early = False
            return
        self._pump()
        if self.process is not None and not self.process.started:
            self.process.warm_up()
        # asked again until it has started, unless it could not be (then never)
        self._early = (self.process is not None and not self.process.started
                       and not self.process.failed)

    def cached(self, key, draw: Callable, *args, **kwargs) -> None:
        """``self[key] = draw(*args, **kwargs)``, through the disk cache (kind ``figure``): the
        PNG is keyed by a fingerprint of the arguments (:func:`_digest`), ``draw``'s name and
        geardyn's sources, so a run whose inputs did not change takes its figures from the
        cache instead of drawing them again (issue 16.6). A :class:`Deferred` argument counts
        by its fingerprint and is computed only when the figure is drawn. Arguments it cannot
        fingerprint, or ``GEARDYN_NO_CACHE``, draw the figure without the cache. With a figure
        process, a figure not in the cache is handed to it (its :class:`Deferred` arguments
        computed here first) and collected later (class docstring)."""
        self._cached(key, draw, args, kwargs, here=False)

    def cached_here(self, key, draw: Callable, *args, **kwargs) -> None:
        """:meth:`cached`, drawn by this process even with a figure process: for a figure whose
        drawing reuses what this process holds (e.g. the FE mesh it has just built, which the
        figure process would build again)."""
        self._cached(key, draw, args, kwargs, here=True)

    def _cached(self, key, draw: Callable, args: tuple, kwargs: dict, here: bool) -> None:
        import hashlib

        from ..cache import default_cache

        h = hashlib.sha256(f"{key};{draw.__module__}.{draw.__qualname__};".encode())
        try:
            _digest(args, h)
            _digest(kwargs, h)
        except _Undigestable:
            args, kwargs = _resolve(args, kwargs)
            if self.process is not None and not here:
                self._hand_over(key, None, draw, args, kwargs)
            else:
                self[key] = draw(*args, **kwargs)
            return
        h.update(_source_digest().encode())
        cache = default_cache()
        digest = h.hexdigest()
        if self.process is not None and not here and not (
                cache.enabled and cache.path("figure", digest, ".png").exists()):
            # the figure process draws it; it goes into the cache when collected
            self._hand_over(key, digest if cache.enabled else None, draw,
                            *_resolve(args, kwargs))
            return

        def build() -> bytes:
            a, kw = _resolve(args, kwargs)
            self[key] = draw(*a, **kw)
            return dict.__getitem__(self, key).png

        png, _ = cache.get_or_build("figure", digest, ".png", build,
                                    lambda data, path: Path(path).write_bytes(data),
                                    lambda path: Path(path).read_bytes())
        super().__setitem__(key, RenderedFigure(png))

    def _hand_over(self, key, digest: str | None, draw: Callable, args: tuple,
                   kwargs: dict) -> None:
        """Hand ``draw(*args, **kwargs)`` to the figure process, after the figures handed over
        before it (:meth:`_pump`); ``digest``: its figure-cache key (None: not cached)."""
        job = _Pending(key, digest, draw, args, kwargs)
        super().__setitem__(key, job)
        with self._lock:
            self._held.append(job)
        self._pump()
